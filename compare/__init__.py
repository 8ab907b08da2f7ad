"""feedoracle's comparison side: per-block optimality gap, reports, the CLI and the CI gate.

The public API, importable from here:

* the comparison of a heuristic plan with an oracle solution on their shared path:
  :func:`compare`, :class:`Comparison` (rows, totals, gap interval, ``verdict``),
  :func:`format_interval`;
* the CLI's work as plain functions (:mod:`compare.pipeline`): :func:`load_inputs`,
  :func:`plan_program`, :func:`optimize_program`, :func:`compare_program`,
  :func:`check_trajectory`;
* outputs: :func:`comparison_dict` (the JSON contract), :func:`blocks_csv`,
  :func:`write_report` (HTML), :func:`print_comparison` (text).

Names are imported on first use (PEP 562): ``import compare`` stays cheap, and the
report's plotting library loads only when a report is written.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

#: Public name -> module that defines it.
_EXPORTS = {
    "ComparedBlock": "compare.result", "Comparison": "compare.result",
    "OracleResult": "compare.result", "Side": "compare.result",
    "Verdict": "compare.result", "compare": "compare.comparison",
    "compare_profiles": "compare.comparison", "format_interval": "compare.result",
    "oracle_result": "compare.comparison",
    "Inputs": "compare.pipeline", "OptimizeResult": "compare.pipeline",
    "check_trajectory": "compare.pipeline", "compare_program": "compare.pipeline",
    "load_inputs": "compare.pipeline", "optimize_program": "compare.pipeline",
    "plan_program": "compare.pipeline",
    "CheckResult": "compare.recorded",
    "blocks_csv": "compare.export", "comparison_dict": "compare.export",
    "write_json": "compare.export",
    "write_report": "compare.report_html",
    "print_comparison": "compare.text",
    "main": "compare.cli",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    try:
        module = _EXPORTS[name]
    except KeyError:
        raise AttributeError(f"module 'compare' has no attribute {name!r}") from None
    return getattr(importlib.import_module(module), name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


if TYPE_CHECKING:  # for type checkers and editors; at run time names load on first use
    from .cli import main
    from .comparison import compare, compare_profiles, oracle_result
    from .result import (ComparedBlock, Comparison, OracleResult, Side, Verdict,
                         format_interval)
    from .export import blocks_csv, comparison_dict, write_json
    from .pipeline import (Inputs, OptimizeResult, check_trajectory, compare_program,
                           load_inputs, optimize_program, plan_program)
    from .recorded import CheckResult
    from .report_html import write_report
    from .text import print_comparison

"""Stage: the plan as the JSON contract of DESIGN section 7 (the ``reference`` part)."""

from __future__ import annotations

from typing import Iterator

import numpy as np

from ..core.constraints import BOUND_SETS
from . import causes as C
from .result import ReferencePlan


def _num(x: float) -> float:
    """A plain float. Infinite values (a velocity jump where the machine allows none)
    stay ``inf``: the one JSON writer (:func:`reference.core.jsonio.write_json`) encodes them for
    every part of the contract alike, so the planner does not invent its own rule."""
    return float(x)


def to_json_dict(plan: ReferencePlan) -> dict:
    """The plan as a JSON-ready dict (schema ``result.schema.json``).

    Parameters
    ----------
    plan : ReferencePlan

    Returns
    -------
    dict
        Plain floats (an infinite ratio stays ``inf``; write the dict with
        ``reference.core.jsonio.write_json``, which encodes it as the JSON contract says).
        ``{"program", "machine", "bounds", "reference": {"time_s", "violations"},
        "blocks": [...]}``; ``bounds`` is the planner's own bound set, ``violations``
        lists the constraints of that set the own profile breaks
        (``{"constraint", "axis", "ratio", "s", "block"}``), and every block row has
        ``block, line, label, kind, length_mm, t_reference_s, v_exit_reference,
        limit_reference, hold_s, hold_cause`` (the block's imposed hold, dwell or
        exact-stop settle, contained in ``t_reference_s``; ``hold_cause`` ``""`` if none).
    """
    viol = []
    if plan.report is not None:
        for r in plan.report.violations(BOUND_SETS[plan.bound_set]):
            viol.append({"constraint": r.constraint, "axis": r.axis, "ratio": _num(r.ratio),
                         "s": _num(r.s), "block": int(r.block)})
    blocks = list(iter_json_rows(plan))
    return {"program": plan.program, "machine": plan.machine, "bounds": plan.bound_set,
            "reference": {"time_s": _num(plan.time_s), "violations": viol},
            "blocks": blocks}


#: Rows converted to Python objects at a time by :func:`iter_json_rows`.
_ROW_CHUNK = 1 << 16


def iter_json_rows(plan: ReferencePlan) -> Iterator[dict]:
    """The ``blocks`` rows of :func:`to_json_dict`, one dict at a time (a table printed
    from them never holds all 10^6 of them at once)."""
    # Built from the table's columns, a chunk of rows at a time: 10^6 blocks would cost
    # 10^6 row objects, or nine lists of 10^6 Python numbers, otherwise.
    tab = plan.blocks
    names = ("block", "line", "label", "kind", "length_mm", "time_s", "v_exit",
             "cause_code", "hold_s")
    floats = {"length_mm", "time_s", "v_exit", "hold_s"}    # plain floats, as the contract says
    full = {name: (np.asarray(tab.column(name), dtype=np.float64) if name in floats
                   else tab.column(name)) for name in names}
    hold_cause = plan.holds.causes_by_block()
    for lo in range(0, len(tab), _ROW_CHUNK):
        cols = [full[name][lo:lo + _ROW_CHUNK] for name in names]
        cols = [c.tolist() if isinstance(c, np.ndarray) else c for c in cols]
        cols[7] = [C.CAUSES[k] if k >= 0 else "" for k in cols[7]]
        for b, ln, lab, kind, length, t, v, cause, hold in zip(*cols):
            yield {"block": b, "line": max(1, ln), "label": lab, "kind": kind,
                   "length_mm": max(0.0, length), "t_reference_s": max(0.0, t),
                   "v_exit_reference": max(0.0, v), "limit_reference": cause,
                   "hold_s": hold, "hold_cause": hold_cause.get(b, "")}

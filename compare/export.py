"""JSON and CSV output (the contract of DESIGN section 7 and ``schema/result.schema.json``).

Non-finite numbers are encoded by the one JSON writer of the project,
:mod:`reference.core.jsonio` (re-exported here).

Every ``--json`` output validates against the schema; the tests check it.
"""

from __future__ import annotations

import csv
import io
import json
import math
import sys
from importlib import resources
from pathlib import Path as FsPath
from typing import Any, Iterable

import numpy as np

from reference.core.constraints import BOUND_SETS, ConstraintResult
from reference.core.geometry import Path
from reference.core.jsonio import JSON_INF, dumps, json_ready, write_json
from reference.core.profile import Profile

from .comparison import Comparison, ComparedBlock, block_span

__all__ = ["CSV_COLUMNS", "JSON_INF", "blocks_csv", "comparison_dict", "dumps", "json_ready",
           "profile_samples", "schema", "violation_dict", "write_json",
           "write_samples_csv"]


#: Block-row columns of the CSV report, in order.
CSV_COLUMNS = ("block", "line", "label", "kind", "corner", "length_mm", "t_reference_s",
               "t_oracle_s", "lb_oracle_s", "hold_s", "hold_cause", "gap_s", "gap_rel", "v_entry_reference", "v_exit_reference",
               "v_peak_reference", "v_entry_oracle", "v_exit_oracle", "v_peak_oracle",
               "limit_reference", "limit_oracle", "ratio_reference", "ratio_oracle",
               "stop_reason", "rounding", "note", "source")


def schema() -> dict:
    """The result schema shipped with the package (a copy of ``shared/schema``)."""
    text = resources.files("compare").joinpath("schema/result.schema.json").read_text("utf-8")
    return json.loads(text)


def violation_dict(v: ConstraintResult, path: Path | None = None) -> dict:
    """One violation in the schema's form, plus value, limit, unit, t and line."""
    d = {"constraint": v.constraint, "axis": v.axis, "ratio": v.ratio, "s": v.s,
         "block": int(v.block), "value": v.value, "limit": v.limit, "unit": v.unit, "t": v.t}
    if v.detail:
        d["detail"] = v.detail
    if path is not None:
        span = block_span(path, v.block)
        if span is not None:
            d["line"] = span.line
    return d


def _row_dict(r: ComparedBlock) -> dict:
    d = {"block": r.block, "line": r.line, "label": r.label, "kind": r.kind,
         "length_mm": r.length_mm, "t_reference_s": r.t_reference_s,
         "t_oracle_s": r.t_oracle_s, "hold_s": r.hold_s, "hold_cause": r.hold_cause,
         "gap_s": r.gap_s,
         "v_entry_reference": r.v_entry_reference, "v_exit_reference": r.v_exit_reference,
         "v_peak_reference": r.v_peak_reference, "v_entry_oracle": r.v_entry_oracle,
         "v_exit_oracle": r.v_exit_oracle, "v_peak_oracle": r.v_peak_oracle,
         "limit_reference": r.limit_reference, "limit_oracle": r.limit_oracle,
         "ratio_reference": r.ratio_reference, "ratio_oracle": r.ratio_oracle,
         "stop_reason": r.stop_reason, "source": r.source}
    if r.corner is not None:
        d["corner_lines"] = list(r.corner)
    if r.note:
        d["note"] = r.note
    if r.rounding:
        d["rounding"] = r.rounding
    if math.isfinite(r.lb_oracle_s):
        d["lb_oracle_s"] = r.lb_oracle_s
    return d


def comparison_dict(c: Comparison, max_gap: float | None = None) -> dict:
    """The full JSON result of ``compare`` / ``check`` (all parts of the contract).

    Parameters
    ----------
    c : Comparison
    max_gap : float, optional
        The gate (fraction) the verdict was taken against.

    Returns
    -------
    dict
        Ready for :func:`write_json`.
    """
    verdict = c.verdict(max_gap)
    ref_viol = [violation_dict(v, c.path) for v in c.reference_violations]
    out: dict[str, Any] = {
        "program": c.program, "machine": c.machine, "bounds": c.oracle.bounds,
        "reference": {"time_s": c.t_reference_s, "violations": ref_viol,
                      "planner": c.reference_name, "bound_set": c.reference_bounds,
                      "constraints_checked": list(BOUND_SETS[c.reference_bounds]),
                      "ratio_tol": c.reference_ratio_tol},
        "oracle": {"lower_bound_s": c.oracle.lower_bound_s,
                   "upper_bound_s": c.oracle.upper_bound_s, "status": c.oracle.status,
                   "solve_time_s": c.oracle.solve_time_s, "grid_points": c.oracle.grid_points,
                   "time_s": c.t_oracle_s,
                   "violations": [violation_dict(v, c.path) for v in c.oracle_violations]},
        "gap": {"lower": c.gap_lower, "upper": c.gap_upper,
                "lower_valid": c.gap_lower_valid, "hold_s": c.hold_s},
        "verdict": {"ok": verdict.ok, "status": verdict.status, "text": verdict.text,
                    "max_gap": max_gap},
        "notes": list(c.notes),
        "blocks": [_row_dict(r) for r in c.rows],
    }
    if not c.certified:
        # no certified bounds: the schema's numbers must still be numbers >= 0
        for k in ("lower_bound_s", "upper_bound_s"):
            v = out["oracle"][k]
            if not (isinstance(v, float) and math.isfinite(v) and v >= 0):
                out["oracle"][k] = 0.0
        out["gap"] = {"lower": -1.0, "upper": math.inf, "lower_valid": False,
                      "note": "no certified bounds: the gap is unknown"}
    return out


def blocks_csv(c: Comparison) -> str:
    """The block table as CSV text (columns :data:`CSV_COLUMNS`; speeds mm/s, times s)."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_COLUMNS)
    for r in c.rows:
        d = _row_dict(r)
        d["gap_rel"] = r.gap_rel
        d["corner"] = f"{r.corner[0]}-{r.corner[1]}" if r.corner else ""
        d["note"] = r.note
        w.writerow([_csv_cell(d.get(k, "")) for k in CSV_COLUMNS])
    return buf.getvalue()


def _csv_cell(v: Any) -> Any:
    if isinstance(v, float):
        if math.isnan(v):
            return ""
        return repr(v) if math.isfinite(v) else ("inf" if v > 0 else "-inf")
    return v


def profile_samples(path: Path, profile: Profile, dt: float
                    ) -> tuple[tuple[str, ...], np.ndarray]:
    """A profile sampled at a fixed period: columns ``t, s, v`` and every axis.

    Parameters
    ----------
    path : Path
    profile : Profile
    dt : float
        Sampling period, s (the IPO cycle).

    Returns
    -------
    header : tuple[str, ...]
        ``("t", "s", "v", *path.axes)``.
    data : numpy.ndarray, shape (N, 3 + n)
        s, mm, mm/s, mm (degrees for rotary axes).
    """
    t, s, v, _, _ = profile.sample(dt)
    s = np.clip(s, 0.0, path.total_length)
    q = path.evaluate(s)[0] if path.n_segments else np.zeros((t.size, path.n_axes))
    return ("t", "s", "v", *path.axes), np.column_stack([t, s, v, q])


def write_samples_csv(header: Iterable[str], data: np.ndarray, file: str | FsPath) -> None:
    """Write sampled motion as CSV with a header line (full float precision)."""
    text = ",".join(header) + "\n" + "\n".join(
        ",".join(repr(float(x)) for x in row) for row in np.asarray(data)) + "\n"
    if str(file) == "-":
        sys.stdout.write(text)
        return
    FsPath(file).parent.mkdir(parents=True, exist_ok=True)
    FsPath(file).write_text(text, encoding="utf-8")

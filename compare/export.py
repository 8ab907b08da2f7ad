"""JSON and CSV output (the contract of DESIGN section 7 and ``schema/result.schema.json``).

JSON has no infinity and no NaN. Where a value is not finite we write:

* ``+inf`` (a velocity jump at a corner where the machine allows none has ratio
  ``inf``; a gap upper end with a zero lower bound) as ``1.7976931348623157e+308``, the
  largest double, together with a sibling flag ``"<name>_infinite": true``. It parses
  back to a float larger than any real value, so ``ratio > 1`` tests stay right;
* ``-inf`` as ``-1.7976931348623157e+308`` (same flag);
* ``NaN`` (a quantity that does not exist, e.g. the oracle's speed without an oracle
  profile) by leaving the key out, or ``null`` in fields the schema does not type.

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
from reference.core.profile import Profile

from .comparison import BlockRow, Comparison, block_span

#: How +inf is written (see the module docstring).
JSON_INF = sys.float_info.max

#: Block-row columns of the CSV report, in order.
CSV_COLUMNS = ("block", "line", "label", "kind", "corner", "length_mm", "t_reference_s",
               "t_oracle_s", "hold_s", "hold_cause", "gap_s", "gap_rel", "v_entry_reference", "v_exit_reference",
               "v_peak_reference", "v_entry_oracle", "v_exit_oracle", "v_peak_oracle",
               "limit_reference", "limit_oracle", "ratio_reference", "ratio_oracle",
               "stop_reason", "note", "source")


def schema() -> dict:
    """The result schema shipped with the package (a copy of ``shared/schema``)."""
    text = resources.files("compare").joinpath("schema/result.schema.json").read_text("utf-8")
    return json.loads(text)


def _clean(obj: Any) -> Any:
    """Replace non-finite floats recursively (see the module docstring)."""
    if isinstance(obj, dict):
        out = {}
        for k, v in obj.items():
            if isinstance(v, (float, np.floating)) and not math.isfinite(float(v)):
                if math.isnan(float(v)):
                    continue
                out[k] = JSON_INF if v > 0 else -JSON_INF
                out[f"{k}_infinite"] = True
            else:
                out[k] = _clean(v)
        return out
    if isinstance(obj, (list, tuple)):
        return [None if isinstance(v, (float, np.floating)) and math.isnan(float(v))
                else (JSON_INF if v > 0 else -JSON_INF)
                if isinstance(v, (float, np.floating)) and math.isinf(float(v))
                else _clean(v) for v in obj]
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating):
        return float(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def dumps(obj: dict | list) -> str:
    """JSON text of a result (non-finite floats replaced, strict JSON)."""
    return json.dumps(_clean(obj), indent=1, allow_nan=False, ensure_ascii=False) + "\n"


def write_json(obj: dict | list, file: str | FsPath) -> None:
    """Write a result as JSON (``-`` writes to stdout)."""
    text = dumps(obj)
    if str(file) == "-":
        sys.stdout.write(text)
        return
    FsPath(file).parent.mkdir(parents=True, exist_ok=True)
    FsPath(file).write_text(text, encoding="utf-8")


def violation_dict(v: ConstraintResult, path: Path | None = None) -> dict:
    """One violation in the schema's form, plus value, limit, unit, t and line."""
    d = {"constraint": v.constraint, "axis": v.axis, "ratio": v.ratio, "s": v.s,
         "block": int(v.block), "value": v.value, "limit": v.limit, "unit": v.unit, "t": v.t}
    if path is not None:
        span = block_span(path, v.block)
        if span is not None:
            d["line"] = span.line
    return d


def _row_dict(r: BlockRow) -> dict:
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

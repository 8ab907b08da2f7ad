"""Text summaries the CLI prints: one comparison, a table of several, block tables.

Shared by the commands (:mod:`compare.commands`) and the recorded-trajectory check
(:mod:`compare.recorded`), so neither imports the other. Writers only: every number is
computed elsewhere; these functions format it.
"""

from __future__ import annotations

import math
from typing import Any, Iterable, Mapping, Sequence, TextIO

from reference.core.constraints import BOUND_SETS

from .comparison import ComparedBlock, Comparison, describe_violation, format_interval


def num(x: float, nd: int = 3) -> str:
    """``x`` with ``nd`` decimals; ``"-"`` for NaN (no value), ``"inf"`` for infinity."""
    if isinstance(x, float) and math.isnan(x):
        return "-"
    if isinstance(x, float) and math.isinf(x):
        return "inf"
    return f"{x:.{nd}f}"


def _ms(x: float) -> str:
    return "-" if not math.isfinite(x) else f"{1e3 * x:+.1f}"


def block_table(rows: Iterable[ComparedBlock], out: TextIO, limit: int | None = None) -> None:
    """Comparison rows: times and exit speeds of both sides, the gap, both causes."""
    out.write(f"    {'line':>5} {'label':<8} {'kind':<8} {'length_mm':>9} {'t_ref_s':>8} "
              f"{'t_opt_s':>8} {'gap_ms':>8} {'v_exit ref/opt mm/s':>19}  limit (ref / opt)\n")
    for r in list(rows)[:limit]:
        vx = f"{r.v_exit_reference:.1f}/{num(r.v_exit_oracle, 1)}"
        kind = r.kind if not r.corner else f"{r.kind}@{r.corner[0]}"
        out.write(f"    {r.line:>5} {r.label[:8]:<8} {kind[:8]:<8} {r.length_mm:>9.3f} "
                  f"{r.t_reference_s:>8.4f} {num(r.t_oracle_s, 4):>8} {_ms(r.gap_s):>8} "
                  f"{vx:>19}  {r.limit_reference} / {r.limit_oracle}\n")


def print_comparison(c: Comparison, max_gap: float | None, out: TextIO,
                     n_worst: int = 5) -> None:
    """The text summary of one comparison (totals, gap, verdict, notes, worst blocks)."""
    v = c.verdict(max_gap)
    who = "recorded" if c.reference_name == "recorded" else "heuristic"
    out.write(f"{c.program}: machine {c.machine!r}, oracle bounds {c.bounds}, "
              f"{who} bounds {c.reference_bounds}\n")
    viol = c.reference_violations
    out.write(f"  {who:<10} {c.t_reference_s:10.4f} s   "
              f"{'no violations of ' + ', '.join(BOUND_SETS[c.reference_bounds]) if not viol else str(len(viol)) + ' violation(s)'}\n")
    for item in viol:
        out.write(f"    VIOLATION {describe_violation(item, c)}\n")
    o = c.oracle
    out.write(f"  {'oracle':<10} LB {num(o.lower_bound_s, 4)} s, UB {num(o.upper_bound_s, 4)} s"
              f"   ({o.status}, {o.grid_points} grid points, {o.solve_time_s:.2f} s)\n")
    for item in c.oracle_violations:
        out.write(f"    ORACLE VIOLATION {describe_violation(item, c)}\n")
    if c.certified:
        valid = "" if c.gap_lower_valid else "   (lower end: gap to the relaxation only)"
        if c.stricter_violations:
            valid = (f"   (against the stricter {c.oracle.bounds} optimum, whose "
                     f"{c.stricter_violations[0].constraint} limit the planner breaks)")
        if c.hold_s > 0:
            out.write(f"  {'holds':<10} {c.hold_s:10.4f} s   dwell and exact-stop settle, the "
                      f"same on both sides: not counted in the gap\n")
            formula = "[(t_ref-H)/(UB-H) - 1, (t_ref-H)/(LB-H) - 1], H = holds"
        else:
            formula = "[t_ref/UB - 1, t_ref/LB - 1]"
        out.write(f"  {'gap':<10} {format_interval(c)}   {formula}{valid}\n")
    out.write(f"  {'verdict':<10} {'ok' if v.ok else 'FAIL'}: {v.text}\n")
    for note in c.notes:
        out.write(f"  note: {note}\n")
    worst = c.worst_blocks(n_worst)
    if worst:
        out.write("  largest block gaps:\n")
        block_table(worst, out)


def print_summary(results: Sequence[tuple[str, Comparison]], max_gap: float | None,
                  out: TextIO) -> None:
    """One table row per program: times, bounds, gap interval, verdict."""
    w = max(7, max(len(c.program) for _, c in results))
    out.write(f"{'program':<{w}} {'t_ref_s':>9} {'LB_s':>9} {'UB_s':>9} {'gap':>16} "
              f"{'viol':>4}  verdict\n")
    for _, c in results:
        v = c.verdict(max_gap)
        gap = format_interval(c) if c.certified else "-"
        out.write(f"{c.program:<{w}} {c.t_reference_s:>9.4f} {num(c.oracle.lower_bound_s, 4):>9} "
                  f"{num(c.oracle.upper_bound_s, 4):>9} {gap:>16} "
                  f"{len(c.reference_violations):>4}  {'ok' if v.ok else 'FAIL ' + v.status}\n")
    if max_gap is not None:
        out.write(f"gate: gap upper end (t_ref-H)/(LB-H) - 1 <= {100 * max_gap:g} % "
                  f"(H: holds)\n")


def rows_table(rows: Iterable[Mapping[str, Any]], out: TextIO, t_key: str, v_key: str,
               limit_key: str) -> None:
    """One side's JSON block rows (``plan`` or ``optimize``): time, exit speed, cause."""
    out.write(f"    {'line':>5} {'label':<8} {'kind':<8} {'length_mm':>9} {'t_s':>8} "
              f"{'v_exit':>8}  limit\n")
    isfinite = math.isfinite
    lines = []
    for r in rows:
        t = r.get(t_key) or 0.0
        v = r.get(v_key) or 0.0
        # the plain format where the value is finite (all but a few rows): num() is the
        # one rule for NaN and infinity, and a call per value costs 10^6 calls at scale
        ts = f"{t:.4f}" if isinstance(t, float) and isfinite(t) else num(t, 4)
        vs = f"{v:.1f}" if isinstance(v, float) and isfinite(v) else num(v, 1)
        lines.append(f"    {r.get('line', 0):>5} {str(r.get('label', ''))[:8]:<8} "
                     f"{str(r.get('kind', ''))[:8]:<8} {r.get('length_mm', 0.0):>9.3f} "
                     f"{ts:>8} {vs:>8}  {r.get(limit_key, '')}\n")
        if len(lines) >= 4096:
            out.write("".join(lines))
            lines.clear()
    out.write("".join(lines))


__all__ = ["block_table", "num", "print_comparison", "print_summary", "rows_table"]

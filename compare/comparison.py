"""Block-by-block comparison of a planner's profile with the oracle on the same path.

:func:`compare` takes the heuristic's :class:`~reference.planner.ReferencePlan` and the
oracle's :class:`~optimal.OptimalSolution`; :func:`compare_profiles` takes any profile
(a recorded trajectory, another planner) in place of the heuristic's.

Holds are not gaps
    Dwell (G4) and the exact-stop settle (G601/G602) are waits the program and the
    machine impose; no velocity profile avoids or shortens them. One function computes
    them (:func:`reference.holds.imposed_holds`) and both the heuristic's and the
    oracle's profiles contain them, identical, at the same breaks. ``H`` is their total
    (``Comparison.hold_s``); every time below that is called *motion time* is a total or
    block time minus its holds. The gap measures velocity planning only: it compares
    motion times.
Per program
    both total times (holds included), the oracle's certified bounds ``LB <= T* <= UB``
    (holds included) and the gap interval
    ``[(t_ref - H)/(UB - H) - 1, (t_ref - H)/(LB - H) - 1]`` (fractions, 0.12 = 12 %),
    which holds the true gap of the motion ``(t_ref - H)/(T* - H) - 1``; every violation
    :func:`check_profile` finds in either profile under the bound set that side
    declares. A program whose optimal motion time is 0 (only holds) has gap 0 when the
    planner adds no motion time either.
Per NC block (one :class:`ComparedBlock` per :class:`~reference.core.geometry.BlockSpan`,
inserted blocks on their own rows, attributed to the corner they replace)
    length, time on each side (holds included), the block's hold and its cause
    (``dwell``, ``exact stop settle``), entry/exit/peak speeds, the gap
    ``(t_ref_b - hold_b) - (t_opt_b - hold_b)`` and the limiting cause of the motion on
    each side (a block that only waits, a dwell block, shows its hold's cause on both
    sides). ``t_opt_b`` is the time the oracle's *verified* profile (duration ``UB``)
    spends in the block, so the block gaps sum to ``t_ref - UB``. A recorded trajectory
    carries its measured waits: what it waits beyond the imposed hold is a gap.

Why a block gap can be negative: the oracle minimises the total time, not each block.
Under acceleration bounds alone the exact optimum is at least as fast as any feasible
motion at *every* point of the path (the maximal velocity curve), so a negative block
gap there is the oracle's discretisation (its verified profile lies up to
``UB/LB - 1`` above the optimum). Under jerk or frequency bounds the optimum may really
be slower in one block to be faster overall (it starts braking earlier, or takes a
corner slower to accelerate sooner after it). Each such row carries a note.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Iterable

import numpy as np

from reference.core.causes import normalise_cause
from reference.core.constraints import BOUND_SETS, ConstraintReport, check_profile
from reference.core.geometry import BlockSpan, Path
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.core.rows import BlockMotion, BlockRow, block_motion
from reference.core.errors import InternalError
from reference.core.tolerances import RATIO_TOL, ROUNDOFF_MARGIN_REL

from .causes import derive_causes
from .result import (GAP_ABS_TOL_S, INSERTED_KINDS, ComparedBlock, Comparison, OracleResult,
                     Side, Verdict, block_span, describe_violation, format_interval)

if TYPE_CHECKING:                 # annotations only: the heuristic and oracle stay unloaded
    from optimal import OptimalSolution
    from reference.nc.program import Program
    from reference.planner import ReferencePlan

__all__ = ["ComparedBlock", "Comparison", "OracleResult", "Side", "Verdict",
           "block_span", "compare", "compare_profiles", "describe_violation",
           "format_interval", "oracle_result", "reference_side"]


# ---------------------------------------------------------------------- helpers
def _corners(path: Path) -> dict[int, tuple[int, int]]:
    """Inserted spans -> (line before, line after) of the corner they replace."""
    spans = path.blocks
    out: dict[int, tuple[int, int]] = {}
    for i, sp in enumerate(spans):
        if sp.kind not in INSERTED_KINDS:
            continue
        before = next((spans[k] for k in range(i - 1, -1, -1)
                       if spans[k].kind not in INSERTED_KINDS and spans[k].n_segments), None)
        after = next((spans[k] for k in range(i + 1, len(spans))
                      if spans[k].kind not in INSERTED_KINDS and spans[k].n_segments), None)
        out[i] = (before.line if before else sp.line, after.line if after else sp.line)
    return out


def _row_ratios(report: ConstraintReport, names: Iterable[str], idx: np.ndarray) -> np.ndarray:
    out = np.zeros(idx.size)
    for name in names:
        r = report.block_ratios.get(name)
        if r is not None and r.size:
            out = np.maximum(out, np.asarray(r)[np.clip(idx, 0, r.size - 1)])
    return out


def _gap_note(row_gap: float, t_opt: float, c_rel_band: float, oracle_bounds: str,
              ve_r: float, vx_r: float, ve_o: float, vx_o: float,
              breaks_limits: bool = False) -> str:
    """Explanation of a negative block gap (``""`` when there is nothing to explain)."""
    band = max(GAP_ABS_TOL_S, c_rel_band * t_opt)
    if row_gap >= -GAP_ABS_TOL_S:
        return ""
    speeds = (f"oracle enters at {ve_o:.1f} and leaves at {vx_o:.1f} mm/s, "
              f"planner at {ve_r:.1f} and {vx_r:.1f} mm/s")
    if breaks_limits:
        return (f"negative by {-1e3 * row_gap:.2f} ms: the planner breaks limits the "
                f"oracle keeps (see the violations), so it can be faster ({speeds})")
    if oracle_bounds == "acc":
        if -row_gap <= band:
            return (f"negative by {-1e3 * row_gap:.2f} ms, within the oracle's resolution "
                    f"(its verified profile is up to {100 * c_rel_band:.2f} % above the "
                    f"optimum): with acceleration bounds the exact optimum is at least as "
                    f"fast at every point of the path ({speeds})")
        return (f"negative by {-1e3 * row_gap:.2f} ms: with acceleration bounds the exact "
                f"optimum is at least as fast at every point of the path, so the oracle's "
                f"discretised profile is conservative here ({speeds})")
    return (f"negative by {-1e3 * row_gap:.2f} ms: the optimum minimises the total time, "
            f"not each block; it is slower here to be faster elsewhere ({speeds})")


# ---------------------------------------------------------------------- entry points
def compare_profiles(path: Path, limits: MachineLimits, reference: Side,
                     oracle: OracleResult, *, program: str = "", machine: str = "",
                     program_lines: tuple[str, ...] = (), notes: Iterable[str] = ()
                     ) -> Comparison:
    """Compare any planner's motion with the oracle on the same path.

    Parameters
    ----------
    path : Path
        The path both profiles run on.
    limits : MachineLimits
        Machine limits (both profiles are checked against them).
    reference : Side
        The planner under test.
    oracle : OracleResult
        The oracle's result on ``path``.
    program, machine : str
        Names for reports.
    program_lines : tuple[str, ...]
        Program source lines (for the source column and the report).
    notes : iterable of str
        Extra program-level remarks.

    Returns
    -------
    Comparison
    """
    if reference.bound_set not in BOUND_SETS:
        raise ValueError(f"unknown bound set {reference.bound_set!r}; "
                         f"known: {', '.join(BOUND_SETS)}")
    ref_prof = reference.profile
    ref_report = reference.report or check_profile(path, limits, ref_prof,
                                                   steps=reference.steps)
    opt_prof = oracle.profile
    opt_report = check_profile(path, limits, opt_prof) if opt_prof is not None else None

    spans = path.blocks
    idx = np.array([b.block for b in spans], dtype=np.int64)
    mot_r = block_motion(path, ref_prof)
    if opt_prof is not None:
        mot_o = block_motion(path, opt_prof)
    else:
        nan = np.full(len(spans), math.nan)
        mot_o = BlockMotion(nan, nan, nan, nan)
    t_ref, t_opt = mot_r.time_s, mot_o.time_s
    ve_r, vx_r, ve_o, vx_o = mot_r.v_entry, mot_r.v_exit, mot_o.v_entry, mot_o.v_exit

    by_block = {b.block: b for b in spans}
    jerk_ref = "jerk" in BOUND_SETS[reference.bound_set]
    jerk_opt = "jerk" in BOUND_SETS.get(oracle.bounds, ())
    c_ref = {b: _block_cause(v, by_block.get(b))
             for b, v in (reference.causes or {}).items()}
    if any(b.block not in c_ref for b in spans):
        derived = derive_causes(path, limits, ref_prof, jerk=jerk_ref)
        c_ref = {**derived, **c_ref}
    c_opt = {b: _block_cause(v, by_block.get(b)) for b, v in (oracle.causes or {}).items()}
    if opt_prof is not None and any(b.block not in c_opt for b in spans):
        derived = derive_causes(path, limits, opt_prof, jerk=jerk_opt)
        c_opt = {**derived, **c_opt}

    r_ref = _row_ratios(ref_report, BOUND_SETS[reference.bound_set], idx)
    breaks = bool(ref_report.violations(BOUND_SETS[reference.bound_set], reference.ratio_tol))
    r_opt = _row_ratios(opt_report, BOUND_SETS.get(oracle.bounds, ()), idx) \
        if opt_report is not None else np.full(len(spans), math.nan)
    lb, ub = oracle.lower_bound_s, oracle.upper_bound_s
    _check_certificate(path, ref_prof, ref_report, oracle)
    n_blocks = int(idx.max()) + 1 if idx.size else 0
    hold_blk = oracle.holds.per_block(n_blocks)[idx] if idx.size else np.zeros(0)
    H = oracle.holds.total_s
    # the oracle's resolution on motion times (holds are exact on both sides)
    rel_band = ((ub - H) / (lb - H) - 1.0) if (lb - H > 0 and math.isfinite(ub)) else math.inf
    corners = _corners(path)
    lines = program_lines
    rows = []
    for i, sp in enumerate(spans):
        corner = corners.get(i)
        line = corner[0] if corner else sp.line
        source = "" if corner or not (0 < sp.line <= len(lines)) else lines[sp.line - 1]
        hold = float(hold_blk[i])
        hold_cause = oracle.holds.cause_of(sp.block) if hold > 0 else ""
        gap = float((t_ref[i] - hold) - (t_opt[i] - hold))
        note = "" if math.isnan(gap) else _gap_note(
            gap, float(t_opt[i] - hold), rel_band, oracle.bounds, float(ve_r[i]),
            float(vx_r[i]), float(ve_o[i]), float(vx_o[i]), breaks)
        lim_r, lim_o = c_ref.get(sp.block, "-"), c_opt.get(sp.block, "-")
        if hold_cause and sp.n_segments == 0:
            # a block that only waits: its time is the hold on every side
            lim_r = lim_o = hold_cause
        ident = dict(block=sp.block, line=max(1, line), label=sp.label, kind=sp.kind,
                     length_mm=sp.length, hold_s=hold)
        rows.append(ComparedBlock(
            reference=BlockRow(**ident, time_s=float(mot_r.time_s[i]),
                               v_entry=float(mot_r.v_entry[i]), v_exit=float(mot_r.v_exit[i]),
                               v_peak=float(mot_r.v_peak[i]), cause=lim_r),
            oracle=BlockRow(**ident, time_s=float(mot_o.time_s[i]),
                            v_entry=float(mot_o.v_entry[i]), v_exit=float(mot_o.v_exit[i]),
                            v_peak=float(mot_o.v_peak[i]), cause=lim_o),
            source=source.strip(), corner=corner, s_start=sp.s_start,
            ratio_reference=float(r_ref[i]), ratio_oracle=float(r_opt[i]),
            stop_reason=sp.stop_reason, note=note, hold_cause=hold_cause))

    all_notes = list(notes)
    if not set(BOUND_SETS[reference.bound_set]) <= set(BOUND_SETS.get(oracle.bounds, ())):
        extra = sorted(set(BOUND_SETS[reference.bound_set]) - set(BOUND_SETS[oracle.bounds]))
        all_notes.append(
            f"The planner keeps {', '.join(extra)} limits that the {oracle.bounds!r} oracle "
            f"does not model, so the oracle solves a relaxation: its lower bound still bounds "
            f"the planner's true optimum from below (the gap's upper end, with LB, is "
            f"valid), but its upper bound is a motion the planner may not make, so "
            f"the lower end, with UB, is not a lower end of the gap (the true gap is at "
            f"least 0).")
    if H > 0 and reference.name != "reference":
        all_notes.append(
            f"The oracle waits the imposed holds the machine data give, H = {H:.4f} s "
            f"(dwell, exact-stop settle); the {reference.name} motion's own waits are "
            f"compared with them: waiting longer shows as a gap, waiting less (e.g. a "
            f"feed-forward the machine data do not state) as a negative one.")
    if oracle.status not in ("optimal",):
        all_notes.append(f"Oracle status: {oracle.status}.")
    if any(r.note for r in rows):
        all_notes.append(
            "Some blocks have a negative gap: " + (
                "the planner breaks limits the oracle keeps" if breaks else
                "the oracle minimises the total time, not each block") +
            "; see the notes on those rows.")
    return Comparison(program=program or path.source, machine=machine or limits.name,
                      reference_name=reference.name, reference_bounds=reference.bound_set,
                      oracle=oracle, path=path, limits=limits, reference_profile=ref_prof,
                      rows=tuple(rows), reference_report=ref_report, oracle_report=opt_report,
                      notes=tuple(all_notes), program_lines=tuple(program_lines),
                      reference_ratio_tol=reference.ratio_tol)


def _check_certificate(path: Path, profile: Profile, report: ConstraintReport,
                       oracle: OracleResult) -> None:
    """A profile the checker accepts under the oracle's bound set is never faster than
    the oracle's certified lower bound; if it is, the certificate is broken (a rule
    written twice, a relaxation that is not one): a bug, reported as such (exit 3),
    never printed as a negative gap with the verdict "ok".

    The comparison is exact up to :data:`ROUNDOFF_MARGIN_REL` (the bound and the profile's
    duration are sums of different round-off).
    """
    lb = oracle.lower_bound_s
    if not (math.isfinite(lb) and lb > 0) or oracle.status not in ("optimal", "gap_not_met"):
        return
    if report.violations(BOUND_SETS.get(oracle.bounds, ()), RATIO_TOL):
        return                  # the profile breaks a limit the oracle keeps: no claim
    t = profile.duration
    if t < lb * (1.0 - ROUNDOFF_MARGIN_REL):
        raise InternalError(
            f"certificate broken on {path.source or 'the path'}: a profile the checker "
            f"accepts under the {oracle.bounds!r} bounds takes {t:.9g} s, below the oracle's "
            f"lower bound {lb:.9g} s")


def _block_cause(label: str, span: BlockSpan | None = None) -> str:
    """A block's limit label in the shared vocabulary (see
    :func:`reference.core.causes.normalise_cause`)."""
    return normalise_cause(label, span.stop_reason if span is not None else None,
                      span is not None and span.n_segments == 0)


def oracle_result(solution: OptimalSolution, bounds: str = "acc") -> OracleResult:
    """The :class:`OracleResult` of an :class:`optimal.OptimalSolution`."""
    causes = {int(b.block): str(b.cause) for b in solution.blocks}
    return OracleResult(status=str(solution.status.value), profile=solution.profile,
                        lower_bound_s=float(solution.lower_bound_s),
                        upper_bound_s=float(solution.upper_bound_s), bounds=bounds,
                        solve_time_s=float(solution.total_time_s),
                        grid_points=int(solution.grid_points), causes=causes or None,
                        holds=solution.holds)


def reference_side(plan: ReferencePlan) -> Side:
    """The :class:`Side` of a :class:`reference.planner.ReferencePlan`."""
    causes = {int(row.block): str(row.cause) for row in plan.blocks if row.cause}
    return Side(name="reference", profile=plan.profile, bound_set=plan.bound_set,
                causes=causes or None, report=plan.report)


def compare(plan: ReferencePlan, solution: OptimalSolution, *,
            limits: MachineLimits | None = None, program: Program | None = None,
            machine: str = "") -> Comparison:
    """Compare the heuristic's plan with the oracle's solution on the plan's path.

    Parameters
    ----------
    plan : reference.planner.ReferencePlan
        The heuristic's result (its ``path`` is the path both sides run on).
    solution : optimal.OptimalSolution
        The oracle solved on ``plan.path``.
    limits : MachineLimits, optional
        Machine limits (default: the plan's).
    program : reference.nc.Program, optional
        The program (for source lines in the rows and reports).
    machine : str
        Machine name for reports (default: ``limits.name``).

    Returns
    -------
    Comparison
    """
    if limits is None:
        limits = plan.limits
    if not plan.holds.same_as(solution.holds):
        raise ValueError("compare(): the oracle was solved with other holds than the plan's; "
                         "pass holds=plan.holds to optimal.solve")
    lines = tuple(program.lines) if program is not None else ()
    name = program.file if program is not None else ""
    return compare_profiles(plan.path, limits, reference_side(plan),
                            oracle_result(solution, solution.bounds),
                            program=name, machine=machine, program_lines=lines)

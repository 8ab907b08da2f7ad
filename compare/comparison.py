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
from reference.core.geometry import KIND_CODES, BlockSpan, Path
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.core.rows import BlockMotion, BlockRow, block_motion
from reference.core.errors import FeedOracleError, InternalError
from reference.core.tolerances import RATIO_TOL, ROUNDOFF_MARGIN_REL
from reference.prepare import prepare, restrict_to_machine

from .causes import derive_causes, stretch_causes
from .inserted import inserted_splits, stretch_motion
from .result import (GAP_ABS_TOL_S, INSERTED_KINDS, ComparedBlock, Comparison, OracleResult,
                     Side, Verdict, block_span, describe_violation, format_interval)

if TYPE_CHECKING:                 # annotations only: the heuristic and oracle stay unloaded
    from optimal import OptimalSolution
    from reference.nc.program import Program
    from reference.planner import ReferencePlan

__all__ = ["ComparedBlock", "Comparison", "OracleResult", "Side", "Verdict",
           "block_span", "compare", "compare_profiles", "describe_violation",
           "format_interval", "oracle_result", "programmed_contour", "reference_side"]


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


def _at(mot: BlockMotion, i: int) -> tuple[float, float, float, float]:
    """(time, entry, exit, peak) of span ``i``."""
    return (float(mot.time_s[i]), float(mot.v_entry[i]), float(mot.v_exit[i]),
            float(mot.v_peak[i]))


def _split_inserted(path: Path, limits: MachineLimits, ref_prof: Profile,
                    opt_prof: Profile | None, jerk_ref: bool, jerk_opt: bool) -> dict:
    """Per span holding inserted segments (corner rounding): a function that turns the
    span's one row piece into the block's own piece followed by one piece per inserted
    block (a run of inserted segments: a clothoid pair is one rounding; see
    :func:`compare_profiles` for the piece layout).

    The inserted pieces are measured on each profile exactly
    (:func:`compare.inserted.stretch_motion`); the block keeps the rest of its time, so
    the rows still sum to each profile's duration; its limiting cause is derived from
    each motion on the stretch (:func:`compare.causes.stretch_causes`: the planners
    report causes per program block). An inserted segment at the end of
    the span (a rounding always is) ends the block's own piece: its exit speed is the
    inserted piece's entry speed and its peak is measured on the stretch before it.
    """
    splits = inserted_splits(path)
    if not splits:
        return {}
    spans = path.blocks
    runs = np.concatenate([sp.runs for sp in splits])            # (R, 2) first, last
    sb = path.s_breaks
    # the block's own stretch before its first inserted block, then each inserted one
    own0 = np.array([spans[sp.span].s_start for sp in splits])
    own1 = np.array([sb[sp.runs[0, 0]] for sp in splits])
    ins0, ins1 = sb[runs[:, 0]], sb[runs[:, 1] + 1]

    def measure(prof: Profile | None, s0: np.ndarray, s1: np.ndarray) -> np.ndarray:
        if prof is None or s0.size == 0:
            return np.full((s0.size, 4), math.nan)
        m = stretch_motion(prof, s0, s1)
        return np.column_stack((m.time_s, m.v_entry, m.v_exit, m.v_peak))

    has_own = own1 > own0
    ins_r, ins_o = measure(ref_prof, ins0, ins1), measure(opt_prof, ins0, ins1)
    own_r = np.full((len(splits), 4), math.nan)
    own_o = np.full((len(splits), 4), math.nan)
    own_r[has_own] = measure(ref_prof, own0[has_own], own1[has_own])
    own_o[has_own] = measure(opt_prof, own0[has_own], own1[has_own])
    cause_r = stretch_causes(path, limits, ref_prof, ins0, ins1, jerk_ref)
    cause_o = (stretch_causes(path, limits, opt_prof, ins0, ins1, jerk_opt)
               if opt_prof is not None else ["-"] * runs.shape[0])
    lines = {sp.block: sp.line for sp in spans}
    kinds = KIND_CODES
    out = {}
    pos = 0
    for n, split in enumerate(splits):
        i, ks, tail = split.span, split.runs, split.tail
        nk = ks.shape[0]
        rows_r, rows_o = ins_r[pos:pos + nk], ins_o[pos:pos + nk]
        cr, co = cause_r[pos:pos + nk], cause_o[pos:pos + nk]
        pos += nk
        sp = spans[i]
        corner_here = (tuple(lines.get(b, 0) for b in split.corner_blocks)
                       if split.corner_blocks is not None else (sp.line, sp.line))
        ins_len = split.inserted_length

        # every per-span value bound now: make runs after the loop has moved on
        def make(base, ks=ks, nk=nk, rows_r=rows_r, rows_o=rows_o, n=n, tail=tail, cr=cr,
                 co=co, corner_here=corner_here, ins_len=ins_len):
            kind, corner, line, source, s_start, length, stop, hold, mr, mo, lr, lo = base
            own = []
            for whole, part, own_part in ((mr, rows_r, own_r[n]), (mo, rows_o, own_o[n])):
                t = whole[0] - float(np.nansum(part[:, 0]))
                exit_ = part[0, 1] if tail else whole[2]
                peak = own_part[3] if tail and has_own[n] else whole[3]
                own.append((t, whole[1], float(exit_), float(peak)))
            pieces = [(kind, corner, line, source, s_start, length - ins_len,
                       "" if tail else stop, hold, own[0], own[1], lr, lo)]
            for j, (k, k_end) in enumerate(ks.tolist()):
                last = j == nk - 1
                pieces.append((kinds[int(path.kind[k])], corner_here, corner_here[0], "",
                               float(sb[k]), float(sb[k_end + 1] - sb[k]),
                               stop if (tail and last) else "", 0.0,
                               tuple(float(x) for x in rows_r[j]),
                               tuple(float(x) for x in rows_o[j]), cr[j], co[j]))
            return pieces

        out[i] = make
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
                     program_lines: tuple[str, ...] = (), notes: Iterable[str] = (),
                     programmed: Path | None = None) -> Comparison:
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
    programmed : Path, optional
        The programmed contour before compensation and rounding (for the tool-path
        plot; :func:`programmed_contour`).

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
    split = _split_inserted(path, limits, ref_prof, opt_prof, jerk_ref, jerk_opt)
    row_lb = _row_lower_bounds(path, oracle.segment_lower_bounds_s)
    decided = path.rounding.decision_by_block() if path.rounding is not None else {}
    rows = []
    for i, sp in enumerate(spans):
        corner = corners.get(i)
        line = corner[0] if corner else sp.line
        source = "" if corner or not (0 < sp.line <= len(lines)) else lines[sp.line - 1]
        hold = float(hold_blk[i])
        hold_cause = oracle.holds.cause_of(sp.block) if hold > 0 else ""
        lim_r, lim_o = c_ref.get(sp.block, "-"), c_opt.get(sp.block, "-")
        if hold_cause and sp.n_segments == 0:
            # a block that only waits: its time is the hold on every side
            lim_r = lim_o = hold_cause
        # (kind, corner, line, source, s_start, length, stop, hold, reference motion,
        # oracle motion, reference cause, oracle cause) per row: the block itself, then
        # its inserted blocks on rows of their own
        pieces = [(sp.kind, corner, line, source, sp.s_start, sp.length, sp.stop_reason,
                   hold, _at(mot_r, i), _at(mot_o, i), lim_r, lim_o)]
        if i in split:
            pieces = split[i](pieces[0])
        for kind, corn, ln, src, s_start, length, stop, hld, mr, mo, cr, co in pieces:
            gap = float((mr[0] - hld) - (mo[0] - hld))
            note = "" if math.isnan(gap) else _gap_note(
                gap, float(mo[0] - hld), rel_band, oracle.bounds, mr[1], mr[2], mo[1], mo[2],
                breaks)
            ident = dict(block=sp.block, line=max(1, ln), label=sp.label if corn is None
                         or corner is not None else "", kind=kind, length_mm=length,
                         hold_s=hld)
            rows.append(ComparedBlock(
                reference=BlockRow(**ident, time_s=mr[0], v_entry=mr[1], v_exit=mr[2],
                                   v_peak=mr[3], cause=cr),
                oracle=BlockRow(**ident, time_s=mo[0], v_entry=mo[1], v_exit=mo[2],
                                v_peak=mo[3], cause=co),
                source=src.strip(), corner=corn, s_start=s_start,
                ratio_reference=float(r_ref[i]), ratio_oracle=float(r_opt[i]),
                stop_reason=stop, note=note, hold_cause=hold_cause if hld > 0 else "",
                rounding=decided.get(sp.block, "") if corn is None else "",
                lb_oracle_s=hld + row_lb(s_start, length)))

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
                      reference_ratio_tol=reference.ratio_tol, programmed=programmed)


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


def _row_lower_bounds(path: Path, seg_lb: np.ndarray | None):
    """``f(s_start, length)``: the sum of the per-segment lower bounds ``seg_lb`` (s) over
    the segments whose middle lies in the row's span ``[s_start, s_start + length]``
    (rows are unions of whole segments); ``nan`` without per-segment bounds."""
    if seg_lb is None or len(seg_lb) != path.n_segments:
        return lambda s0, length: math.nan
    mid = path.s_breaks[:-1] + 0.5 * path.length
    cum = np.concatenate(([0.0], np.cumsum(np.asarray(seg_lb, dtype=np.float64))))

    def f(s0: float, length: float) -> float:
        if not (length > 0):
            return 0.0
        lo, hi = np.searchsorted(mid, [s0, s0 + length])
        return float(cum[hi] - cum[lo])
    return f


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
                        holds=solution.holds,
                        segment_lower_bounds_s=solution.segment_lower_bounds_s)


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
                            program=name, machine=machine, program_lines=lines,
                            programmed=programmed_contour(program, limits))


def programmed_contour(program: Program | None, limits: MachineLimits) -> Path | None:
    """The program's contour as programmed -- positions, lines and arcs of its blocks over
    the machine's axes, before tool radius compensation and corner rounding
    (:func:`reference.prepare.prepare`, :func:`reference.prepare.restrict_to_machine`)
    -- or ``None`` without a program or when it cannot be built (the planned path is
    then drawn alone; the path stages already reported any error)."""
    if program is None:
        return None
    try:
        return restrict_to_machine(prepare(program), limits)
    except FeedOracleError:
        return None

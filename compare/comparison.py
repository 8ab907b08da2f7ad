"""Block-by-block comparison of a planner's profile with the oracle on the same path.

:func:`compare` takes the heuristic's :class:`~reference.planner.ReferencePlan` and the
oracle's :class:`~optimal.OptimalSolution`; :func:`compare_profiles` takes any profile
(a recorded trajectory, another planner) in place of the heuristic's.

Per program
    both total times, the oracle's certified bounds ``LB <= T* <= UB`` and the gap
    interval ``[t_ref/UB - 1, t_ref/LB - 1]`` (fractions, 0.12 = 12 %), which holds the
    true gap ``t_ref/T* - 1``; every violation :func:`check_profile` finds in either
    profile under the bound set that side declares.
Per NC block (one :class:`BlockRow` per :class:`~reference.core.geometry.BlockSpan`,
inserted blocks on their own rows, attributed to the corner they replace)
    length, time on each side, entry/exit/peak speeds, the gap ``t_ref_b - t_opt_b`` and
    the limiting cause on each side. ``t_opt_b`` is the time the oracle's *verified*
    profile (duration ``UB``) spends in the block, so the block gaps sum to
    ``t_ref - UB``.

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
from dataclasses import dataclass, field
from typing import Iterable, Mapping

import numpy as np

from reference.core.causes import normalise_cause
from reference.core.constraints import BOUND_SETS, ConstraintReport, ConstraintResult, check_profile
from reference.core.geometry import BlockSpan, Path
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.core.tolerances import RATIO_TOL

from .causes import derive_causes

#: Kinds of blocks the planner inserts (they have no NC line of their own).
INSERTED_KINDS = ("rounding", "trc", "tlift")

#: Block gaps within this many seconds of zero count as zero whatever the oracle's
#: band (1 us: far below one IPO cycle, above round-off of summed interval times).
GAP_ABS_TOL_S = 1e-6


@dataclass(frozen=True, slots=True)
class Side:
    """One planner's motion on the path, as :func:`compare_profiles` needs it.

    Attributes
    ----------
    name : str
        ``"reference"`` (the heuristic), ``"recorded"`` (an imported trajectory), ...
    profile : Profile
        The motion.
    bound_set : str
        The constraint set the planner declares it keeps (a key of ``BOUND_SETS``);
        violations are judged against it.
    causes : Mapping[int, str] or None
        Limiting cause per block index as the planner reports it; derived from the
        motion (:func:`compare.causes.derive_causes`) when ``None`` or missing a block.
    report : ConstraintReport or None
        ``check_profile`` of this profile, when already computed.
    ratio_tol : float
        A constraint counts as violated above ``1 + ratio_tol``: ``RATIO_TOL`` for
        computed profiles, more for measured ones (see :mod:`compare.recorded`).
    """

    name: str
    profile: Profile
    bound_set: str
    causes: Mapping[int, str] | None = None
    report: ConstraintReport | None = None
    ratio_tol: float = RATIO_TOL


@dataclass(frozen=True, slots=True)
class OracleResult:
    """The oracle's numbers as the comparison uses them.

    Attributes
    ----------
    status : str
        ``"optimal"``, ``"gap_not_met"``, ``"infeasible"`` or ``"solver_error"``.
    profile : Profile or None
        The verified profile (duration = ``upper_bound_s``); ``None`` without one.
    lower_bound_s, upper_bound_s : float
        Certified bounds on the optimal time, s.
    bounds : str
        The bound set solved (``"acc"``, ...).
    solve_time_s : float
        Wall time of the solve, s.
    grid_points : int
        Grid size.
    causes : Mapping[int, str] or None
        Active constraint per block as the oracle reports it.
    """

    status: str
    profile: Profile | None
    lower_bound_s: float
    upper_bound_s: float
    bounds: str = "acc"
    solve_time_s: float = 0.0
    grid_points: int = 0
    causes: Mapping[int, str] | None = None


@dataclass(frozen=True, slots=True)
class BlockRow:
    """One NC block (or inserted block) of the comparison.

    Attributes
    ----------
    block : int
        Block index (``BlockSpan.block``).
    line : int
        1-based source line (for an inserted block: the line of the block ending at
        its corner).
    label : str
        Block number or label as written, ``""`` if none.
    kind : str
        ``"G0"``, ``"G1"``, ``"G2"``, ``"G3"``, ``"none"`` or an inserted kind.
    source : str
        Source text of the line (``""`` for inserted blocks).
    corner : tuple[int, int] or None
        For an inserted block: the source lines of the two blocks whose corner it
        replaces; ``None`` otherwise.
    s_start, length_mm : float
        Path position of the block start and its length, mm.
    t_reference_s, t_oracle_s : float
        Time spent in the block, s.
    v_entry_reference, v_exit_reference, v_peak_reference : float
        Path speeds, mm/s.
    v_entry_oracle, v_exit_oracle, v_peak_oracle : float
        Path speeds, mm/s.
    limit_reference, limit_oracle : str
        Limiting cause on each side (see :data:`reference.core.causes.CAUSES`).
    ratio_reference, ratio_oracle : float
        Worst ratio value/limit in the block over the side's declared constraints.
    stop_reason : str
        Why the motion rests at the block end (``""`` if it need not).
    note : str
        Explanation of a negative or unresolved gap, ``""`` otherwise.
    """

    block: int
    line: int
    label: str
    kind: str
    source: str
    corner: tuple[int, int] | None
    s_start: float
    length_mm: float
    t_reference_s: float
    t_oracle_s: float
    v_entry_reference: float
    v_exit_reference: float
    v_peak_reference: float
    v_entry_oracle: float
    v_exit_oracle: float
    v_peak_oracle: float
    limit_reference: str
    limit_oracle: str
    ratio_reference: float
    ratio_oracle: float
    stop_reason: str = ""
    note: str = ""

    @property
    def inserted(self) -> bool:
        """True for blocks the planner inserted (rounding, TRC corners, TLIFT)."""
        return self.corner is not None

    @property
    def gap_s(self) -> float:
        """``t_reference_s - t_oracle_s``, s (may be negative, see the module docstring)."""
        return self.t_reference_s - self.t_oracle_s

    @property
    def gap_rel(self) -> float:
        """Block gap relative to the oracle's block time (``nan`` for a zero time)."""
        return self.gap_s / self.t_oracle_s if self.t_oracle_s > 0 else math.nan


@dataclass(frozen=True, slots=True)
class Comparison:
    """A planner against the oracle on one program.

    Attributes
    ----------
    program : str
        Program file.
    machine : str
        Machine name.
    reference_name : str
        What the planner under test is (``"reference"``, ``"recorded"``).
    reference_bounds : str
        Bound set the planner declares (its profile is judged against it).
    oracle : OracleResult
        The oracle's numbers (``oracle.bounds`` is the bound set of the gap).
    path : Path
        The path both profiles run on.
    limits : MachineLimits
        The machine limits.
    reference_profile : Profile
        The planner's motion.
    rows : tuple[BlockRow, ...]
        One per block span, in path order.
    reference_report, oracle_report : ConstraintReport or None
        ``check_profile`` of each profile (``None`` for a missing oracle profile).
    notes : tuple[str, ...]
        Program-level remarks (relaxed bound sets, oracle status, ...).
    program_lines : tuple[str, ...]
        Source text of the program, one entry per line (for reports).
    reference_ratio_tol : float
        Violation threshold of the planner's profile (``Side.ratio_tol``).
    """

    program: str
    machine: str
    reference_name: str
    reference_bounds: str
    oracle: OracleResult
    path: Path
    limits: MachineLimits
    reference_profile: Profile
    rows: tuple[BlockRow, ...]
    reference_report: ConstraintReport
    oracle_report: ConstraintReport | None
    notes: tuple[str, ...] = ()
    program_lines: tuple[str, ...] = field(default=(), repr=False)
    reference_ratio_tol: float = RATIO_TOL

    # ------------------------------------------------------------------ totals
    @property
    def t_reference_s(self) -> float:
        """Total time of the planner under test, s."""
        return self.reference_profile.duration

    @property
    def t_oracle_s(self) -> float:
        """Duration of the oracle's verified profile, s (``nan`` without one)."""
        return self.oracle.profile.duration if self.oracle.profile is not None else math.nan

    @property
    def bounds(self) -> str:
        """Bound set of the oracle (the ``bounds`` field of the JSON contract)."""
        return self.oracle.bounds

    @property
    def certified(self) -> bool:
        """True when the oracle produced both bounds (any status but a failure)."""
        lb, ub = self.oracle.lower_bound_s, self.oracle.upper_bound_s
        return math.isfinite(lb) and math.isfinite(ub) and lb > 0 and ub >= lb \
            and self.oracle.status in ("optimal", "gap_not_met")

    @property
    def gap_lower(self) -> float:
        """``t_ref / UB - 1``: the true gap is at least this (see :attr:`gap_lower_valid`)."""
        ub = self.oracle.upper_bound_s
        return self.t_reference_s / ub - 1.0 if ub > 0 else math.nan

    @property
    def gap_upper(self) -> float:
        """``t_ref / LB - 1``: the true gap is at most this (``inf`` for LB = 0)."""
        lb = self.oracle.lower_bound_s
        return self.t_reference_s / lb - 1.0 if lb > 0 else math.inf

    @property
    def gap_lower_valid(self) -> bool:
        """False when the oracle solved a relaxation of the planner's bound set.

        The oracle's lower bound then still bounds the stricter optimum from below (so
        :attr:`gap_upper` stays a valid upper end), but its upper bound is a motion the
        planner is not allowed to make, so :attr:`gap_lower` is only the gap to the
        relaxed optimum, not a lower end of the true gap.
        """
        return set(BOUND_SETS.get(self.reference_bounds, ())) <= set(
            BOUND_SETS.get(self.oracle.bounds, ()))

    # ------------------------------------------------------------------ checks
    @property
    def reference_violations(self) -> tuple[ConstraintResult, ...]:
        """Violations of the planner's declared bound set in its profile."""
        return self.reference_report.violations(BOUND_SETS[self.reference_bounds],
                                                self.reference_ratio_tol)

    @property
    def oracle_violations(self) -> tuple[ConstraintResult, ...]:
        """Violations of the oracle's bound set in its verified profile (a bug if any)."""
        if self.oracle_report is None:
            return ()
        return self.oracle_report.violations(BOUND_SETS[self.oracle.bounds])

    def worst_blocks(self, n: int = 5) -> tuple[BlockRow, ...]:
        """The ``n`` rows with the largest positive block gap, largest first."""
        rows = [r for r in self.rows if r.gap_s > GAP_ABS_TOL_S]
        return tuple(sorted(rows, key=lambda r: -r.gap_s)[:n])

    def verdict(self, max_gap: float | None = None) -> "Verdict":
        """Pass/fail of the program (see :class:`Verdict`)."""
        return Verdict.of(self, max_gap)


@dataclass(frozen=True, slots=True)
class Verdict:
    """Outcome of one comparison: ``ok`` decides the exit code.

    Attributes
    ----------
    ok : bool
        False on a violation in either profile, an oracle without certified bounds, or
        (with a gate) a gap upper end above ``max_gap``.
    status : str
        ``"ok"``, ``"gap above gate"``, ``"violation"``, ``"oracle violation"`` or
        ``"no certificate"``.
    text : str
        One sentence for people.
    max_gap : float or None
        The gate (fraction), if any.
    """

    ok: bool
    status: str
    text: str
    max_gap: float | None

    @classmethod
    def of(cls, c: Comparison, max_gap: float | None) -> "Verdict":
        """Decide the verdict of a comparison.

        The gate compares the *upper* end ``t_ref/LB - 1`` with ``max_gap``: a program
        passes only when its gap is certified to be at most ``max_gap``.
        """
        who = "the recorded trajectory" if c.reference_name == "recorded" else "the heuristic"
        if c.reference_violations:
            v = c.reference_violations[0]
            more = len(c.reference_violations) - 1
            return cls(False, "violation",
                       f"{who} breaks a limit it must keep: {describe_violation(v, c)}"
                       + (f" (and {more} more)" if more else ""), max_gap)
        if c.oracle_violations:
            v = c.oracle_violations[0]
            return cls(False, "oracle violation",
                       f"the oracle's verified profile breaks a limit (an oracle bug): "
                       f"{describe_violation(v, c)}", max_gap)
        if not c.certified:
            if c.oracle.status in ("optimal", "gap_not_met") and c.oracle.lower_bound_s == 0:
                # solved, but a zero lower bound certifies nothing (no motion): say so
                return cls(False, "no certificate",
                           "the oracle's lower bound is 0 s (the path has no motion), so "
                           "the gap t_ref/LB - 1 is undefined", max_gap)
            return cls(False, "no certificate",
                       f"the oracle gave no certified bounds (status {c.oracle.status})",
                       max_gap)
        gap = format_interval(c)
        if max_gap is not None and c.gap_upper > max_gap:
            return cls(False, "gap above gate",
                       f"{who} may be up to {100 * c.gap_upper:.1f} % slower than the "
                       f"optimum, above the gate of {100 * max_gap:g} % (gap {gap})", max_gap)
        if c.gap_lower_valid:
            text = f"{who} is {gap} slower than the time-optimal motion"
        else:
            text = (f"{who} is at most {100 * c.gap_upper:.1f} % slower than the optimum "
                    f"under its own ({c.reference_bounds}) limits; {gap} against the "
                    f"{c.oracle.bounds}-bounded relaxation")
        if max_gap is not None:
            text += f" (within the gate of {100 * max_gap:g} %)"
        return cls(True, "ok", text, max_gap)


# ---------------------------------------------------------------------- helpers
def format_interval(c: Comparison) -> str:
    """The gap interval in percent, e.g. ``"12.1 – 12.4 %"``."""
    lo, hi = c.gap_lower, c.gap_upper
    if not math.isfinite(hi):
        return f"≥ {100 * lo:.1f} %"
    return f"{100 * lo:.1f} – {100 * hi:.1f} %"


def describe_violation(v: ConstraintResult, c: Comparison) -> str:
    """One line naming a violation: constraint, axis, value, limit, ratio and place."""
    span = block_span(c.path, v.block)
    where = f"s = {v.s:.3f} mm, t = {v.t:.4f} s"
    if span is not None:
        lab = f" {span.label}" if span.label else ""
        where += f", line {span.line}{lab}"
    if v.constraint == "stop":
        k = int(np.argmin(np.abs(c.path.s_breaks - v.s))) if c.path.n_segments else 0
        reason = c.path.stop_reason[k] if c.path.n_segments else ""
        return (f"no stop where the path requires rest ({reason or 'stop'}): "
                f"{v.value:.4g} mm/s at {where}")
    axis = f" on {v.axis}" if v.axis else ""
    ratio = "inf" if not math.isfinite(v.ratio) else f"{v.ratio:.3f}"
    return (f"{v.constraint}{axis} {v.value:.4g} {v.unit} > limit {v.limit:.4g} {v.unit} "
            f"(ratio {ratio}) at {where}")


def block_span(path: Path, block: int) -> BlockSpan | None:
    """The span of a block index, ``None`` if the path has none."""
    for span in path.blocks:
        if span.block == block:
            return span
    return None


def block_speeds(path: Path, profile: Profile) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Entry, exit and peak path speed of every block span.

    Parameters
    ----------
    path : Path
    profile : Profile

    Returns
    -------
    v_entry, v_exit, v_peak : numpy.ndarray, shape (len(path.blocks),)
        mm/s, in ``path.blocks`` order. Entry is the speed on leaving the block start
        (after any hold there), exit the speed on arriving at its end.
    """
    spans = path.blocks
    cuts = [b.s_end for b in spans if b.s_end > b.s_start]
    prof = profile.split_at(cuts)
    s0 = np.array([b.s_start for b in spans])
    s1 = np.array([b.s_end for b in spans])
    K = prof.n_intervals
    k_dep = np.clip(np.searchsorted(prof.s, s0, side="right") - 1, 0, prof.s.size - 1)
    k_arr = np.clip(np.searchsorted(prof.s, s1, side="left"), 0, prof.s.size - 1)
    v_entry, v_exit = prof.v[k_dep], prof.v[k_arr]
    # peak: knots and stationary points of v inside each interval, per block
    h = np.diff(prof.t)
    with np.errstate(divide="ignore", invalid="ignore"):
        ts = np.where(prof.j != 0, -prof.a / np.where(prof.j != 0, prof.j, 1.0), -1.0)
    inside = (ts > 0) & (ts < h)
    ts = np.where(inside, ts, 0.0)
    v_in = np.where(inside, prof.v[:-1] + prof.a * ts + prof.j * ts ** 2 / 2, 0.0)
    v_int = np.maximum(np.maximum(prof.v[:-1], prof.v[1:]), v_in) if K else np.zeros(0)
    blk = prof.interval_blocks(path)
    n_blocks = max(b.block for b in spans) + 1 if spans else 0
    peak = np.zeros(n_blocks)
    if K:
        np.maximum.at(peak, blk, v_int)
    idx = np.array([b.block for b in spans], dtype=np.int64)
    v_peak = np.maximum(peak[idx], np.maximum(v_entry, v_exit))
    return v_entry, v_exit, v_peak


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
    ref_report = reference.report or check_profile(path, limits, ref_prof)
    opt_prof = oracle.profile
    opt_report = check_profile(path, limits, opt_prof) if opt_prof is not None else None

    spans = path.blocks
    idx = np.array([b.block for b in spans], dtype=np.int64)
    t_ref = ref_prof.block_times(path)[idx] if spans else np.zeros(0)
    ve_r, vx_r, vp_r = block_speeds(path, ref_prof) if spans else (np.zeros(0),) * 3
    if opt_prof is not None and spans:
        t_opt = opt_prof.block_times(path)[idx]
        ve_o, vx_o, vp_o = block_speeds(path, opt_prof)
    else:
        t_opt = ve_o = vx_o = vp_o = np.full(len(spans), math.nan)

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
    rel_band = (ub / lb - 1.0) if (lb > 0 and math.isfinite(ub)) else math.inf
    corners = _corners(path)
    lines = program_lines
    rows = []
    for i, sp in enumerate(spans):
        corner = corners.get(i)
        line = corner[0] if corner else sp.line
        source = "" if corner or not (0 < sp.line <= len(lines)) else lines[sp.line - 1]
        gap = float(t_ref[i] - t_opt[i])
        note = "" if math.isnan(gap) else _gap_note(
            gap, float(t_opt[i]), rel_band, oracle.bounds, float(ve_r[i]), float(vx_r[i]),
            float(ve_o[i]), float(vx_o[i]), breaks)
        rows.append(BlockRow(
            block=sp.block, line=max(1, line), label=sp.label, kind=sp.kind,
            source=source.strip(), corner=corner, s_start=sp.s_start,
            length_mm=sp.length, t_reference_s=float(t_ref[i]), t_oracle_s=float(t_opt[i]),
            v_entry_reference=float(ve_r[i]), v_exit_reference=float(vx_r[i]),
            v_peak_reference=float(vp_r[i]), v_entry_oracle=float(ve_o[i]),
            v_exit_oracle=float(vx_o[i]), v_peak_oracle=float(vp_o[i]),
            limit_reference=c_ref.get(sp.block, "-"), limit_oracle=c_opt.get(sp.block, "-"),
            ratio_reference=float(r_ref[i]), ratio_oracle=float(r_opt[i]),
            stop_reason=sp.stop_reason, note=note))

    all_notes = list(notes)
    if not set(BOUND_SETS[reference.bound_set]) <= set(BOUND_SETS.get(oracle.bounds, ())):
        extra = sorted(set(BOUND_SETS[reference.bound_set]) - set(BOUND_SETS[oracle.bounds]))
        all_notes.append(
            f"The planner keeps {', '.join(extra)} limits that the {oracle.bounds!r} oracle "
            f"does not model, so the oracle solves a relaxation: its lower bound still bounds "
            f"the planner's true optimum from below (t_ref/LB - 1 is a valid upper end of "
            f"the gap), but its upper bound is a motion the planner may not make, so "
            f"t_ref/UB - 1 is not a lower end of the gap (the true gap is at least 0).")
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


def _block_cause(label: str, span: BlockSpan | None = None) -> str:
    """A block's limit label in the shared vocabulary (see
    :func:`reference.core.causes.normalise_cause`)."""
    return normalise_cause(label, span.stop_reason if span is not None else None,
                      span is not None and span.n_segments == 0)


def oracle_result(solution, bounds: str = "acc") -> OracleResult:
    """The :class:`OracleResult` of an ``optimal.OptimalSolution``."""
    status = getattr(solution.status, "value", solution.status)
    causes = {int(b.block): str(b.limit_oracle) for b in getattr(solution, "blocks", ())}
    total = getattr(solution, "total_time_s", None)
    return OracleResult(status=str(status), profile=solution.profile,
                        lower_bound_s=float(solution.lower_bound_s),
                        upper_bound_s=float(solution.upper_bound_s), bounds=bounds,
                        solve_time_s=float(total if total is not None else solution.solve_time_s),
                        grid_points=int(solution.grid_points), causes=causes or None)


def reference_side(plan) -> Side:
    """The :class:`Side` of a ``reference.planner.ReferencePlan``."""
    causes = {}
    for row in getattr(plan, "blocks", ()) or ():
        blk = getattr(row, "block", None)
        cause = None
        for name in ("limit", "limit_cause", "cause", "limit_reference"):
            cause = getattr(row, name, None)
            if cause:
                break
        if blk is not None and cause:
            causes[int(blk)] = str(cause)
    return Side(name="reference", profile=plan.profile,
                bound_set=str(getattr(plan, "bound_set", "acc")), causes=causes or None,
                report=getattr(plan, "report", None))


def compare(plan, solution, *, limits: MachineLimits | None = None, program=None,
            machine: str = "") -> Comparison:
    """Compare the heuristic's plan with the oracle's solution on the plan's path.

    Parameters
    ----------
    plan : reference.planner.ReferencePlan
        The heuristic's result (its ``path`` is the path both sides run on).
    solution : optimal.OptimalSolution
        The oracle solved on ``plan.path``.
    limits : MachineLimits, optional
        Machine limits; taken from the plan when it carries them.
    program : reference.nc.Program, optional
        The program (for source lines in the rows and reports).
    machine : str
        Machine name for reports (default: ``limits.name``).

    Returns
    -------
    Comparison
    """
    if limits is None:
        limits = getattr(plan, "limits", None) or getattr(getattr(plan, "machine", None),
                                                          "limits", None)
    if limits is None:
        raise ValueError("compare() needs the machine limits: pass limits=machine.limits")
    lines = tuple(getattr(program, "lines", ()) or ())
    name = getattr(program, "file", "") if program is not None else ""
    return compare_profiles(plan.path, limits, reference_side(plan), oracle_result(solution),
                            program=name, machine=machine, program_lines=lines)

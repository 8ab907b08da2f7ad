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
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Iterable, Mapping

import numpy as np

from reference.core.causes import normalise_cause
from reference.core.constraints import BOUND_SETS, ConstraintReport, ConstraintResult, check_profile
from reference.core.geometry import BlockSpan, Path
from reference.core.holds import NO_HOLDS, Holds
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.core.rows import BlockMotion, BlockRow, block_motion
from reference.core.errors import InternalError
from reference.core.tolerances import RATIO_TOL, ROUNDOFF_MARGIN_REL

from .causes import derive_causes

if TYPE_CHECKING:                 # annotations only: the heuristic and oracle stay unloaded
    from optimal import OptimalSolution
    from reference.nc.program import Program
    from reference.planner import ReferencePlan

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
    holds : Holds
        The imposed holds contained in ``profile`` and in both bounds.
    """

    status: str
    profile: Profile | None
    lower_bound_s: float
    upper_bound_s: float
    bounds: str = "acc"
    solve_time_s: float = 0.0
    grid_points: int = 0
    causes: Mapping[int, str] | None = None
    holds: Holds = NO_HOLDS


@dataclass(frozen=True, slots=True)
class ComparedBlock:
    """One NC block (or inserted block) of the comparison: the two sides' rows of the one
    row model (:class:`reference.core.rows.BlockRow`) side by side, and what relates them.

    Attributes
    ----------
    reference, oracle : BlockRow
        Each side's row (the oracle's with ``nan`` speeds and times when it has no
        profile). Both carry the block's identity (``block``, ``line``: for an inserted
        block the line of the block ending at its corner, ``label``, ``kind``,
        ``length_mm``), its time with the imposed hold included, speeds and cause.
    source : str
        Source text of the line (``""`` for inserted blocks).
    corner : tuple[int, int] or None
        For an inserted block: the source lines of the two blocks whose corner it
        replaces; ``None`` otherwise.
    s_start : float
        Path position of the block start, mm.
    ratio_reference, ratio_oracle : float
        Worst ratio value/limit in the block over the side's declared constraints.
    stop_reason : str
        Why the motion rests at the block end (``""`` if it need not).
    note : str
        Explanation of a negative or unresolved gap, ``""`` otherwise.
    hold_cause : str
        ``"dwell"``, ``"exact stop settle"`` or ``""`` (no hold).

    The flat names of the JSON and CSV contract (``t_reference_s``, ``v_exit_oracle``,
    ``limit_reference``, ``hold_s``, ...) are properties reading the two rows.
    """

    reference: BlockRow
    oracle: BlockRow
    source: str
    corner: tuple[int, int] | None
    s_start: float
    ratio_reference: float
    ratio_oracle: float
    stop_reason: str = ""
    note: str = ""
    hold_cause: str = ""

    # identity and the contract's flat names
    block = property(lambda self: self.reference.block, doc="Block index.")
    line = property(lambda self: self.reference.line, doc="1-based source line.")
    label = property(lambda self: self.reference.label, doc="Block number or label.")
    kind = property(lambda self: self.reference.kind, doc="G0, G1, ... or inserted kind.")
    length_mm = property(lambda self: self.reference.length_mm, doc="Block length, mm.")
    hold_s = property(lambda self: self.reference.hold_s,
                      doc="Imposed hold in the block, s (in both times, never in the gap).")
    t_reference_s = property(lambda self: self.reference.time_s, doc="s")
    t_oracle_s = property(lambda self: self.oracle.time_s, doc="s")
    v_entry_reference = property(lambda self: self.reference.v_entry, doc="mm/s")
    v_exit_reference = property(lambda self: self.reference.v_exit, doc="mm/s")
    v_peak_reference = property(lambda self: self.reference.v_peak, doc="mm/s")
    v_entry_oracle = property(lambda self: self.oracle.v_entry, doc="mm/s")
    v_exit_oracle = property(lambda self: self.oracle.v_exit, doc="mm/s")
    v_peak_oracle = property(lambda self: self.oracle.v_peak, doc="mm/s")
    limit_reference = property(lambda self: self.reference.cause, doc="cause word")
    limit_oracle = property(lambda self: self.oracle.cause, doc="cause word")

    @property
    def inserted(self) -> bool:
        """True for blocks the planner inserted (rounding, TRC corners, TLIFT)."""
        return self.corner is not None

    @property
    def gap_s(self) -> float:
        """Motion-time gap ``(t_reference_s - hold_s) - (t_oracle_s - hold_s)``, s (may be
        negative, see the module docstring); the hold never counts."""
        return (self.t_reference_s - self.hold_s) - (self.t_oracle_s - self.hold_s)

    @property
    def gap_rel(self) -> float:
        """Block gap relative to the oracle's motion time in the block (``nan`` when the
        oracle does not move there, e.g. a dwell block)."""
        motion = self.t_oracle_s - self.hold_s
        return self.gap_s / motion if motion > GAP_ABS_TOL_S else math.nan


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
    rows : tuple[ComparedBlock, ...]
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
    rows: tuple[ComparedBlock, ...]
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
    def hold_s(self) -> float:
        """``H``: the imposed holds (dwell, exact-stop settle) in both totals, s."""
        return self.oracle.holds.total_s

    @property
    def gap_lower(self) -> float:
        """``(t_ref - H)/(UB - H) - 1``: the true gap is at least this (see
        :attr:`gap_lower_valid`); motion times, the holds ``H`` excluded."""
        return _motion_ratio(self.t_reference_s, self.oracle.upper_bound_s, self.hold_s,
                             math.nan)

    @property
    def gap_upper(self) -> float:
        """``(t_ref - H)/(LB - H) - 1``: the true gap is at most this (``inf`` when the
        lower bound has no motion time but the planner has)."""
        return _motion_ratio(self.t_reference_s, self.oracle.lower_bound_s, self.hold_s,
                             math.inf)

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

    def worst_blocks(self, n: int = 5) -> tuple[ComparedBlock, ...]:
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

        The gate compares the *upper* end ``(t_ref - H)/(LB - H) - 1`` with ``max_gap``: a program
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
def _motion_ratio(t_ref: float, t_opt: float, hold: float, undefined: float) -> float:
    """``(t_ref - hold)/(t_opt - hold) - 1``; 0 when neither side has motion time,
    ``undefined`` when only the planner has."""
    if not t_opt > 0:
        return undefined
    m_ref = t_ref - hold
    m_opt = t_opt - hold
    if m_opt <= GAP_ABS_TOL_S:
        return 0.0 if m_ref <= GAP_ABS_TOL_S else undefined
    return m_ref / m_opt - 1.0


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
    return compare_profiles(plan.path, limits, reference_side(plan), oracle_result(solution),
                            program=name, machine=machine, program_lines=lines)

"""Result types of the comparison: what :func:`compare.comparison.compare` returns.

:class:`Side` and :class:`OracleResult` are the two inputs as the comparison needs them,
:class:`ComparedBlock` one row (two :class:`reference.core.rows.BlockRow` side by side),
:class:`Comparison` a whole program with its gap interval and :class:`Verdict`. The
definitions of the gap and of the holds are in :mod:`compare.comparison`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from reference.core.constraints import BOUND_SETS, ConstraintReport, ConstraintResult
from reference.core.geometry import BlockSpan, Path
from reference.core.holds import NO_HOLDS, Holds
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.core.rows import INSERTED_KINDS, BlockRow
from reference.core.rules import STEPS_AT_BREAKS
from reference.core.tolerances import RATIO_TOL

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
    steps : str
        Where its acceleration may step (``check_profile``'s ``steps``): ``"breaks"``
        for a planned motion, ``"spread"`` for a recording sampled at the IPO cycle.
    """

    name: str
    profile: Profile
    bound_set: str
    causes: Mapping[int, str] | None = None
    report: ConstraintReport | None = None
    ratio_tol: float = RATIO_TOL
    steps: str = STEPS_AT_BREAKS


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
    segment_lower_bounds_s : numpy.ndarray, shape (m,), optional
        Certified per-segment lower bounds of the motion time, s (where the method
        gives them: ``jerk``).
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
    segment_lower_bounds_s: np.ndarray | None = None


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
    rounding : str
        For a block whose end is a corner in a rounding mode (G641..G645, RND/RNDM):
        ``"rounded"`` or ``"none: <reason>"``, the rounding stage's decision
        (:meth:`reference.core.rounding.RoundingTable.decision_by_block`); ``""``
        otherwise and on inserted rows.
    lb_oracle_s : float
        Certified lower bound of the row's time, s (its hold plus the oracle's
        per-segment lower bounds of the segments in the row); ``nan`` where the oracle
        gives none. The planner's time is never below it.

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
    rounding: str = ""
    lb_oracle_s: float = math.nan

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
        One per block span, in path order, each followed by the blocks inserted at its
        end (corner rounding) on rows of their own.
    reference_report, oracle_report : ConstraintReport or None
        ``check_profile`` of each profile (``None`` for a missing oracle profile).
    notes : tuple[str, ...]
        Program-level remarks (relaxed bound sets, oracle status, ...).
    program_lines : tuple[str, ...]
        Source text of the program, one entry per line (for reports).
    reference_ratio_tol : float
        Violation threshold of the planner's profile (``Side.ratio_tol``).
    programmed : Path or None
        The programmed contour over the same axes, before tool radius compensation and
        corner rounding (:func:`reference.prepare.prepare`), for the tool-path plot;
        ``None`` when the program is not at hand (then ``path`` is drawn alone).
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
    programmed: Path | None = None

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

    @property
    def reference_bounds_optimum(self) -> bool:
        """True when the planner's own motion is faster than the oracle's verified one
        (``t_ref < UB``, so :attr:`gap_lower` < 0) and meets every limit of the oracle's
        bound set: that motion is then itself a verified upper bound on the optimum (the
        oracle's is loose there), so the true gap is at least 0. The interval of DESIGN 7
        is reported as it is; the verdict and the report say this beside it."""
        return bool(self.gap_lower < 0 and self.reference_report is not None
                    and self.reference_report.ok(BOUND_SETS[self.oracle.bounds]))

    # ------------------------------------------------------------------ checks
    @property
    def reference_violations(self) -> tuple[ConstraintResult, ...]:
        """Violations of the planner's declared bound set in its profile."""
        return self.reference_report.violations(BOUND_SETS[self.reference_bounds],
                                                self.reference_ratio_tol)

    @property
    def stricter_violations(self) -> tuple[ConstraintResult, ...]:
        """Violations, in the planner's profile, of the limits the oracle's bound set adds
        to the planner's (``jerk+freq`` asked for a planner that declares ``jerk``: the
        frequency rule). The planner is then compared with an optimum it is not held to,
        and may be faster than its certified lower bound without a broken certificate."""
        extra = tuple(sorted(set(BOUND_SETS.get(self.oracle.bounds, ()))
                             - set(BOUND_SETS.get(self.reference_bounds, ()))))
        if not extra or self.reference_report is None:
            return ()
        return self.reference_report.violations(extra, self.reference_ratio_tol)

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
            if c.oracle.status in ("optimal", "gap_not_met") and c.oracle.lower_bound_s == 0:
                # solved, but a zero lower bound certifies nothing (no motion): say so
                return cls(False, "no certificate",
                           "the oracle's lower bound is 0 s (the path has no motion), so "
                           "the gap t_ref/LB - 1 is undefined", max_gap)
            return cls(False, "no certificate",
                       f"the oracle gave no certified bounds (status {c.oracle.status})",
                       max_gap)
        gap = format_interval(c)
        beaten = c.reference_bounds_optimum
        if beaten:
            gap = f"0.0 – {_pct(c.gap_upper)} %"
        if max_gap is not None and c.gap_upper > max_gap:
            return cls(False, "gap above gate",
                       f"{who} may be up to {100 * c.gap_upper:.1f} % slower than the "
                       f"optimum, above the gate of {100 * max_gap:g} % (gap {gap})", max_gap)
        stricter = c.stricter_violations
        if stricter:
            # like with like fails the other way round: the oracle solved a stricter set
            # than the planner keeps, and the planner breaks what it adds; a negative gap
            # is then that rule, not a gain
            text = (f"{who} keeps its own ({c.reference_bounds}) limits but not the "
                    f"stricter {c.oracle.bounds} set the oracle solved: "
                    f"{describe_violation(stricter[0], c)}; against that optimum it is "
                    f"{gap} slower, which is not its gap to an optimum it is held to "
                    f"(--bounds auto compares it under its own set)")
        elif c.gap_lower_valid:
            text = f"{who} is {gap} slower than the time-optimal motion"
        else:
            text = (f"{who} is at most {100 * c.gap_upper:.1f} % slower than the optimum "
                    f"under its own ({c.reference_bounds}) limits; {gap} against the "
                    f"{c.oracle.bounds}-bounded relaxation")
        if max_gap is not None:
            text += f" (within the gate of {100 * max_gap:g} %)"
        if c.oracle.status != "optimal":
            # the bounds are valid but the oracle stopped before its tolerance: say how
            # wide the bracket is, never a bare "ok"
            lb, ub = c.oracle.lower_bound_s, c.oracle.upper_bound_s
            text += (f"; the oracle ended '{c.oracle.status}' with a bracket "
                     f"UB/LB - 1 = {100 * (ub / lb - 1):.2f} %, so the interval is that wide")
        if beaten:
            text += (f"; {who}'s own motion is faster than the oracle's verified one "
                     f"(t_ref/UB - 1 = {_pct(c.gap_lower)} %) and meets the same "
                     f"{c.oracle.bounds} limits, so it bounds the optimum from above and "
                     f"the gap is at least 0")
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
        return f"≥ {_pct(lo)} %"
    return f"{_pct(lo)} – {_pct(hi)} %"


def _pct(x: float) -> str:
    """A fraction in percent with one decimal; a value that rounds to zero prints "0.0",
    never "-0.0" (a negative zero reads like a planner faster than the optimum)."""
    s = f"{100 * x:.1f}"
    return "0.0" if s == "-0.0" else s


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
    what = f" ({v.detail})" if v.detail else ""
    return (f"{v.constraint}{axis} {v.value:.4g} {v.unit} > limit {v.limit:.4g} {v.unit} "
            f"(ratio {ratio}) at {where}{what}")


def block_span(path: Path, block: int) -> BlockSpan | None:
    """The span of a block index, ``None`` if the path has none."""
    for span in path.blocks:
        if span.block == block:
            return span
    return None

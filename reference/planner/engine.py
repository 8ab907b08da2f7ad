"""The reference planner: composition of the stages into a :class:`ReferencePlan`.

Stage order (spec/sinumerik-model.md 12.3; TRC and tangential control come in a later
issue):

``build_path`` (program -> path, :mod:`reference.prepare`, corner rounding of
G641..G645 included, :mod:`reference.rounding`; the trace lists what it decided) -> ``stops`` (acceleration
modes, forced stops) -> ``limit curves`` (segment caps, tangential limits) -> ``corners``
(junction limits) -> ``lookahead`` (horizon caps, planning units, passes) -> ``profiles``
(unit profiles) -> ``smoothing`` (LOOKAH_SMOOTH_FACTOR) -> ``adaptation``
(ADAPT_PATH_DYNAMIC) -> ``holds`` (dwell and exact-stop settle,
:func:`reference.holds.imposed_holds`: the machine's waits, not the planner's) -> assembly
of the :class:`~reference.core.profile.Profile` -> ``check`` (the planner's own profile
against its declared bound set).

Each stage is a pure function of data to data; this module only composes them, records
the stage trace and derives the per-block and per-corner rows. The result types live in
:mod:`reference.planner.result` (re-exported here).
"""

from __future__ import annotations

import time
from collections import Counter
from dataclasses import fields
from itertools import compress
from typing import Callable, NamedTuple

import numpy as np

from ..core.arrays import readonly
from ..core.constraints import BOUND_SETS, check_profile
from ..core.geometry import Path
from ..core.holds import SETTLE_CAUSE, Holds, with_holds
from ..core.profile import Profile
from ..core.rounding import ROUNDING_REASONS
from ..holds import imposed_holds
from ..machine import Machine
from ..nc.program import Program
from ..prepare import build_path
from . import causes as C
from .adaptation import adaptation_factors, adapted_units
from .corners import junction_limits
from .limit_curves import segment_limits
from .lookahead import (NodeSpeeds, Units, cruise_splits, horizon_caps, lookahead_passes,
                        planning_units)
from .parameters import CAUSE_REL_TOL, DEFAULT_PARAMETERS, PlannerParameters
from .profiles import (CASE_FALL_ACC, CASE_RISE_ACC, UnitProfiles, case_name,
                       unit_profiles)
from .result import (BlockTable, CornerRow, CornerTable, ReferencePlan,
                     TraceEntry)
from .smoothing import effective_factor, smooth_velocity
from .stops import ACCEL_MODES, MODE_CODE, SegmentModes, segment_modes

Progress = Callable[[str, float], None]



def rounding_note(path: Path) -> str:
    """Stage-trace note of the rounding stage (:func:`reference.rounding.round_corners`):
    corners rounded per mode and, per reason, the corners left sharp."""
    table = path.rounding
    if table is None or table.n == 0:
        return "no corner in G641..G645"
    ins = table.inserted
    # counted over the tuple of mode names (an array of 10^4 strings costs more to build
    # than the counts)
    kinds = set(table.mode)
    if len(kinds) == 1:             # one mode at every corner (most programs): no counting
        n_all, n_in = {md: table.n for md in kinds}, {md: int(ins.sum()) for md in kinds}
    else:
        n_all = Counter(table.mode)
        n_in = Counter(compress(table.mode, ins.tolist()))
    per_mode = ", ".join(f"{md} {n_in[md]}/{n_all[md]}" for md in sorted(n_all))
    left = np.bincount(table.reason[~ins], minlength=len(ROUNDING_REASONS))
    order = sorted(np.flatnonzero(left), key=lambda r: (-left[r], ROUNDING_REASONS[r]))
    why = "; ".join(f"{left[r]} {ROUNDING_REASONS[r]}" for r in order)
    across = int(np.sum(table.blocks_spanned > 2))
    n_inside = int(np.sum(table.internal))
    n_tr = int(np.sum(table.g2 & table.tangential))
    n_g2 = int(np.sum(table.g2)) - n_tr
    return (f"{int(ins.sum())} of {table.n} corners in G641..G645 rounded ({n_g2} by "
            f"clothoid pairs, {int(ins.sum()) - n_g2 - n_tr} by tangent arcs"
            + (f", {n_tr} G645 tangential transitions" if n_tr else "") + "; "
            f"{per_mode}; {float(table.length_mm.sum()):.6g} mm of rounding"
            + (f"; {across} across short blocks" if across else "")
            + (f"; {n_inside} inside the blocks (G643)" if n_inside else "") + ")"
            + (f"; no rounding block: {why}" if why else ""))


# ----------------------------------------------------------------- composition
def _noop(stage: str, fraction: float) -> None:
    return None


def _plan_changed(units: Units, v_nodes: np.ndarray, old_units: Units,
                  old_prof: UnitProfiles, old_v: np.ndarray) -> UnitProfiles:
    """:func:`_plan_all`, the rows of units that were planned before (the same segments
    between the same node speeds) taken from ``old_prof``: a unit's profile depends on
    its own segments' cap and limits and its end speeds only, so this is what planning
    every unit again gives, element by element."""
    first, old_first = units.first_segment, old_units.first_segment
    j = np.minimum(np.searchsorted(old_first, first), max(old_first.size - 1, 0))
    same = np.zeros(first.size, dtype=bool)
    if old_first.size:
        same = ((old_first[j] == first) & (old_units.n_segments[j] == units.n_segments)
                & (old_v[j] == v_nodes[:-1]) & (old_v[j + 1] == v_nodes[1:]))
    new = np.flatnonzero(~same)
    part = _replan(units, new, v_nodes)
    if new.size == first.size:
        return part
    # every row gathered from its old unit, then the planned ones overwritten: a cuts
    # pass changes a few units, and a full gather costs less than a masked one
    out = {}
    for f in fields(UnitProfiles):
        arr = getattr(old_prof, f.name).take(j, axis=0)
        arr[new] = getattr(part, f.name)
        out[f.name] = arr
    return UnitProfiles(**out)


def _replan(units: Units, idx: np.ndarray, v_nodes: np.ndarray) -> UnitProfiles:
    """Unit profiles of units ``idx`` between the node speeds ``v_nodes``."""
    return unit_profiles(v_nodes[idx], v_nodes[idx + 1], units.length[idx], units.cap[idx],
                         units.acc_up[idx], units.jerk_up[idx], units.acc_dn[idx],
                         units.jerk_dn[idx], units.knee[idx], units.knee_ratio[idx])


def _plan_all(units: Units, v_nodes: np.ndarray) -> UnitProfiles:
    """:func:`_replan` of every unit (the arrays as they are, without gathering copies
    of them; the profiles do not write to their inputs)."""
    return unit_profiles(v_nodes[:-1], v_nodes[1:], units.length, units.cap, units.acc_up,
                         units.jerk_up, units.acc_dn, units.jerk_dn, units.knee,
                         units.knee_ratio)


def plan(program: Program, machine: Machine, *, path: Path | None = None,
         parameters: PlannerParameters | None = None, progress: Progress | None = None,
         check: bool = True) -> ReferencePlan:
    """Plan a program with the SINUMERIK-style heuristic.

    Parameters
    ----------
    program : Program
        The parsed NC program.
    machine : Machine
        Machine data (limits, channel and axis settings).
    path : Path, optional
        ``reference.build_path(program, machine)`` when the caller has built it already
        (to hand the very same object to the oracle); built here when omitted. A path
        of another program is refused.
    parameters : PlannerParameters, optional
        Model parameters where the manuals are silent (defaults documented there).
    progress : callable, optional
        ``progress(stage, fraction)`` is called as the stages run (fraction in [0, 1]).
    check : bool
        Judge the own profile with ``check_profile`` (default True).

    Returns
    -------
    ReferencePlan

    Raises
    ------
    FeedOracleError
        Bad input (path geometry, axes without machine data).
    ValueError
        ``path`` is not this program's (another file or another number of blocks).
    """
    params = DEFAULT_PARAMETERS if parameters is None else parameters
    report_progress = progress or _noop
    trace: list[tuple[str, str]] = []
    t_start = time.perf_counter()
    ch = machine.channel
    limits = machine.limits

    report_progress("prepare", 0.0)
    if path is None:
        path = build_path(program, machine)
    elif len(path.blocks) != len(program.blocks) or path.source != program.file:
        raise ValueError(f"plan(path=...): the path of {path.source!r} "
                         f"({len(path.blocks)} blocks) is not the path of {program.file!r} "
                         f"({len(program.blocks)} blocks); use build_path(program, machine)")
    m = path.n_segments
    trace.append(("prepare", f"{len(path.blocks)} blocks, {m} segments, "
                             f"{path.total_length:.6g} mm"))
    trace.append(("rounding", rounding_note(path)))

    report_progress("stops", 0.1)
    modes = segment_modes(program, path, machine)
    notes = sorted({ACCEL_MODES[i].note for i in np.unique(modes.mode) if ACCEL_MODES[i].note})
    counts = {ACCEL_MODES[i].name: int(np.sum(modes.mode == i)) for i in np.unique(modes.mode)}
    trace.append(("stops", f"modes {counts or {ACCEL_MODES[modes.default_mode].name: 0}}; "
                           f"{int(modes.mode_change.sum())} forced stops at BRISK/SOFT "
                           f"changes; {int(np.sum(modes.stop[1:-1]))} interior stops"
                  + ("; " + "; ".join(notes) if notes else "")))

    report_progress("limit curves", 0.2)
    seg = segment_limits(path, machine, modes, params)
    trace.append(("limit curves", _cause_counts("segment caps", seg.cap_cause)
                  + _drive_note(seg, modes)))

    report_progress("corners", 0.3)
    lim = limits.for_axes(path.axes)
    junc = junction_limits(path, lim, limits.t_ipo_s, modes, seg)
    trace.append(("corners", _cause_counts("junction limits", junc.cause[1:-1])))

    report_progress("lookahead", 0.4)
    horizon = horizon_caps(path, seg, modes, ch.lookahead_blocks)
    base_units = planning_units(path, seg, junc, modes, horizon, params.soft_merge_cap_ratio,
                                params.soft_merge_accel_ratio)
    speeds = lookahead_passes(base_units)
    prof = _plan_all(base_units, speeds.v)
    # merged breaks passed at the unit's cap: planned apart, each side ramps with its
    # own dynamics (lookahead.cruise_splits: never slower)
    split = cruise_splits(path, seg, base_units, prof.v_peak, prof.dist_rise,
                          prof.dist_cruise, prof.dist_fall)
    if split.any():
        old_units, old_prof, old_v = base_units, prof, speeds.v
        base_units = planning_units(path, seg, junc, modes, horizon,
                                    params.soft_merge_cap_ratio,
                                    params.soft_merge_accel_ratio, split)
        speeds = lookahead_passes(base_units)
        prof = _plan_changed(base_units, speeds.v, old_units, old_prof, old_v)
    units = base_units
    n_h = int(np.sum(units.node_cause == C.HORIZON))
    trace.append(("lookahead", f"horizon {ch.lookahead_blocks} blocks (v = 0 assumed at its "
                               f"end; binding at {n_h} nodes); {units.n_units} planning units "
                               f"for {m} segments"))
    trace.append(("profiles", _case_counts(prof, units)))

    report_progress("smoothing", 0.6)
    factor = effective_factor(ch.lookahead_smooth_factor_pct)
    sm = smooth_velocity(units, speeds, prof, factor, params.smoothing_rounds, _replan)
    units, speeds, prof = sm.units, sm.speeds, sm.profiles
    md = ch.lookahead_smooth_factor_pct
    trace.append(("smoothing", f"LOOKAH_SMOOTH_FACTOR {md:g} %"
                               + (f" (0 selects the internal {factor:g} %)" if md <= 0 else "")
                               + (": smoothing_rounds = 0, none removed (bare LookAhead)"
                                  if params.smoothing_rounds == 0 else
                                  f": {sm.n_bumps} bumps removed, moving time "
                                  f"{sm.time_before:.6g} s -> {sm.time_after:.6g} s")))

    report_progress("adaptation", 0.7)
    adapt = tuple(ch.adapt_path_dynamic)
    # the factor of each segment's mode (BRISK and DRIVE: index 0, SOFT: index 1)
    adapt_active = bool(units.n_units) and bool(np.any(
        np.asarray(adapt)[modes.jerk_limited.astype(np.int64)] > 1.0))
    if max(adapt) > 1.0 and units.n_units:
        n_ad = 0
        for _ in range(params.adaptation_rounds):
            fac = adaptation_factors(units, prof, base_units, adapt)
            if fac.n_adapted == 0:
                break
            new_units = adapted_units(base_units, units, fac)
            if (np.array_equal(new_units.acc_up, units.acc_up)
                    and np.array_equal(new_units.acc_dn, units.acc_dn)
                    and np.array_equal(new_units.jerk_up, units.jerk_up)
                    and np.array_equal(new_units.jerk_dn, units.jerk_dn)):
                break
            units = new_units
            speeds = lookahead_passes(units)
            prof = _plan_all(units, speeds.v)
            n_ad = int(np.sum(units.adapted_up) + np.sum(units.adapted_dn))
        trace.append(("adaptation", f"ADAPT_PATH_DYNAMIC {list(adapt)}: {n_ad} velocity-change "
                                    "processes stretched towards 1/LOOKAH_FREQUENCY"))
    else:
        trace.append(("adaptation", "off (ADAPT_PATH_DYNAMIC = 1)"))

    report_progress("settle", 0.8)
    holds = imposed_holds(program, path, machine)
    n_settle = sum(1 for c in holds.cause if c == SETTLE_CAUSE)
    n_dwell = holds.n - n_settle
    trace.append(("settle", f"{int(np.sum(modes.exact_stop_block >= 0))} exact stops; "
                            f"{n_settle} settle and {n_dwell} dwell holds, "
                            f"{holds.total_s:.6g} s (imposed: e0 = (1 - VELO_FFW_WEIGHT) "
                            f"* v_prog/Kv, reference.holds)"))

    report_progress("assemble", 0.85)
    profile = with_holds(_assemble(path, units, prof), path, holds)
    at_segments, corners = _segment_rows(path, junc, units, speeds, prof, profile, horizon)
    bound_set = modes.bound_set
    # the planning stages' arrays are done with: freed before the block rows and the
    # checker build their own (with 10^6 blocks all together would be gigabytes)
    del seg, horizon, base_units, units, speeds, prof
    sm = fac = new_units = None     # noqa: F841 - the smoothing's and adaptation's copies
    rows = _block_rows(path, modes, junc, at_segments, profile, holds)
    seg_cause = readonly(at_segments.seg_cause, np.int8)
    del modes, junc, at_segments
    report = None
    if check:
        report_progress("check", 0.9)
        report = check_profile(path, limits, profile)
        viol = report.violations(BOUND_SETS[bound_set])
        trace.append(("check", f"bound set {bound_set!r}: " + (
            "no violations" if not viol else
            "; ".join(f"{v.constraint} ratio {v.ratio:.6g}" for v in viol))))
        if adapt_active:
            bound_set, note = _declared_with_frequency(bound_set, report)
            trace.append(("check", note))
    elif adapt_active:
        trace.append(("check", f"frequency rule not declared: the plan was not checked "
                               f"(bound set {bound_set!r})"))
    trace.append(("time", f"planned {profile.duration:.6g} s in "
                          f"{time.perf_counter() - t_start:.3g} s wall time"))
    report_progress("done", 1.0)
    return ReferencePlan(program=program.file, machine=machine.name, path=path,
                         profile=profile, blocks=rows, corners=corners,
                         trace=tuple(TraceEntry(*e) for e in trace),
                         bound_set=bound_set, report=report, limits=limits,
                         parameters=params, holds=holds, segment_cause=seg_cause)


def _declared_with_frequency(base: str, report) -> tuple[str, str]:
    """The bound set the plan declares when the dynamic response adaptation is active.

    Adaptation stretches velocity changes towards ``1/f`` (model note 7.4), but by at most
    ADAPT_PATH_DYNAMIC, and re-planning may shorten a stretched change again: the plan
    declares the frequency rule (``base + "+freq"``) only when its own profile meets it,
    and otherwise says where the shortest phase is.
    """
    cand = f"{base}+freq"
    w = report.worst("frequency")
    if report.ok(BOUND_SETS[cand]):
        return cand, (f"bound set {cand!r}: the adapted plan meets the frequency rule "
                      f"(shortest phase at ratio {w.ratio:.6g})")
    return base, (f"frequency rule not declared (bound set stays {base!r}): the phase "
                  f"starting at t = {w.t:.6g} s in block {w.block} lasts {1 / w.value:.6g} s "
                  f"(effective) < 1/f = {1 / w.limit:.6g} s of axis {w.axis}; "
                  f"ADAPT_PATH_DYNAMIC limits the stretching")


def _cause_counts(what: str, codes: np.ndarray) -> str:
    if codes.size == 0:
        return f"{what}: none"
    cnt = np.bincount(np.asarray(codes, dtype=np.int64), minlength=len(C.CAUSES))
    parts = [f"{C.CAUSES[i]} {int(c)}" for i, c in enumerate(cnt) if c]
    return f"{what} by cause: " + ", ".join(parts)


def _drive_note(seg, modes: SegmentModes) -> str:
    """DRIVE segments and their knees for the trace ("" without DRIVE)."""
    n_drive = int(np.sum(modes.mode == MODE_CODE["DRIVE"]))
    if not n_drive:
        return ""
    knee = np.isfinite(seg.knee)
    if not knee.any():
        return (f"; DRIVE: {n_drive} segments, none above a knee (no reduction set, or "
                "the caps stay below ACCEL_REDUCTION_SPEED_POINT)")
    r = seg.knee_ratio[knee]
    return (f"; DRIVE: {int(knee.sum())} of {n_drive} segments above a knee, acceleration "
            f"there {100 * r.min():.3g}..{100 * r.max():.3g} % of the one below (cause "
            f"'axis acceleration'); the oracle does not reduce it: the gap includes it")


def _case_counts(prof: UnitProfiles, units: Units) -> str:
    if prof.case.size == 0:
        return "no motion"
    vals, cnt = np.unique(prof.case, return_counts=True)
    kinds = "SOFT 7-phase S-curves" if units.jerk_limited.all() else (
        "BRISK trapezoids" if not units.jerk_limited.any() else
        "BRISK trapezoids and SOFT S-curves")
    return f"{kinds}; cases " + ", ".join(f"{case_name(int(v))} {int(c)}"
                                          for v, c in zip(vals, cnt))


# ----------------------------------------------------------------- assembly
def _exclusive_cumsum(x: np.ndarray) -> np.ndarray:
    """Row-wise sums of the preceding columns (exactly 0 in the first column).

    Column by column over whole rows (the phases are few): the same sequential sums as
    ``np.cumsum(x[:, :-1], axis=1)``, without numpy's inner loop of a few elements per
    row."""
    out = np.empty_like(x)
    out[:, 0] = 0.0
    if x.shape[1] > 1:
        out[:, 1] = x[:, 0]
    for c in range(2, x.shape[1]):
        np.add(out[:, c - 1], x[:, c - 1], out=out[:, c])
    return out


#: Planning units assembled at a time by :func:`_assemble` (its unit x phase
#: temporaries stay a few MB; the result does not depend on it).
_ASSEMBLE_CHUNK = 1 << 16


def _assemble(path: Path, units: Units, prof: UnitProfiles) -> Profile:
    """The motion Profile: unit phases in order (the holds are inserted afterwards by
    :func:`reference.core.holds.with_holds`, as on the oracle's side)."""
    h_all = prof.duration
    keep = h_all > 0
    s_parts, v_parts = [], []
    # In chunks of units, in place, one temporary at a time: every (units x phases) array
    # is some 50 MB for 10^6 blocks. Same operations in the same order as the plain
    # formulas dv = a0 h + jj h^2 / 2, ds = v_start h + a0 h^2 / 2 + jj h^3 / 6 (bitwise
    # equal), all within a unit's row.
    for lo in range(0, h_all.shape[0], _ASSEMBLE_CHUNK):
        hi = lo + _ASSEMBLE_CHUNK
        h, a0, jj = h_all[lo:hi], prof.a0[lo:hi], prof.jerk[lo:hi]
        # without jerk (BRISK, DRIVE) its terms are zeros: adding them changes nothing
        jerk = bool(jj.any())
        dv = a0 * h
        if jerk:
            tmp = jj * h
            tmp *= h
            tmp /= 2
            dv += tmp
        v_start = _exclusive_cumsum(dv)
        del dv
        v_start += prof.v_in[lo:hi, None]
        ds = v_start * h
        tmp = a0 * h
        tmp *= h
        tmp /= 2
        ds += tmp
        del tmp
        if jerk:
            tmp = h ** 3
            tmp *= jj
            tmp /= 6
            ds += tmp
            del tmp
        s_start = _exclusive_cumsum(ds)
        del ds
        s_start += units.s_start[lo:hi, None]
        k = keep[lo:hi]
        s_parts.append(s_start[k])
        v_parts.append(np.maximum(v_start[k], 0.0))
    hh = h_all[keep]
    t = np.concatenate(([0.0], np.cumsum(hh)))
    s = np.concatenate(s_parts + [np.array([path.total_length])])
    del s_parts
    v = np.concatenate(v_parts + [np.zeros(1)])
    del v_parts
    return Profile(t=t, s=s, v=v, a=prof.a0[keep], j=prof.jerk[keep],
                   block=np.full(hh.size, -1))


# ----------------------------------------------------------------- rows
def _group_argmax(values: np.ndarray, lo: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Index of the first largest value in each contiguous group ``[lo, lo + n)``.

    Vectorised (a rounded program has one multi-segment block per corner: 10^5 of them
    must not cost a Python loop each). ``n >= 1``; shapes (g,) -> (g,).
    """
    starts = np.cumsum(n) - n
    idx = np.repeat(lo, n) + (np.arange(int(n.sum())) - np.repeat(starts, n))
    vals = values[idx]
    top = np.maximum.reduceat(vals, starts)
    hit = np.flatnonzero(vals == np.repeat(top, n))
    group = np.repeat(np.arange(lo.size), n)[hit]
    # hits come in group order and every group has one (its maximum): a group's first
    # hit is where the group number changes
    first_hit = np.flatnonzero(np.concatenate(([True], group[1:] != group[:-1])))
    return idx[hit[first_hit]]


def _group_members(lo: np.ndarray, n: np.ndarray) -> np.ndarray:
    """All indices of the contiguous groups ``[lo, lo + n)``, in order, shape (sum(n),)."""
    starts = np.cumsum(n) - n
    return np.repeat(lo, n) + (np.arange(int(n.sum())) - np.repeat(starts, n))


class _SegmentRows(NamedTuple):
    """Per-segment and per-break results the block rows are made of (shapes (m,) and
    (m + 1,)), kept apart so that the planning units can be freed before them."""

    v_break: np.ndarray
    v_peak_seg: np.ndarray
    seg_cause: np.ndarray
    case_seg: np.ndarray


def _segment_rows(path: Path, junc, units: Units, speeds: NodeSpeeds, prof: UnitProfiles,
                  profile: Profile, horizon: np.ndarray
                  ) -> tuple[_SegmentRows, CornerTable]:
    """Speeds and limiting causes at every segment and break, and the corner rows."""
    m = path.n_segments
    tol = CAUSE_REL_TOL
    u = units.n_units
    if u:
        unit_of_seg = np.repeat(np.arange(u), units.n_segments)
        # speed at every break: nodes exact, interior breaks from the profile
        v_break = np.zeros(m + 1)
        inner = np.ones(m + 1, dtype=bool)
        inner[units.node_break] = False
        if inner.any():
            tb = profile.time_at(path.s_breaks[inner])
            v_break[inner] = np.maximum(profile.state(tb)[1], 0.0)
        v_break[units.node_break] = speeds.v
        p1 = units.s_start + prof.dist_rise
        p2 = p1 + prof.dist_cruise
        sa, sb = path.s_breaks[:-1], path.s_breaks[1:]
        us = unit_of_seg
        holds_peak = (sb >= p1[us]) & (sa <= p2[us])
        v_peak_seg = np.where(holds_peak, prof.v_peak[us], np.maximum(v_break[:-1],
                                                                       v_break[1:]))
        at_cap = prof.v_peak >= units.cap * (1 - tol)
        rising = sb <= p1[us] * (1 + 1e-12)
        rise_cause = _accel_cause(units, prof, up=True)
        exit_cause = _node_cause(units, speeds, prof)[1:]
        # at the cap: the cap's cause; only rising (the ramp from behind limits it):
        # acceleration, jerk or frequency; holding a peak below the cap or braking: what
        # the unit brakes for (a corner, a stop, the horizon end, ...)
        seg_cause = np.where(at_cap[us] & holds_peak, units.cap_cause[us],
                             np.where(rising, rise_cause[us], exit_cause[us]))
        # breaks: node causes; interior breaks like segment positions
        node_c = _node_cause(units, speeds, prof)
        brk_cause = np.empty(m + 1, dtype=np.int64)
        us_b = np.clip(np.searchsorted(units.node_break, np.arange(m + 1), side="right") - 1,
                       0, u - 1)
        at_cap_b = v_break >= units.cap[us_b] * (1 - tol)
        rising_b = path.s_breaks <= p1[us_b] * (1 + 1e-12)
        brk_cause[:] = np.where(at_cap_b, units.cap_cause[us_b],
                                np.where(rising_b, rise_cause[us_b], exit_cause[us_b]))
        brk_cause[units.node_break] = node_c
        case_seg = prof.case[us]
    else:
        v_break = np.zeros(m + 1)
        v_peak_seg = np.zeros(m)
        seg_cause = np.zeros(m, dtype=np.int64)
        brk_cause = np.full(m + 1, C.FORCED_STOP)
        case_seg = np.zeros(m, dtype=np.int64)
    k = np.arange(1, m) if m >= 2 else np.zeros(0, dtype=np.int64)
    own = np.minimum(junc.cap, horizon)
    corners = CornerTable(
        index=k, s=path.s_breaks[k], block_before=path.block[k - 1] if k.size else k,
        block_after=path.block[k] if k.size else k, v=v_break[k], v_limit=own[k],
        v_g64=junc.g64[k], tangential=junc.tangential[k], cause_code=brk_cause[k])
    return _SegmentRows(v_break, v_peak_seg, seg_cause, case_seg), corners


def _block_rows(path: Path, modes: SegmentModes, junc, at: _SegmentRows, profile: Profile,
                holds: Holds) -> BlockTable:
    """Per-block rows: times, speeds and limiting causes."""
    m = path.n_segments
    v_break, v_peak_seg, seg_cause, case_seg = (at.v_break, at.v_peak_seg, at.seg_cause,
                                                at.case_seg)
    spans = path.blocks
    nb = len(spans)
    first, nseg, ids = spans.first_segment, spans.n_segments, spans.block
    multi = np.flatnonzero(nseg > 1)
    moving = nseg > 0
    # per block: the segment where it spends most time decides cause, mode and case
    main = first.copy()
    if multi.size:            # blocks with roundings: their segments' times too
        segs = _group_members(first[multi], nseg[multi])
        times, seg_t = profile.block_and_segment_times(path, segs)
        main[multi] = _group_argmax(seg_t, first[multi], nseg[multi])
    else:
        times = profile.block_times(path) if nb else np.zeros(0)
    mainc = np.clip(main, 0, max(m - 1, 0))
    t_blk = times[np.clip(ids, 0, max(times.size - 1, 0))] if times.size else np.zeros(nb)
    kb = np.clip(first, 0, m)
    v_entry = v_break[kb]
    v_exit = v_break[np.clip(first + nseg, 0, m)]
    v_pk = v_entry.copy()
    if m:
        v_pk[moving] = v_peak_seg[mainc[moving]]
        if multi.size:
            v_pk[multi] = v_peak_seg[_group_argmax(v_peak_seg, first[multi], nseg[multi])]
    stop_here = modes.stop[kb] & (t_blk > 0)
    cause_code = np.where(moving, seg_cause[mainc] if m else 0, junc.cause[kb])
    cause_code = np.where(moving | stop_here, cause_code, -1)
    # a dwell block's whole time is its hold: the hold's own cause, not "forced stop"
    is_dwell = (spans.dwell_s > 0) & (nseg == 0)
    cause_code = np.where(is_dwell & (t_blk > 0), C.DWELL, cause_code)
    mode_code = np.where(moving, modes.mode[mainc] if m else 0, -1)
    case_code = np.where(moving, case_seg[mainc] if m else 0, -1)
    return BlockTable(
        block=ids, line=spans.line, label=spans.label, kind=spans.kind,
        length_mm=spans.s_end - spans.s_start,
        v_entry=v_entry, v_exit=v_exit, v_peak=v_pk, time_s=t_blk, cause_code=cause_code,
        mode_code=mode_code, case_code=case_code,
        hold_s=holds.per_block(int(ids.max()) + 1)[ids] if nb else np.zeros(0))


def _accel_cause(units: Units, prof: UnitProfiles, up: bool) -> np.ndarray:
    """Cause of a ramp that stays below the cap: frequency (adapted), jerk (SOFT ramp that
    never reaches a_max), else axis acceleration."""
    adapted = units.adapted_up if up else units.adapted_dn
    acc_bit = CASE_RISE_ACC if up else CASE_FALL_ACC
    jerk_lim = units.jerk_limited & ((prof.case & acc_bit) == 0)
    return np.where(adapted, C.FREQUENCY, np.where(jerk_lim, C.JERK, C.AXIS_ACCELERATION))


def _node_cause(units: Units, speeds: NodeSpeeds, prof: UnitProfiles) -> np.ndarray:
    """Cause of every node speed: its own limit, the propagated braking limit, or the
    acceleration from behind."""
    tol = CAUSE_REL_TOL
    own = speeds.v >= units.node_cap * (1 - tol)
    rise = _accel_cause(units, prof, up=True)
    behind = np.concatenate(([C.AXIS_ACCELERATION], rise))
    return np.where(own, units.node_cause,
                    np.where(speeds.accel_limited, behind, speeds.origin_cause))


__all__ = ["BlockTable", "CornerRow", "CornerTable", "ReferencePlan", "TraceEntry",
           "plan"]

"""Stage: smoothing of the path velocity (MD20460 LOOKAH_SMOOTH_FACTOR, model note 7.3).

Short acceleration "bumps" (the speed rises and falls again) save little time but excite
the machine. The smoothing factor is the productivity loss (in %) the control may spend
to avoid them; only bumps whose duration is below ``1/f`` count, ``f`` the smallest
LOOKAH_FREQUENCY (MD32440) of the axes moving in the bump (AX2 at 10 Hz dominates as soon
as AX2 moves). No contour error results: only the speed changes.

Model [I]:

* A bump is the stretch between two consecutive *valleys* of the planned speed: nodes
  where the descent from a peak ends or the ascent to one starts. A constant-speed
  stretch (a cruise) ends a descent and starts an ascent like a dip does, so a node
  counts when the speed just before it falls or stays level and just after it rises, or
  just before it falls and just after it stays level or rises (program start and end
  count). A short rise and fall between two stretches at constant speed is a bump of
  its own (``G1 X50 F3000 / X51 F6000 / X101 F3000``); a plateau at the top of a bump
  (level on both sides of a node) is no valley, so the bump keeps its plateau.
* Candidate: cap the bump at ``v_flat = max(v_left_valley, v_right_valley)``; this keeps
  every pair of node speeds joinable (lower speeds never lengthen a ramp).
* Accept the candidate when the bump is shorter than ``1/f`` and the time it costs is at
  most ``factor`` % of the bump's time. Bumps are taken shortest first: each round caps
  the bumps that qualify, after which neighbouring bumps may merge into larger ones
  (``smoothing_rounds`` rounds).

Each capped bump costs at most ``factor`` % of its own time, so the whole program slows
down by at most ``factor`` %: 1 % is "practically off", as the manual's example says.

The value 0 (:func:`effective_factor`): the B1 excerpt on dynamic response adaptation
(Function Manual 11/2006, example 1, note) says "A smoothing factor other than 0%
prevents the default value of 100% from being used to smooth the path velocity", and
sets 1.0 % to "practically deactivate" the smoothing. So 0 selects the control's internal
100 % (model note 7.3: "treat 0 as 'use 100 %'"), and there is no exact "off": a small
factor is the manual's way to switch smoothing practically off, and by the bound above
it slows the program by at most that many percent.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Callable

import numpy as np

from . import causes as C
from .lookahead import NodeSpeeds, Units
from .parameters import CAUSE_REL_TOL, DISTANCE_REL_TOL
from .profiles import UnitProfiles


#: The smoothing factor, %, the control uses when MD20460 LOOKAH_SMOOTH_FACTOR is 0 (the
#: B1 note: "a smoothing factor other than 0% prevents the default value of 100% from
#: being used").
INTERNAL_DEFAULT_FACTOR_PCT = 100.0


def effective_factor(md_value_pct: float) -> float:
    """The smoothing factor in effect for a value of MD20460 LOOKAH_SMOOTH_FACTOR.

    Parameters
    ----------
    md_value_pct : float
        The machine-data value, % (>= 0).

    Returns
    -------
    float
        ``md_value_pct``, or :data:`INTERNAL_DEFAULT_FACTOR_PCT` (100 %) for 0: "a
        smoothing factor other than 0% prevents the default value of 100% from being
        used to smooth the path velocity" (B1 excerpt, note to example 1).
    """
    return INTERNAL_DEFAULT_FACTOR_PCT if md_value_pct <= 0.0 else float(md_value_pct)


@dataclass(frozen=True, slots=True)
class SmoothingResult:
    """Output of :func:`smooth_velocity`.

    Attributes
    ----------
    units : Units
        Units with the smoothing caps (cause ``frequency``).
    speeds : NodeSpeeds
        Node speeds (capped inside smoothed bumps).
    profiles : UnitProfiles
        Re-planned unit profiles.
    n_bumps : int
        Bumps removed.
    time_before, time_after : float
        Moving time before and after smoothing, s.
    """

    units: Units
    speeds: NodeSpeeds
    profiles: UnitProfiles
    n_bumps: int
    time_before: float
    time_after: float


def _moves(prof: UnitProfiles):
    tol = CAUSE_REL_TOL
    rise = prof.v_peak > prof.v_in * (1 + tol) + 1e-9
    fall = prof.v_peak > prof.v_out * (1 + tol) + 1e-9
    return rise, fall


#: Direction of the speed: falling, level, rising.
_FALL, _LEVEL, _RISE = -1, 0, 1


def find_valleys(prof: UnitProfiles) -> np.ndarray:
    """Nodes where a descent ends or an ascent starts (the bump boundaries).

    A unit's profile is rise, cruise, fall, so the speed just after its entry node
    rises (a rise), stays level (a cruise) or falls, and just before its exit node falls,
    stays level or rises. Node ``k`` is a valley when the speed just before it falls or
    stays level and just after it rises or stays level, except level on both sides (a
    plateau, e.g. the top of a bump spread over several units, is not cut). Program
    start and end count as level outside.

    Parameters
    ----------
    prof : UnitProfiles
        Profiles of ``u`` units.

    Returns
    -------
    numpy.ndarray of int
        Sorted node indices in ``[0, u]``.
    """
    return _valleys(prof, *_moves(prof))


def _valleys(prof: UnitProfiles, rise: np.ndarray, fall: np.ndarray) -> np.ndarray:
    """:func:`find_valleys` with the units' rises and falls (:func:`_moves`) given."""
    length = prof.dist_rise + prof.dist_cruise + prof.dist_fall
    # a cruise shorter than the profiles' round-off is no constant-speed stretch
    cruise = prof.dist_cruise > DISTANCE_REL_TOL * np.maximum(length, 1.0)
    # direction into the exit node: falling, else level (a cruise, or no rise), else
    # rising; out of the entry node: rising, else level (a cruise, or no fall), else
    # falling. As differences of 0/1 flags (_FALL, _LEVEL, _RISE = -1, 0, 1), which
    # numpy forms several times faster than nested where() over the scalars.
    last = (~fall & ~cruise & rise).view(np.int8) - fall.view(np.int8)
    first = rise.view(np.int8) - (~rise & ~cruise & fall).view(np.int8)
    before = np.concatenate(([_LEVEL], last))
    after = np.concatenate((first, [_LEVEL]))
    valley = (before <= _LEVEL) & (after >= _LEVEL) & ~((before == _LEVEL)
                                                        & (after == _LEVEL))
    valley[[0, -1]] = True          # the program starts and ends at rest
    return np.flatnonzero(valley)


def smooth_velocity(units: Units, speeds: NodeSpeeds, prof: UnitProfiles,
                    factor_pct: float, rounds: int,
                    replan: Callable[[Units, np.ndarray, np.ndarray], UnitProfiles]
                    ) -> SmoothingResult:
    """Remove short bumps whose removal costs at most ``factor_pct`` % of their time.

    Parameters
    ----------
    units : Units
    speeds : NodeSpeeds
    prof : UnitProfiles
    factor_pct : float
        The factor in effect, % (:func:`effective_factor` of LOOKAH_SMOOTH_FACTOR;
        a value <= 0 plans no smoothing, for callers that want the bare LookAhead).
    rounds : int
        Rounds of bump removal (0: none).
    replan : callable
        ``replan(units_subset_index -> ...)``: given ``(units, idx, v_nodes)`` returns the
        unit profiles of units ``idx`` with entry ``v_nodes[idx]`` and exit
        ``v_nodes[idx + 1]``; each unit's profile must depend on that unit's inputs
        only (as :func:`reference.planner.profiles.unit_profiles` does, element by
        element), so that the profiles of accepted bumps are spliced in without
        planning the other units again.

    Returns
    -------
    SmoothingResult
    """
    time_u = prof.time                  # per unit, s (kept up to date below)
    t0 = float(time_u.sum())
    n_bumps = 0
    if factor_pct <= 0.0 or rounds <= 0 or units.n_units == 0:
        return SmoothingResult(units, speeds, prof, 0, t0, t0)
    v = speeds.v.copy()
    u = units.n_units
    s_node = np.concatenate((units.s_start, [units.s_start[-1] + units.length[-1]]))
    # bumps rejected in an earlier round, as keys a (u + 1) + b: a bump whose units have
    # not changed since is the same question with the same answer (same caps, speeds,
    # profiles and frequency), so it is not planned again; a change to any of its units
    # forgets it
    rejected = np.zeros(0, dtype=np.int64)
    owned = False                       # prof's arrays are copies this stage may write
    for _ in range(rounds):
        rise, fall = _moves(prof)
        valleys = _valleys(prof, rise, fall)
        if valleys.size < 2:
            break
        a, b = valleys[:-1], valleys[1:]
        n_rise = np.concatenate(([0], np.cumsum(rise)))
        has_rise = (n_rise[b] - n_rise[a]) > 0
        t_cum = np.concatenate(([0.0], np.cumsum(time_u)))
        t_bump = t_cum[b] - t_cum[a]
        f_bump = np.minimum.reduceat(units.frequency[: b[-1]], a)
        with np.errstate(divide="ignore"):
            short = t_bump < 1.0 / f_bump
        # a bump between two standstills cannot be flattened (v_flat = 0)
        v_flat_all = np.maximum(v[a], v[b])
        # capped, no speed in the bump exceeds v_flat: it takes at least L / v_flat, so a
        # bump whose bound already costs more than the factor is rejected unplanned
        with np.errstate(divide="ignore", invalid="ignore"):
            t_low = (s_node[b] - s_node[a]) / v_flat_all
        affordable = t_low - t_bump <= factor_pct / 100.0 * t_bump * (1.0 + 1e-9)
        cand = np.flatnonzero(has_rise & short & (b > a) & (v_flat_all > 0) & affordable)
        if rejected.size and cand.size:
            cand = cand[~_is_member(a[cand] * (u + 1) + b[cand], rejected)]
        if cand.size == 0:
            break
        v_flat = np.maximum(v[a[cand]], v[b[cand]])
        # units of the candidate bumps and their flat speed
        counts = b[cand] - a[cand]
        first = np.cumsum(counts) - counts
        uidx = np.arange(int(counts.sum())) + np.repeat(a[cand] - first, counts)
        vf_u = np.repeat(v_flat, counts)
        new_cap = np.minimum(units.cap[uidx], vf_u)
        v_new = v.copy()
        nidx = uidx[uidx > 0]
        v_new[nidx] = np.minimum(v_new[nidx], vf_u[uidx > 0])
        # the trial plans units ``uidx`` only, from their caps (node caps unused)
        trial = replace(units, cap=_scatter(units.cap, uidx, new_cap))
        p_new = replan(trial, uidx, v_new)
        starts = np.concatenate(([0], np.cumsum(counts)[:-1]))
        t_new_u = p_new.time
        t_new = np.add.reduceat(t_new_u, starts)
        ok = t_new - t_bump[cand] <= factor_pct / 100.0 * t_bump[cand]
        rejected = np.concatenate((rejected, a[cand[~ok]] * (u + 1) + b[cand[~ok]]))
        if not ok.any():
            break
        keep_u = np.repeat(ok, counts)
        sel = uidx[keep_u]
        cap = units.cap.copy()
        cause = units.cap_cause.copy()
        lowered = new_cap[keep_u] < cap[sel]
        cap[sel] = new_cap[keep_u]
        cause[sel] = np.where(lowered, C.FREQUENCY, cause[sel])
        units = units.with_caps(cap, cause)
        # interior nodes of accepted bumps keep the flat speed as their limit
        nodes = sel[sel > 0]
        vf_sel = vf_u[keep_u][sel > 0]
        start = np.zeros(u + 1, dtype=bool)        # the accepted bumps' first nodes
        start[a[cand][ok]] = True
        inner = ~start[nodes]
        nodes, vf_sel = nodes[inner], vf_sel[inner]
        node_cap = units.node_cap.copy()
        node_cause = units.node_cause.copy()
        low = vf_sel < node_cap[nodes]
        node_cap[nodes[low]] = vf_sel[low]
        node_cause[nodes[low]] = C.FREQUENCY
        units = replace(units, node_cap=node_cap, node_cause=node_cause)
        v[nodes] = np.minimum(v[nodes], vf_sel)
        n_bumps += int(ok.sum())
        # a unit's profile depends on its own cap, limits and end speeds only, and the
        # accepted units are exactly those whose cap or end speeds changed (the nodes
        # changed are interior to accepted bumps; the bumps' end nodes are unchanged),
        # planned above with these very caps and speeds: their rows replace the old ones
        # (what a replan of every unit would give, element by element)
        rows = np.flatnonzero(keep_u)
        if not owned:
            prof = UnitProfiles(**{f.name: getattr(prof, f.name).copy()
                                   for f in fields(UnitProfiles)})
            time_u = time_u.copy()
            owned = True
        for f in fields(UnitProfiles):
            getattr(prof, f.name)[sel] = getattr(p_new, f.name)[rows]
        time_u[sel] = t_new_u[rows]
        # rejected bumps that share a unit with an accepted one are open again
        if rejected.size:
            touched = np.zeros(u + 1, dtype=np.int64)
            touched[sel + 1] = 1
            np.cumsum(touched, out=touched)
            ra, rb = rejected // (u + 1), rejected % (u + 1)
            rejected = rejected[touched[rb] == touched[ra]]
    speeds = replace(speeds, v=v)
    return SmoothingResult(units, speeds, prof, n_bumps, t0, float(time_u.sum()))


def _is_member(keys: np.ndarray, table: np.ndarray) -> np.ndarray:
    """``numpy.isin(keys, table)`` for integer keys, by bisection in the sorted table
    (a few times faster than ``isin`` on the few hundred keys of a round)."""
    table = np.sort(table)
    at = np.minimum(np.searchsorted(table, keys), table.size - 1)
    return table[at] == keys


def _scatter(base: np.ndarray, idx: np.ndarray, values: np.ndarray) -> np.ndarray:
    out = base.copy()
    out[idx] = values
    return out

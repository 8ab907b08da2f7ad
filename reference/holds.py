"""Stage: the holds the program and the machine impose (dwell, exact-stop settle).

:func:`imposed_holds` is the one function that computes them, from the program, its
path and the machine data only: it does not look at any velocity profile, so the
heuristic, the oracle and a recorded trajectory's comparison all get the same holds,
and the comparison can keep them out of the planning gap (see
:mod:`reference.core.holds` for the data type and the insertion into a profile).

Holds
-----
``dwell``
    G4 (SINUMERIK ``G4 F<s>`` / ``G4 S<rev>``; NGC ``G4 P<s>``): the programmed time, at
    the break where the dwell block sits (``BlockSpan.dwell_s``).
``exact stop settle``
    At the end of a moving block with exact stop (G60 modal, G9 non-modal) and the
    block-change criterion G601 (fine window, MD36010 STOP_LIMIT_FINE) or G602 (coarse
    window, MD36000 STOP_LIMIT_COARSE): the time the following error needs to decay
    into the window after the interpolator has brought the set speed to 0
    (spec/sinumerik-model.md section 3). G603 (interpolator end) waits for nothing.

Settle model (a choice where the manuals give no formula; every quantity is machine
data or programmed, none is a planner's choice):

* Position loop of first order with gain ``Kv_i`` (MD32200 POSCTRL_GAIN, 1 (m/min)/mm
  = 16.67 1/s): once the set point rests, the following error decays as
  ``e(t) = e0_i exp(-Kv_i t)``, so axis ``i`` is inside its window ``w_i`` after
  ``t_i = max(0, ln(e0_i / w_i) / Kv_i)``; the hold is the largest ``t_i`` of the axes.
* ``e0_i`` is the steady following error of axis ``i`` at the block's *programmed*
  speed: ``e0_i = (1 - ffw_i) |q_i'| v_prog / Kv_i``, with ``q_i'`` the axis tangent at
  the block end, ``v_prog = min(F, min_i MAX_AX_VELO_i / |q_i'|)`` (G0: the axis
  velocities alone) and ``ffw_i`` the velocity feed-forward weight (axis key
  ``VELO_FFW_WEIGHT``, MD32610; 0 = no feed-forward, the error is the full lag ``v/Kv``;
  1 = ideal feed-forward / DSC, no lag, no settle).
* Feed-forward assumption: the drive follows its set point with the lag of a
  proportional position loop reduced by the feed-forward weight; the error built up at
  constant speed is *not* assumed to shrink while braking. This is conservative (an
  upper estimate) when the block never reaches its programmed speed or the braking
  lasts longer than ``1/Kv`` (during braking at ``a`` the lag tends to ``a/Kv^2``), but
  it depends only on data both sides share; the logarithm makes the hold insensitive to
  this choice (a factor 2 in ``e0`` changes it by ``ln 2 / Kv``, 42 ms at Kv = 16.7 1/s).
* NGC dialect (LinuxCNC): exact stop (G61, G61.1) ends when the commanded motion has
  stopped; the trajectory planner waits for no in-position window, so there is no
  settle hold (the G603 behaviour).

Units: mm, s (degrees for rotary axes, whose windows are then in degrees too).
"""

from __future__ import annotations

import numpy as np

from .core.geometry import Path
from .core.holds import DWELL_CAUSE, SETTLE_CAUSE, Holds, NO_HOLDS
from .machine import Machine
from .nc.program import Program

#: Exact-stop window per block-change criterion: AxisSettings field, or None (no wait).
CRITERION_WINDOW = {"G601": "stop_fine_mm", "G602": "stop_coarse_mm", "G603": None}


def settle_time(tangent: np.ndarray, v_prog: float, kv_per_s: np.ndarray,
                window: np.ndarray, ffw_weight: np.ndarray) -> float:
    """Exact-stop settle time of one block end (the model of the module docstring).

    Parameters
    ----------
    tangent : numpy.ndarray, shape (n,)
        Axis tangent ``q'`` at the block end (mm/mm, deg/mm).
    v_prog : float
        Programmed path speed at the block end, mm/s (finite).
    kv_per_s, window, ffw_weight : numpy.ndarray, shape (n,)
        Position-loop gain (1/s), stop window (mm or deg) and velocity feed-forward
        weight (0..1) per axis.

    Returns
    -------
    float
        Settle time, s (0 when every axis starts inside its window).
    """
    e0 = (1.0 - ffw_weight) * np.abs(tangent) * v_prog / kv_per_s
    out = e0 > window
    t = np.zeros_like(e0)
    t[out] = np.log(e0[out] / window[out]) / kv_per_s[out]
    return float(t.max()) if t.size else 0.0


def programmed_speed(tangent: np.ndarray, feed_mm_s: float, v_max: np.ndarray) -> float:
    """``min(F, min_i v_max_i / |q_i'|)``: the speed the block is programmed to run at.

    Parameters
    ----------
    tangent : numpy.ndarray, shape (n,)
        Axis tangent at the block end.
    feed_mm_s : float
        Programmed path feed, mm/s (``inf`` for G0).
    v_max : numpy.ndarray, shape (n,)
        Axis velocity limits, mm/s (deg/s).

    Returns
    -------
    float
        mm/s.
    """
    dq = np.abs(tangent)
    moving = dq > 0
    caps = v_max[moving] / dq[moving]
    return float(min(feed_mm_s, caps.min() if caps.size else np.inf))


def imposed_holds(program: Program, path: Path, machine: Machine) -> Holds:
    """Every dwell and exact-stop settle hold of a program on its path.

    Parameters
    ----------
    program : Program
        The parsed program (exact stop, criterion and dialect of each block).
    path : Path
        Its path (``prepare`` + ``restrict_to_machine``): block spans, dwell times, feeds.
    machine : Machine
        ``POSCTRL_GAIN``, ``STOP_LIMIT_FINE``, ``STOP_LIMIT_COARSE``, ``VELO_FFW_WEIGHT``
        and ``MAX_AX_VELO`` of the path's axes.

    Returns
    -------
    Holds
        Sorted by break; at one break the settle of the block arriving there comes
        first, then the dwell blocks sitting there, in program order.
    """
    rows: list[tuple[int, int, int, float, str]] = []    # (break, order, block, time, cause)
    spans = path.blocks
    for order in np.flatnonzero(spans.dwell_s > 0).tolist():
        rows.append((int(spans.first_segment[order]), 1 + order, int(spans.block[order]),
                     float(spans.dwell_s[order]), DWELL_CAUSE))
    if program.dialect != "ngc" and path.n_segments:
        settings = [machine.settings_of(a) for a in path.axes]
        kv = np.array([st.kv_per_s for st in settings])
        ffw = np.array([st.velo_ffw_weight for st in settings])
        v_max = machine.limits.for_axes(path.axes).v_max
        pb, blk = program.blocks, spans.block.tolist()
        ends = [i for i in np.flatnonzero(spans.n_segments > 0).tolist()
                if pb[blk[i]].exact_stop_here
                and CRITERION_WINDOW.get(pb[blk[i]].exact_stop_criterion)]
        if ends:
            k_end = spans.first_segment[ends] + spans.n_segments[ends]
            _, dq, _, _ = path.evaluate(path.s_breaks[k_end], side="left")
            for row, i in enumerate(ends):
                field = CRITERION_WINDOW[pb[blk[i]].exact_stop_criterion]
                window = np.array([getattr(st, field) for st in settings])
                v_prog = programmed_speed(dq[row], float(path.feed[k_end[row] - 1]), v_max)
                t = settle_time(dq[row], v_prog, kv, window, ffw)
                if t > 0:
                    rows.append((int(k_end[row]), 0, blk[i], t, SETTLE_CAUSE))
    if not rows:
        return NO_HOLDS
    rows.sort(key=lambda r: (r[0], r[1]))
    return Holds(break_index=np.array([r[0] for r in rows]),
                 block=np.array([r[2] for r in rows]),
                 duration_s=np.array([r[3] for r in rows]),
                 cause=tuple(r[4] for r in rows))


__all__ = ["CRITERION_WINDOW", "imposed_holds", "programmed_speed", "settle_time"]

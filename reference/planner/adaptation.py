"""Stage: dynamic response adaptation (MD20465 ADAPT_PATH_DYNAMIC, model note 7.4).

The time window is ``t_adapt = 1/f`` with ``f`` the smallest LOOKAH_FREQUENCY (MD32440)
of the axes moving in the process. A velocity change (one rise or fall of a unit
profile) that would take less than ``t_adapt`` gets lower dynamics, by a factor
``lambda`` between 1 and ADAPT_PATH_DYNAMIC, so that it lasts about ``t_adapt``:

* BRISK (index 0): acceleration ``A / lambda``. For a fixed speed change the duration
  grows by ``lambda``: ``lambda = clip(t_adapt / T, 1, F)``.
* SOFT (index 1): jerk ``J / lambda``. The ramp time ``dv/A + A lambda/J`` (or
  ``2 sqrt(dv lambda/J)`` while jerk-limited) equals ``t_adapt`` for a closed-form
  ``lambda``, clipped to ``[1, F]``.

Either the process then lasts ``t_adapt`` (the permitted reduction was not used up), or
it stays shorter with the full factor ``F`` applied, as the manual's two cases say. A
process of ``t_adapt`` or longer is not touched. The manual's example (AX1 20 Hz, AX2
10 Hz, factor 1.5): a 40 ms process involving AX2 becomes 60 ms, an 80 ms one 100 ms,
a 120 ms one stays.

Lower dynamics lengthen the ramps, so the LookAhead passes run again with the adapted
limits (``adaptation_rounds`` rounds; the factors are always taken against the original
limits and never compound beyond ``F``). Speed changes the re-planning makes smaller
(distance-limited ramps) may end below ``t_adapt``: a documented approximation.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .lookahead import Units
from .profiles import UnitProfiles, knee_ramp_time, ramp_time


@dataclass(frozen=True, slots=True)
class AdaptationFactors:
    """Reduction factors per unit and side (1 = untouched).

    Attributes
    ----------
    rise, fall : numpy.ndarray, shape (u,)
    """

    rise: np.ndarray
    fall: np.ndarray

    @property
    def n_adapted(self) -> int:
        """Number of adapted processes."""
        return int(np.sum(self.rise > 1.0) + np.sum(self.fall > 1.0))


def process_factor(dv: np.ndarray, acc: np.ndarray, jerk: np.ndarray,
                   t_adapt: np.ndarray, f_max: np.ndarray,
                   duration: np.ndarray | None = None) -> np.ndarray:
    """Reduction factor of one velocity-change process.

    Parameters
    ----------
    dv : numpy.ndarray
        Speed change, mm/s.
    acc, jerk : numpy.ndarray
        Original limits (``jerk = inf``: BRISK, the factor acts on ``acc``; else on
        ``jerk``).
    t_adapt : numpy.ndarray
        ``1/f``, s.
    f_max : numpy.ndarray
        ADAPT_PATH_DYNAMIC of the mode (>= 1).
    duration : numpy.ndarray, optional
        The process duration where it is not the plain ramp's (DRIVE: the ramp across
        the knee, :func:`reference.planner.profiles.knee_ramp_time`); NaN elsewhere.
        Lowering both accelerations of a DRIVE ramp by ``lambda`` stretches it by
        ``lambda`` too, as a BRISK ramp.

    Returns
    -------
    numpy.ndarray
        ``lambda`` in ``[1, f_max]``.
    """
    T = ramp_time(dv, acc, jerk)
    if duration is not None:
        T = np.where(np.isnan(duration), T, duration)
    soft = np.isfinite(jerk)
    jf = np.where(soft, jerk, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        lam_brisk = t_adapt / T
        # SOFT: t = 2 sqrt(dv lam / J) while t >= 2 dv/A, else t = dv/A + A lam / J
        dvs = np.where(dv > 0, dv, 1.0)
        lam_jerk = jf * t_adapt ** 2 / (4.0 * dvs)
        lam_acc = (t_adapt - dv / acc) * jf / acc
    lam_soft = np.where(t_adapt >= 2.0 * dv / acc, lam_jerk, lam_acc)
    lam = np.where(soft, lam_soft, lam_brisk)
    needs = (dv > 0) & (T > 0) & (T < t_adapt)
    lam = np.where(needs & np.isfinite(lam), lam, 1.0)
    return np.clip(lam, 1.0, f_max)


def adaptation_factors(units: Units, prof: UnitProfiles, base: Units,
                       adapt: tuple[float, float]) -> AdaptationFactors:
    """Factors for every rise and fall of the planned units.

    Parameters
    ----------
    units : Units
        Units of the current plan (the node speeds came from them).
    prof : UnitProfiles
        Their profiles.
    base : Units
        The units with the original (unadapted) limits.
    adapt : tuple of float
        ADAPT_PATH_DYNAMIC ``[BRISK, SOFT]``.

    Returns
    -------
    AdaptationFactors
    """
    f_max = np.where(units.jerk_limited, adapt[1], adapt[0])
    with np.errstate(divide="ignore"):
        t_adapt = np.where(np.isfinite(units.frequency), 1.0 / units.frequency, 0.0)
    t_rise = t_fall = None
    drive = np.isfinite(base.knee)
    if drive.any():
        t_rise = np.where(drive, knee_ramp_time(prof.v_in, prof.v_peak, base.acc_up,
                                                base.knee, base.knee_ratio), np.nan)
        t_fall = np.where(drive, knee_ramp_time(prof.v_out, prof.v_peak, base.acc_dn,
                                                base.knee, base.knee_ratio), np.nan)
    rise = process_factor(prof.v_peak - prof.v_in, base.acc_up, base.jerk_up, t_adapt, f_max,
                          t_rise)
    fall = process_factor(prof.v_peak - prof.v_out, base.acc_dn, base.jerk_dn, t_adapt, f_max,
                          t_fall)
    return AdaptationFactors(rise=rise, fall=fall)


def adapted_units(base: Units, current: Units, factors: AdaptationFactors) -> Units:
    """Units whose ramp limits are the original ones divided by the factors (never
    compounding: the larger of the current and the new factor applies).

    Parameters
    ----------
    base : Units
        Original limits.
    current : Units
        Current units (caps and node limits after smoothing are kept).
    factors : AdaptationFactors

    Returns
    -------
    Units
    """
    soft = base.jerk_limited
    with np.errstate(divide="ignore", invalid="ignore"):
        cur_up = np.where(soft, base.jerk_up / current.jerk_up, base.acc_up / current.acc_up)
        cur_dn = np.where(soft, base.jerk_dn / current.jerk_dn, base.acc_dn / current.acc_dn)
    cur_up = np.where(np.isfinite(cur_up), cur_up, 1.0)
    cur_dn = np.where(np.isfinite(cur_dn), cur_dn, 1.0)
    lam_up = np.maximum(cur_up, factors.rise)
    lam_dn = np.maximum(cur_dn, factors.fall)
    return replace(
        current,
        acc_up=np.where(soft, base.acc_up, base.acc_up / lam_up),
        acc_dn=np.where(soft, base.acc_dn, base.acc_dn / lam_dn),
        jerk_up=np.where(soft, base.jerk_up / lam_up, base.jerk_up),
        jerk_dn=np.where(soft, base.jerk_dn / lam_dn, base.jerk_dn),
        adapted_up=lam_up > 1.0, adapted_dn=lam_dn > 1.0)

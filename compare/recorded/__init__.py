"""Trajectories recorded from other controllers or simulators (``feedoracle check``).

A recording (a CSV file ``t,X,Y,Z[,A,...]``, one row per sample) is turned into a
:class:`~reference.core.profile.Profile` on the program's path so that the one checker
(:func:`~reference.core.constraints.check_profile`) judges it and the comparison with
the oracle works block by block, exactly as for the heuristic. One module per stage,
in the order they run:

1. **Read and validate** (:mod:`.reading`: :func:`read_trajectory`,
   :func:`align_axes`): header, units, numbers, strictly increasing time; every
   problem is a :class:`~reference.core.errors.TrajectoryError` naming file and row.
2. **Project** (:mod:`.projection`: :func:`project`): each sample to the nearest point
   of the path, monotone in ``s``, refined by Newton steps on the exact geometry; the
   distance to the path is the *deviation*.
3. **Smooth** (:mod:`.smoothing`: :func:`estimate_noise`, :func:`smooth`; only when the
   samples are noisy): a Whittaker smoother on third differences, with the strength
   chosen so the residual matches the noise level.
4. **Reconstruct** (:mod:`.reconstruction`: :func:`reconstruct`,
   :func:`measurement_tolerance`): constant path acceleration between the mid-points
   of sample intervals, stops and corners pinned exactly, rest at the ends trimmed.
5. **Judge** (:mod:`.check`: :func:`recorded_profile`, :func:`check_recorded`,
   :class:`CheckResult`): ``check_profile`` on the reconstructed profile with a
   measurement tolerance (1 %, more for noisy recordings), the deviation against
   ``--max-deviation``, and the comparison with the oracle block by block; the holds the
   program imposes before the first and after the last motion are put back as imposed.

Jerk of a recording is estimated from acceleration steps spread over one IPO cycle,
meaningful when the recording is sampled at the IPO cycle; by default recordings are
judged on the ``acc`` bound set (velocity, acceleration, feed, corner jumps, stops) and
jerk is shown for information (``--bounds jerk`` makes it binding).
"""

from __future__ import annotations

from .check import (ACCEL_NOISE_REL, DEFAULT_MAX_DEVIATION_MM, CheckResult, check_recorded,
                    recorded_profile)
from .projection import (MAX_DENSE_ANGLE_RAD, MAX_DENSE_POINTS, MAX_DENSE_STEP_MM,
                         MIN_DENSE_STEP_MM, NEWTON_STEPS, Projection, project)
from .reading import (IGNORED_COLUMNS, LINEAR_UNITS, ROTARY_UNITS, TIME_UNITS, Recording,
                      align_axes, read_trajectory)
from .reconstruction import (NOISE_TOL_FACTOR, RECORDED_RATIO_TOL, STOP_SNAP_FACTOR,
                             measurement_tolerance, reconstruct)
from .smoothing import estimate_noise, smooth

__all__ = [
    # reading
    "Recording", "read_trajectory", "align_axes",
    "TIME_UNITS", "LINEAR_UNITS", "ROTARY_UNITS", "IGNORED_COLUMNS",
    # projection
    "Projection", "project",
    "MAX_DENSE_STEP_MM", "MAX_DENSE_ANGLE_RAD", "MIN_DENSE_STEP_MM", "MAX_DENSE_POINTS",
    "NEWTON_STEPS",
    # smoothing
    "estimate_noise", "smooth",
    # reconstruction
    "reconstruct", "measurement_tolerance",
    "STOP_SNAP_FACTOR", "RECORDED_RATIO_TOL", "NOISE_TOL_FACTOR",
    # the check
    "CheckResult", "recorded_profile", "check_recorded",
    "DEFAULT_MAX_DEVIATION_MM", "ACCEL_NOISE_REL",
]

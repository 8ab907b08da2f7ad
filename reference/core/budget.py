"""Size budget: how many points the stages would sample along a path, known up front.

Every large array of feedoracle is sized by the path: the constraint checker samples arcs
and helices every :data:`~reference.core.constraints.ARC_SAMPLE_STEP_RAD` of sweep, the
oracle's grid has intervals per angle, the CSV outputs one row per IPO cycle. The checker
works in chunks of :data:`~reference.core.constraints.CHUNK_SAMPLES` points, so its
memory stays bounded; its *time* is linear in the points. A program that would need more
than :data:`DEFAULT_MAX_GRID_POINTS` of them (``TURN=1000000``: about 3e9) is rejected
before any of them is computed, naming its line; ``--max-grid-points`` raises the budget.

Units: rad, mm, s. Shapes: ``m`` segments.
"""

from __future__ import annotations

import numpy as np

from .constraints import ARC_SAMPLE_STEP_RAD, MIN_ARC_SAMPLES
from .geometry import Path, plane_amplitudes

__all__ = ["DEFAULT_MAX_GRID_POINTS", "grid_points", "ipo_points"]

#: Largest number of points any stage samples along the path (checker samples on arcs,
#: IPO rows of a CSV). The checker evaluates about 1e6 points per second in chunks of
#: bounded memory, so the default costs at most a few minutes and never the memory; a
#: program that needs more is almost always a typing error (``TURN=1000000``).
DEFAULT_MAX_GRID_POINTS = 100_000_000


def grid_points(path: Path) -> np.ndarray:
    """Points the constraint checker samples on each segment, estimated from the geometry.

    An arc or helix segment is sampled every ``ARC_SAMPLE_STEP_RAD`` of its largest
    in-plane angular rate times its length (at least ``MIN_ARC_SAMPLES``); a straight
    segment is checked exactly at one point per interval (counted as 1). The estimate is
    that of a motion cut into few intervals; more intervals add ``MIN_ARC_SAMPLES`` each.

    Parameters
    ----------
    path : Path

    Returns
    -------
    numpy.ndarray of float, shape (m,)
        Points per segment (float: a hostile program may need more than int64 holds).
    """
    if path.n_segments == 0:
        return np.zeros(0)
    sweep = plane_amplitudes(path).omega_max * path.length
    arc = path.radius > 0
    with np.errstate(over="ignore", invalid="ignore"):
        n = np.where(arc, np.maximum(MIN_ARC_SAMPLES, sweep / ARC_SAMPLE_STEP_RAD + 1), 1.0)
    return np.where(np.isfinite(n), n, np.inf)


def ipo_points(duration_s: float, t_ipo_s: float) -> float:
    """Rows of a motion sampled at the IPO cycle (``duration / T_ipo + 2``)."""
    return float(duration_s) / float(t_ipo_s) + 2.0

"""Stage: sampling of the planned motion in the interpolation (IPO) cycle.

The interpolator outputs one set point per IPO cycle ``T_ipo`` (MD10050 x MD10070):
:func:`ipo_samples` evaluates the exact piecewise-cubic profile at ``t = 0, T_ipo,
2 T_ipo, ...`` (and at the end time) and maps ``s`` to every axis position on the path.
"""

from __future__ import annotations

import numpy as np

from .result import ReferencePlan


def ipo_samples(plan: ReferencePlan) -> tuple[list[str], np.ndarray]:
    """Set points of the plan at the IPO cycle, for CSV output.

    Parameters
    ----------
    plan : ReferencePlan

    Returns
    -------
    header : list of str
        ``["t", "s", "v", <axis names>...]``.
    data : numpy.ndarray, shape (N, 3 + n_axes)
        Time (s), path position (mm), path speed (mm/s) and the axis positions (mm or
        degrees), one row per IPO cycle, the last row at the end of the motion.
    """
    path = plan.path
    t, s, v, _, _ = plan.profile.sample(plan.limits.t_ipo_s)
    if path.n_segments:
        q = path.evaluate(np.clip(s, 0.0, path.total_length))[0]
    else:
        q = np.zeros((t.size, path.n_axes))
    header = ["t", "s", "v", *path.axes]
    return header, np.column_stack([t, s, np.maximum(v, 0.0), q])

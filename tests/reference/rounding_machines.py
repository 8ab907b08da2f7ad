"""The small test machine the rounding tests share: three equal axes, BRISK, 4 ms IPO
cycle, and MAX_ACCEL_OVL_FACTOR 1.0, so that G64 stops at every corner. Where the
rounding runs at the feed (low feeds in these tests) it costs no speed and shortens the
path, so every corner is rounded and a test sees the geometry alone."""

from __future__ import annotations

import copy

from reference.machine import Machine, machine_from_dict

#: Machine data of :func:`rounding_machine` (SINUMERIK units: mm/min, m/s^2, m/s^3).
BASE = {
    "machine": {"name": "t", "ipo_cycle_ms": 4.0},
    "channel": {"lookahead_blocks": 50, "acceleration_mode": "BRISK"},
    "axis": {ax: {"MAX_AX_VELO": 30000.0, "MAX_AX_ACCEL": 2.0, "MAX_AX_JERK": 40.0,
                  "MAX_ACCEL_OVL_FACTOR": 1.0, "LOOKAH_FREQUENCY": 20.0,
                  "COMPRESS_POS_TOL": 0.01}
             for ax in "XYZ"},
}


def rounding_machine(tol: float | None = None, **channel) -> Machine:
    """:data:`BASE` with ``channel`` keys set and, if given, COMPRESS_POS_TOL = ``tol``
    (mm) on every axis."""
    d = copy.deepcopy(BASE)
    d["channel"].update(channel)
    if tol is not None:
        for ax in d["axis"].values():
            ax["COMPRESS_POS_TOL"] = tol
    return machine_from_dict(d)

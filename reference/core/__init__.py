"""Shared, numpy-only vocabulary of feedoracle: geometry, limits, profiles, checks.

Symbols used throughout (two vocabularies, as in Ruckig: descriptive public names,
short maths symbols inside kernels):

=========  ==============================================  =========
symbol     meaning                                         unit
=========  ==============================================  =========
``s``      path position (arc length of X, Y, Z)           mm
``v``      path velocity ds/dt                             mm/s
``a``      path acceleration                               mm/s^2
``j``      path jerk                                       mm/s^3
``b``      squared path velocity v^2                       mm^2/s^2
``q``      axis positions, shape (N, n)                    mm, deg
``dq``     tangent dq/ds                                   1
``ddq``    curvature vector d2q/ds2                        1/mm
=========  ==============================================  =========

Import rule: this package imports only the standard library, numpy and scipy.
"""

from .errors import (BackendNotFoundError, FeedOracleError, InfeasibleError,
                     InternalError, MachineDataError, NCSyntaxError, PathError, ProfileError,
                     SolverError, TrajectoryError)
from .geometry import (BlockSpan, HelicalSegment, Path, arc_segment, line_segments,
                       path_from_pieces)
from .limits import AxisArrays, AxisLimits, MachineLimits
from .profile import Profile

__all__ = [
    "AxisArrays", "AxisLimits", "BackendNotFoundError", "BlockSpan", "FeedOracleError",
    "HelicalSegment", "InfeasibleError", "InternalError", "MachineDataError", "MachineLimits",
    "NCSyntaxError", "Path", "PathError", "Profile", "ProfileError", "SolverError",
    "TrajectoryError", "arc_segment", "line_segments", "path_from_pieces",
]

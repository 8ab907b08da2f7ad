"""The ``jerk+freq`` bound set: the frequency rule of :mod:`reference.core.phases` on top
of the jerk oracle (:mod:`optimal.jerk`). See :mod:`optimal.freq.oracle`."""

from .lower import freq_lower_bound, rest_pieces, segment_periods
from .oracle import DEFAULT_FREQ_GAP_TOL, solve_freq
from .upper import fir_filtered

__all__ = ["DEFAULT_FREQ_GAP_TOL", "fir_filtered", "freq_lower_bound", "rest_pieces",
           "segment_periods", "solve_freq"]

"""Limiting causes of the heuristic: the shared vocabulary of :mod:`reference.core.causes`.

Stages store causes as small integer codes into :data:`CAUSES`; the words and their
meaning are defined once, in the core.
"""

from __future__ import annotations

from ..core.causes import (AXIS_ACCELERATION, AXIS_VELOCITY, CAUSES, CORNER_RULE, DWELL,
                           EXACT_STOP, FEED, FORCED_STOP, FREQUENCY, HORIZON, IPO_CAP, JERK,
                           EXACT_STOP_SETTLE, cause_name)

__all__ = ["AXIS_ACCELERATION", "AXIS_VELOCITY", "CAUSES", "CORNER_RULE", "DWELL",
           "EXACT_STOP", "FEED", "FORCED_STOP", "FREQUENCY", "HORIZON", "IPO_CAP", "JERK",
           "EXACT_STOP_SETTLE", "cause_name"]

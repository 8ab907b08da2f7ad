"""The reference planner: a fast LookAhead velocity planner modelled on the SINUMERIK
continuous-path mode (exact stop G60/G9 with G601..G603, G64 corner speed, LookAhead with
a receding horizon, BRISK trapezoids and SOFT S-curves, velocity smoothing and dynamic
adaptation).

``plan(program, machine) -> ReferencePlan``; ``to_json_dict(plan)`` and
``ipo_samples(plan)`` give the CLI's JSON and CSV outputs. One module per stage; see
:mod:`reference.planner.engine` for the order and :mod:`reference.planner.parameters`
for every model choice the manuals leave open.
"""

from .engine import plan
from .export import to_json_dict
from .ipo import ipo_samples
from .parameters import DEFAULT_PARAMETERS, PlannerParameters
from .result import CornerRow, PlannedBlock, ReferencePlan, TraceEntry

__all__ = ["CornerRow", "PlannedBlock", "DEFAULT_PARAMETERS", "PlannerParameters",
           "ReferencePlan", "TraceEntry", "ipo_samples", "plan", "to_json_dict"]

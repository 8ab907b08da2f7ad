"""Stage: the plan as the JSON contract of DESIGN section 7 (the ``reference`` part)."""

from __future__ import annotations

from ..core.constraints import BOUND_SETS
from .result import ReferencePlan


def _num(x: float) -> float:
    """A plain float. Infinite values (a velocity jump where the machine allows none)
    stay ``inf``: the one JSON writer (:func:`reference.core.jsonio.write_json`) encodes them for
    every part of the contract alike, so the planner does not invent its own rule."""
    return float(x)


def to_json_dict(plan: ReferencePlan) -> dict:
    """The plan as a JSON-ready dict (schema ``result.schema.json``).

    Parameters
    ----------
    plan : ReferencePlan

    Returns
    -------
    dict
        Plain floats (an infinite ratio stays ``inf``; write the dict with
        ``reference.core.jsonio.write_json``, which encodes it as the JSON contract says).
        ``{"program", "machine", "bounds", "reference": {"time_s", "violations"},
        "blocks": [...]}``; ``bounds`` is the planner's own bound set, ``violations``
        lists the constraints of that set the own profile breaks
        (``{"constraint", "axis", "ratio", "s", "block"}``), and every block row has
        ``block, line, label, kind, length_mm, t_reference_s, v_exit_reference,
        limit_reference, hold_s, hold_cause`` (the block's imposed hold, dwell or
        exact-stop settle, contained in ``t_reference_s``; ``hold_cause`` ``""`` if none).
    """
    viol = []
    if plan.report is not None:
        for r in plan.report.violations(BOUND_SETS[plan.bound_set]):
            viol.append({"constraint": r.constraint, "axis": r.axis, "ratio": _num(r.ratio),
                         "s": _num(r.s), "block": int(r.block)})
    blocks = [{"block": int(b.block), "line": max(1, int(b.line)), "label": b.label,
               "kind": b.kind, "length_mm": max(0.0, _num(b.length_mm)),
               "t_reference_s": max(0.0, _num(b.time_s)),
               "v_exit_reference": max(0.0, _num(b.v_exit)),
               "limit_reference": b.cause, "hold_s": b.hold_s,
               "hold_cause": plan.holds.cause_of(int(b.block))} for b in plan.blocks]
    return {"program": plan.program, "machine": plan.machine, "bounds": plan.bound_set,
            "reference": {"time_s": _num(plan.time_s), "violations": viol},
            "blocks": blocks}

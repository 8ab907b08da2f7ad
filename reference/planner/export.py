"""Stage: the plan as the JSON contract of DESIGN section 7 (the ``reference`` part)."""

from __future__ import annotations

from typing import Iterator

import numpy as np

from ..core.constraints import BOUND_SETS
from ..core.geometry import KIND_CODES
from ..core.rows import inserted_splits, stretch_motion
from . import causes as C
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
    blocks = list(iter_json_rows(plan))
    return {"program": plan.program, "machine": plan.machine, "bounds": plan.bound_set,
            "reference": {"time_s": _num(plan.time_s), "violations": viol},
            "blocks": blocks}


#: Rows converted to Python objects at a time by :func:`iter_json_rows`.
_ROW_CHUNK = 1 << 16


def iter_json_rows(plan: ReferencePlan) -> Iterator[dict]:
    """The ``blocks`` rows of :func:`to_json_dict`, one dict at a time (a table printed
    from them never holds all 10^6 of them at once).

    One row per program block, in program order; an inserted corner rounding follows
    the block it is attributed to on a row of its own (``kind`` ``"rounding"``, ``line``
    the corner's first line, ``corner_lines`` both lines of the corner), as the
    comparison shows it: the block's row then keeps the rest of its length and time
    and, where the rounding ends the block, exits at the rounding's entry speed
    (:func:`_inserted_rows`). A block whose end is a corner in a rounding mode carries
    ``rounding``: ``"rounded"`` or ``"none: <reason>"``
    (:meth:`reference.core.rounding.RoundingTable.decision_by_block`).
    """
    # Built from the table's columns, a chunk of rows at a time: 10^6 blocks would cost
    # 10^6 row objects, or nine lists of 10^6 Python numbers, otherwise.
    tab = plan.blocks
    names = ("block", "line", "label", "kind", "length_mm", "time_s", "v_exit",
             "cause_code", "hold_s")
    floats = {"length_mm", "time_s", "v_exit", "hold_s"}    # plain floats, as the contract says
    full = {name: (np.asarray(tab.column(name), dtype=np.float64) if name in floats
                   else tab.column(name)) for name in names}
    hold_cause = plan.holds.causes_by_block()
    split = _inserted_rows(plan)
    # the rounding stage's decision at each block's end corner (G641..G645, RND/RNDM):
    # "rounded" or why none was inserted (issue 13: named in the block rows)
    decided = (plan.path.rounding.decision_by_block() if plan.path.rounding is not None
               else {})
    for lo in range(0, len(tab), _ROW_CHUNK):
        cols = [full[name][lo:lo + _ROW_CHUNK] for name in names]
        cols = [c.tolist() if isinstance(c, np.ndarray) else c for c in cols]
        cols[7] = [C.CAUSES[k] if k >= 0 else "" for k in cols[7]]
        for i, (b, ln, lab, kind, length, t, v, cause, hold) in enumerate(zip(*cols), lo):
            row = {"block": b, "line": max(1, ln), "label": lab, "kind": kind,
                   "length_mm": max(0.0, length), "t_reference_s": max(0.0, t),
                   "v_exit_reference": max(0.0, v), "limit_reference": cause,
                   "hold_s": hold, "hold_cause": hold_cause.get(b, "")}
            if b in decided:
                row["rounding"] = decided[b]
            extra = split.get(i)
            if extra is None:
                yield row
                continue
            own, inserted = extra
            row.update(own)
            yield row
            yield from inserted


def _inserted_rows(plan: ReferencePlan) -> dict[int, tuple[dict, list[dict]]]:
    """Per span holding inserted corner roundings: the fields of the block's own row
    that change and the rows of its roundings (a clothoid pair is one rounding).

    Each rounding is measured on the plan's profile exactly
    (:func:`reference.core.rows.stretch_motion`, the comparison's measure); its limiting
    cause is the planner's own for its first segment; the block keeps the rest of its
    length and time, so the rows still sum to the plan's duration.
    """
    path = plan.path
    splits = inserted_splits(path)
    if not splits:
        return {}
    spans = path.blocks
    runs = np.concatenate([sp.runs for sp in splits])            # (R, 2) first, last
    sb = path.s_breaks
    s0, s1 = sb[runs[:, 0]], sb[runs[:, 1] + 1]
    mot = stretch_motion(plan.profile, s0, s1)
    cause = (plan.segment_cause[runs[:, 0]] if plan.segment_cause is not None
             else np.full(runs.shape[0], -1))
    line_of = dict(zip(spans.block.tolist(), spans.line.tolist()))
    t_blk = np.asarray(plan.blocks.column("time_s"), dtype=np.float64)
    out = {}
    pos = 0
    for sp in splits:
        i, ks, tail = sp.span, sp.runs, sp.tail
        nk = ks.shape[0]
        sl = slice(pos, pos + nk)
        pos += nk
        blk, line = int(spans.block[i]), max(1, int(spans.line[i]))
        lengths = sb[ks[:, 1] + 1] - sb[ks[:, 0]]
        times = mot.time_s[sl]
        own = {"length_mm": max(0.0, float(spans.s_end[i] - spans.s_start[i]
                                           - sp.inserted_length)),
               "t_reference_s": max(0.0, float(t_blk[i] - times.sum()))}
        if tail:
            own["v_exit_reference"] = max(0.0, float(mot.v_entry[sl][0]))
        lines = ([max(1, line_of.get(b, 1)) for b in sp.corner_blocks]
                 if sp.corner_blocks is not None else [line, line])
        rows = [{"block": blk, "line": lines[0], "label": "",
                 "kind": KIND_CODES[int(path.kind[a])], "length_mm": float(ln),
                 "t_reference_s": max(0.0, float(t)), "v_exit_reference": max(0.0, float(v)),
                 "limit_reference": C.CAUSES[int(c)] if c >= 0 else "", "hold_s": 0.0,
                 "hold_cause": "", "corner_lines": list(lines)}
                for (a, _), ln, t, v, c in zip(ks.tolist(), lengths.tolist(),
                                               times.tolist(), mot.v_exit[sl].tolist(),
                                               cause[sl].tolist())]
        out[i] = (own, rows)
    return out

"""Stage: resolved NC blocks -> :class:`~reference.core.geometry.Path`.

This is the one path that the heuristic and the oracle both run on. Each moving block
becomes one segment (line, arc or helix); zero-length blocks add no segment but keep
their :class:`~reference.core.geometry.BlockSpan` (they may carry stops or aux words).

Stops (``Path.stop_reason``) are decided here, as the control decides them before the
LookAhead (sinumerik-model sections 3 and 5.2). Model choices, each a documented rule:

* exact stop (G60 modal, G9 non-modal; NGC G61.1) -> rest at the block end;
* NGC G61 (exact path) -> rest at every non-tangential block end;
* a block without path motion that the main run executes (G4 dwell, M/S/T/D/H words,
  ``MSG``, a kept cycle) -> rest where it sits; pure calculation, label or modal-only
  blocks are handled in block preparation and do not stop the path;
* M0, M1 (programmed stop), M2, M30 (end) in a moving block -> rest at its end;
  M6 (tool change) in a moving block -> rest at its start (aux output before motion);
  a positioning-axis block (SINUMERIK ``POS[A]=...``) -> rest at its start and its end;
  other M, S, T, D, H words in a moving block are output during motion: no stop;
* SINUMERIK: geometry axes (X, Y, Z) move in one of two consecutive moving blocks but
  not in the other (e.g. ``A30`` alone between two X blocks) -> rest between them.

The last rule is the function manual's list of transitions where "the axes stop between
the blocks anyway" (sinumerik-model 5.2 group 1: "geometry axes move in one block but
not in the other", next to "the next block has no path motion", the positioning-axis
change and the auxiliary output before motion, which are path stops here too). It is a
rule of the block sequence, not of velocity planning: the control stops there whatever
the LookAhead would allow, because the path velocity changes its meaning (F and the path
parameter refer to the geometry axes in one block and to the other axes in the next).
So it is a path stop that every planner obeys, the oracle included; the gap does not
charge it to the heuristic. NGC programs do not get it: LinuxCNC's planner blends a
transition into or out of a rotary-only move (it skips only the blend arc and the
tangency test there).

Stops that only the heuristic makes (a BRISK/SOFT change) belong to the reference
planner (:mod:`reference.planner.stops`), not to the path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .core.errors import MachineDataError, PathError
from .core.geometry import KIND_CODES, BlockSpans, Path, arc_segments, line_segments
from .core.limits import MachineLimits
from .core.rules import is_tangential
from .core.tolerances import (ARC_RADIUS_REL_TOL, ARC_RADIUS_TOL_MM, MAX_BLOCK_MOTION_S,
                              POS_TOL_MM)
from .machine import Machine
from .nc.program import Block, Program, ProgramWarning
from .rounding import round_corners
from .tangential import TangentialResult, tangential_path
from .trc import TrcResult, compensate_path

#: Stop reason where geometry axes move in one block only (sinumerik-model 5.2).
GEOMETRY_AXES_STOP = "geometry axes move in one block only"

_PLANES = {"G17": ("X", "Y"), "G18": ("Z", "X"), "G19": ("Y", "Z")}
_STOP_AT_END_M = {0: "M0 programmed stop", 1: "M1 optional stop", 2: "M2 program end",
                  30: "M30 program end", 17: "M17 subprogram end"}
_STOP_AT_START_M = {6: "M6 tool change"}


def _aux_stops(block: Block) -> tuple[str, str]:
    """(reason at block start, reason at block end) caused by M words of a moving block."""
    start = end = ""
    for letter, value in block.aux:
        if letter == "POS":      # positioning axes: the path rests while they move
            start = end = f"positioning axis POS[{value}]"
            continue
        if letter != "M" or value != int(value):
            continue
        code = int(value)
        if code in _STOP_AT_START_M:
            start = _STOP_AT_START_M[code]
        if code in _STOP_AT_END_M:
            end = _STOP_AT_END_M[code]
    return start, end


def _idle_stop(block: Block) -> str:
    """Stop reason of a block without path motion, or "" if the main run skips it."""
    if block.dwell_s is not None:
        return f"dwell G4 {block.dwell_s:g} s"
    for letter, value in block.aux:
        if letter == "M" and value == int(value) and int(value) in _STOP_AT_END_M:
            return _STOP_AT_END_M[int(value)]
        if letter == "M" and value == int(value) and int(value) in _STOP_AT_START_M:
            return _STOP_AT_START_M[int(value)]
    if block.aux:
        words = " ".join(f'{l}="{v}"' if isinstance(v, str) else f"{l}{v:g}"
                         for l, v in block.aux)
        return f"block without path motion ({words})"
    if block.message is not None:
        return "block without path motion (MSG)"
    if block.kept_unmodelled:
        return f"block without path motion ({block.kept_unmodelled[0]})"
    return ""


def prepare(program: Program) -> Path:
    """Build the path of a program.

    Parameters
    ----------
    program : Program
        Parsed program (absolute positions in mm / degrees).

    Returns
    -------
    Path
        One segment per moving block, a :class:`BlockSpan` for every block, stop flags.

    Raises
    ------
    PathError
        An arc whose radii do not match or with zero radius (names file, line, block).
    """
    axes = program.axes
    n = len(axes)
    geometry = np.array([a in ("X", "Y", "Z") for a in axes])
    index = {a: i for i, a in enumerate(axes)}
    blocks = program.blocks
    nb = len(blocks)

    starts = np.array([b.start for b in blocks], dtype=np.float64).reshape(nb, n)
    ends = np.array([b.end for b in blocks], dtype=np.float64).reshape(nb, n)
    is_motion = np.array([b.motion is not None for b in blocks], dtype=bool)
    is_arc = np.array([b.motion in ("G2", "G3") for b in blocks], dtype=bool)
    delta = ends - starts
    geo = np.sqrt(np.sum(delta[:, geometry] ** 2, axis=1))
    allax = np.sqrt(np.sum(delta ** 2, axis=1))
    line_len = np.where(geo > POS_TOL_MM, geo, allax)
    geo_moves = is_arc | (geo > POS_TOL_MM)        # per block: X, Y or Z move
    del delta, geo, allax
    moving_line = is_motion & ~is_arc & (line_len > POS_TOL_MM)
    moving = moving_line | is_arc  # arcs decided below (a full circle has start == end)

    # --- packed parameters, one row per moving block, in block order -------------
    rows = np.flatnonzero(moving)
    # line_segments builds fresh arrays from these fresh copies (origin is the copy
    # itself), except block, which is ``rows``: only that one is copied before the arcs
    # are written in (10^6 segments: a copy of all would be some 150 MB at once)
    packed = line_segments(starts[rows], ends[rows], geometry, rows)
    packed["block"] = packed["block"].copy()
    arc_i = np.flatnonzero(is_arc[rows])           # positions among the moving rows
    if arc_i.size:
        arc_rows = rows[arc_i]
        e1 = np.zeros((arc_i.size, n))
        e2 = np.zeros((arc_i.size, n))
        centers = np.empty((arc_i.size, n))
        cw = np.empty(arc_i.size, dtype=bool)
        turns = np.empty(arc_i.size, dtype=np.int64)
        for j, r in enumerate(arc_rows):
            b = blocks[r]
            if b.plane_basis is not None:       # a rotated frame tilts the plane
                e1[j, :3], e2[j, :3] = b.plane_basis
            else:
                u, v = _PLANES[b.plane]
                e1[j, index[u]] = 1.0
                e2[j, index[v]] = 1.0
            centers[j] = b.center
            cw[j] = b.motion == "G2"
            turns[j] = b.turns
        ps = starts[arc_rows] - centers
        r0 = np.hypot(np.sum(ps * e1, axis=1), np.sum(ps * e2, axis=1))
        tol = np.maximum(ARC_RADIUS_TOL_MM, ARC_RADIUS_REL_TOL * r0)
        try:
            arcs = arc_segments(starts[arc_rows], ends[arc_rows], centers, e1, e2, cw, turns,
                                geometry, arc_rows, tol)
        except PathError as exc:
            b = blocks[exc.block]
            raise PathError(f"{program.file}:{b.line}: {exc}", b.index) from None
        for k in packed:
            packed[k][arc_i] = arcs[k]
    del starts, ends           # the spans below are 10^6 objects: make room first
    keep = packed["length"] > POS_TOL_MM
    if not np.all(keep):
        rows = rows[keep]
        packed = {k: v[keep] for k, v in packed.items()}
    m = rows.size
    seg_of_block = np.full(nb, -1, dtype=np.int64)
    seg_of_block[rows] = np.arange(m)

    feed = np.array([np.inf if (blocks[r].motion == "G0" or blocks[r].feed_mm_s is None)
                     else blocks[r].feed_mm_s for r in rows], dtype=np.float64)
    rapid = np.array([blocks[r].motion == "G0" for r in rows], dtype=bool)

    # --- stops at the m + 1 breaks -----------------------------------------------
    reasons = [""] * (m + 1)
    # SINUMERIK: geometry axes in one of two consecutive moving blocks only (5.2)
    geo_change = np.zeros(m + 1, dtype=bool)
    if program.dialect == "sinumerik" and m >= 2:
        geo_seg = geo_moves[rows]
        geo_change[1:m] = geo_seg[1:] != geo_seg[:-1]

    # the block spans as columns (:class:`BlockSpans`): per block its break range
    # ``[k0, k0 + n)`` (a block without motion sits at the break in front of the next
    # segment), its stop reason and its dwell
    k0 = np.empty(nb, dtype=np.int64)
    n_seg = np.empty(nb, dtype=np.int64)
    span_stop = [""] * nb
    dwell = np.zeros(nb)
    next_break = 0            # break index in front of the next segment
    seg_list = seg_of_block.tolist()
    for i, b in enumerate(blocks):
        seg = seg_list[b.index]
        if seg >= 0:
            at_start, at_end = _aux_stops(b)
            if at_start and not reasons[seg]:
                reasons[seg] = at_start
            end_reason = at_end
            if b.exact_stop_here:
                end_reason = end_reason or ("exact stop G60" if b.continuous_mode == "G60"
                                            else "exact stop G9")
            if end_reason:
                reasons[seg + 1] = end_reason
            k0[i], n_seg[i], span_stop[i] = seg, 1, end_reason
            next_break = seg + 1
        else:
            why = _idle_stop(b)
            if why and not reasons[next_break]:
                reasons[next_break] = why
            k0[i], n_seg[i], span_stop[i] = next_break, 0, why
            dwell[i] = float(b.dwell_s or 0.0)
    # the geometry-axes stop last: a reason the program states (POS, M6, ...) names it
    for k in np.flatnonzero(geo_change).tolist():
        if not reasons[k]:
            reasons[k] = GEOMETRY_AXES_STOP
            i = int(rows[k - 1])                # the block that ends at break k
            if not span_stop[i]:
                span_stop[i] = GEOMETRY_AXES_STOP
    s_at = np.concatenate(([0.0], np.cumsum(packed["length"])))
    span_feed = np.full(nb, np.inf)
    span_feed[rows] = feed
    spans = BlockSpans(
        block=[b.index for b in blocks], line=[b.line for b in blocks], label=[b.label for b in blocks],
        kind=[b.motion or "none" for b in blocks], s_start=s_at[k0],
        s_end=s_at[k0 + n_seg], first_segment=k0, n_segments=n_seg, feed_mm_s=span_feed,
        stop_reason=span_stop, dwell_s=dwell)
    reasons[0] = reasons[0] or "start"
    reasons[m] = reasons[m] or "end"

    path = Path(axes=tuple(axes), geometry=geometry, rotary=np.array(program.rotary),
                feed=feed, rapid=rapid, stop=np.array([bool(r) for r in reasons]),
                stop_reason=tuple(reasons), blocks=spans, source=program.file,
                **packed)
    return _exact_path_stops(path, program)


def _exact_path_stops(path: Path, program: Program) -> Path:
    """NGC G61: rest at every non-tangential break whose block before is in G61."""
    if path.n_segments < 2:
        return path
    modes = np.array([program.blocks[b].continuous_mode == "G61" for b in path.block[:-1]])
    if not modes.any():
        return path
    t_in, t_out = path.junction_tangents()
    kink = ~is_tangential(t_in, t_out)
    reasons = list(path.stop_reason)
    for k in np.flatnonzero(modes & kink):
        reasons[k + 1] = reasons[k + 1] or "exact path G61 corner"
    fields = {f: getattr(path, f) for f in ("axes", "geometry", "rotary", "origin", "e1",
              "e2", "d", "radius", "omega", "theta0", "length", "block", "kind", "feed",
              "rapid", "blocks", "source", "dradius", "sharpness")}
    return Path(stop=np.array([bool(r) for r in reasons]), stop_reason=tuple(reasons),
                **fields)


def unmodelled_features(program: Program) -> tuple[ProgramWarning, ...]:
    """Warnings for programmed features one side of the comparison does not know.

    Tool radius compensation (:mod:`reference.trc`) and tangential control
    (:mod:`reference.tangential`) are applied by :func:`build_path`; what they cannot
    model is an error there, naming the line. DRIVE: the heuristic reduces the
    acceleration above the knee, the oracle does not.

    Parameters
    ----------
    program : Program

    Returns
    -------
    tuple[ProgramWarning, ...]
        At most one warning per feature, naming the first line that uses it.
    """
    out: list[ProgramWarning] = []
    drive = next((b for b in program.blocks if b.accel_mode == "DRIVE"), None)
    if drive is not None:
        out.append(ProgramWarning(program.file, drive.line,
                                  "DRIVE: the heuristic reduces the acceleration above "
                                  "ACCEL_REDUCTION_SPEED_POINT as the machine data set it "
                                  "(MD35220, MD35230, MD35240); the oracle does not know "
                                  "DRIVE and accelerates with MAX_AX_ACCEL, so the gap "
                                  "includes that reduction"))
    return tuple(out)


def require_axes(path: Path, limits: MachineLimits) -> None:
    """Check that the machine has limits for every axis the path moves.

    Raises
    ------
    MachineDataError
        Naming the axis and the first source line that moves it.
    """
    have = set(limits.names)
    for i, name in enumerate(path.axes):
        if name in have:
            continue
        moved = np.flatnonzero(np.abs(path.d[:, i]) + path.radius * (
            np.abs(path.e1[:, i]) + np.abs(path.e2[:, i])) > 0)
        if moved.size:
            blk = int(path.block[moved[0]])
            line = next((b.line for b in path.blocks if b.block == blk), 0)
            raise MachineDataError(
                f"axis.{name}", None,
                f"{path.source}:{line}: the program moves axis {name}, but machine "
                f"'{limits.name}' defines no limits for it (add an [axis.{name}] section)")


def restrict_to_machine(path: Path, limits: MachineLimits) -> Path:
    """Drop axes the program names but never moves and the machine does not have.

    Parameters
    ----------
    path : Path
    limits : MachineLimits

    Returns
    -------
    Path
        The same path over the axes that the machine knows (after :func:`require_axes`).
    """
    require_axes(path, limits)
    keep = np.array([a in set(limits.names) for a in path.axes])
    if keep.all():
        return path
    f = {k: getattr(path, k) for k in ("radius", "omega", "theta0", "length", "block",
                                       "kind", "feed", "rapid", "stop", "stop_reason",
                                       "blocks", "source", "dradius", "sharpness")}
    return Path(axes=tuple(a for a, k in zip(path.axes, keep) if k),
                geometry=path.geometry[keep], rotary=path.rotary[keep],
                origin=path.origin[:, keep], e1=path.e1[:, keep], e2=path.e2[:, keep],
                d=path.d[:, keep], **f)


def build_path(program: Program, machine: Machine) -> Path:
    """The path both planners run on: the one way from a program and a machine to a Path.

    The heuristic (:func:`reference.planner.plan`), the oracle's callers and the
    comparison all take their path from here, so the gap measures velocity planning
    alone (DESIGN section 1): the programmed contour (:func:`prepare`) over the axes the
    machine knows (:func:`restrict_to_machine`), then the stages in the control's order
    (DESIGN section 5): tool radius compensation (:func:`reference.trc.apply_trc`),
    tangential control (:func:`reference.tangential.apply_tangential`) and the corner
    rounding of blocks in G641..G645 (:func:`reference.rounding.round_corners`).

    Parameters
    ----------
    program : Program
        Parsed program (absolute positions in mm / degrees).
    machine : Machine
        Machine data; its limits name the axes the path keeps.

    Returns
    -------
    Path

    Raises
    ------
    PathError
        Arc geometry out of tolerance (names file and line).
    MachineDataError
        The program moves an axis the machine has no limits for, or tangential control
        turns one (names axis and line).
    PathError
        Tool radius compensation or tangential control cannot build the path: a missing
        tool radius, the tool does not fit (the control's collision alarm), a model limit
        (names file and line).
    """
    return path_stages(program, machine).path


@dataclass(frozen=True, slots=True, eq=False)
class PathStages:
    """The stages of :func:`build_path` with what each decided (for ``inspect``).

    Attributes
    ----------
    trc : reference.trc.TrcResult
        Tool radius compensation: the compensated path, its blocks and corners.
    tangential : reference.tangential.TangentialResult
        Tangential control: the path with the following axes, their corners.
    path : Path
        The final path (after rounding; its ``rounding`` table says what was rounded).
    """

    trc: TrcResult
    tangential: TangentialResult
    path: Path


def path_stages(program: Program, machine: Machine) -> PathStages:
    """:func:`build_path` with the result of every stage kept (same path, same errors)."""
    path = restrict_to_machine(prepare(program), machine.limits)
    _check_motion_times(path)
    trc = compensate_path(path, program, machine)
    tang = tangential_path(trc.path, program, machine)
    return PathStages(trc, tang, round_corners(tang.path, program, machine))


def _check_motion_times(path: Path) -> None:
    """Reject a block whose motion at its programmed feed lasts beyond
    :data:`~reference.core.tolerances.MAX_BLOCK_MOTION_S` (names file and line)."""
    if path.n_segments == 0:
        return
    with np.errstate(divide="ignore", invalid="ignore"):
        t_min = np.where(path.feed > 0, path.length / path.feed, 0.0)
    t_blk = np.bincount(path.block, weights=t_min)
    worst = int(np.argmax(t_blk))
    if t_blk[worst] > MAX_BLOCK_MOTION_S:
        span = next(b for b in path.blocks if b.block == worst)
        raise PathError(f"{path.source}:{span.line}: the block moves "
                        f"{span.length:.6g} mm at F{60.0 * path.feed[path.block == worst][0]:g} "
                        f"mm/min, at least {t_blk[worst]:.3g} s of motion, above the "
                        f"{MAX_BLOCK_MOTION_S:.0e} s one block may take (float64 time "
                        f"resolution); raise the feed or split the block", worst)


__all__ = ["GEOMETRY_AXES_STOP", "PathStages", "build_path", "path_stages", "prepare",
           "require_axes",
           "restrict_to_machine", "unmodelled_features", "KIND_CODES"]

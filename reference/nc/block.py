"""One NC line, full treatment: from its words to one resolved
:class:`~reference.nc.program.Block`.

:func:`_block` goes through the line in sections, in this order: parameter assignments
(NGC), words, G codes, keywords (SINUMERIK flags), named addresses, calls (``MSG``,
tangential control, cycles), frames, feed and dwell, motion (arcs by
:func:`reference.nc.arcs._arc`), modal snapshot and the block itself.
"""

from __future__ import annotations

import math

from ..core.units import MM_PER_INCH
from .arcs import _arc
from .expr import Cursor, ExprError, ngc_parameter_name, parse_expr
from .frames import _apply_frame, _apply_g10, _apply_g92, _ngc_frame
from .lines import Stmt, Word
from .program import NO_EXTRA, Block, BlockExtra, Modal, Tangential
from .state import (_G_GROUPS_NGC, _G_GROUPS_SIN, _IGNORED_G_NGC, _IGNORED_G_SIN,
                    _IGNORED_WHY, _MODES10_SIN, _NGC_CS, _PLANE_AXES, _UNSUPPORTED_G,
                    MAX_COORDINATE_MM, MAX_DWELL_S, MAX_FEED_MM_MIN, ROTARY, _Interp)


def _block(ip: _Interp, st: Stmt) -> bool:
    """Execute one ordinary line; returns True at program end (M2/M30)."""
    ngc = ip.ngc
    # --- NGC parameter assignments: all values are read before any is set, and the
    # words of the line see the old values (RS274/NGC); committed after the words
    pending: list[tuple[str, float]] = []
    for target, node, col in st.assigns:
        if ngc:
            if target[0] == "var":
                key = target[1]
            else:
                try:
                    key = ngc_parameter_name(ip.ev(st, target[1], col + 1), 0)
                except ExprError as exc:
                    raise ip.err(st, col + 1, str(exc)) from None
            pending.append((key, ip.ev(st, node, col + 1)))
        else:                                  # pragma: no cover - SINUMERIK uses words
            ip.vars[target] = ip.ev(st, node, col + 1)
    # --- words ------------------------------------------------------------------
    g_codes: list[tuple[float, int]] = []
    axis_words: list[tuple[str, float, str, int]] = []
    centre: dict[str, tuple[float, str, int]] = {}
    aux: list[tuple[str, float]] = []
    named: dict[str, tuple[float, int]] = {}
    feed_word: tuple[float, int] | None = None
    p_word = q_word = r_word = l_word = None
    seen: dict[str, float] = {}
    m98_col = 0
    positioning: list[tuple[str, float, str, int]] = []   # POS[axis]=value
    t_word = False                              # a T word in this block (edge D1 default)
    d_word: tuple[float, int] | None = None     # the D word (edge; NGC: tool or diameter)
    block_feed: float | None = None             # a feed of this block only (POS with FA)

    def once(name: str, val: float, col: int) -> None:
        """A word may repeat in a block only with the same value."""
        prev = seen.get(name)
        if prev is not None and prev != val:
            sep = "=" if len(name) > 1 else ""
            raise ip.err(st, col, f"{name} is programmed twice in this block with different "
                                  f"values ({name}{sep}{prev:g} and {name}{sep}{val:g})")
        seen[name] = val

    for w in st.words:
        name = w.name
        if not ngc and name.startswith(("POS[", "POSA[")):   # positioning axis
            axis = name[name.index("[") + 1:-1].strip()
            if not axis or not ip.is_axis_name(axis):
                raise ip.err(st, w.col, f"{name}: '{axis}' is not an axis name")
            val = ip.ev(st, w.value, w.col)
            if not math.isfinite(val):
                raise ip.err(st, w.col, f"the value of {name} is too large to be a number")
            once(name.replace("POSA[", "POS["), val, w.col)
            ip.add_axis(axis)
            positioning.append((axis, val, w.mode, w.col))
            if name.startswith("POSA"):
                ip.warn(st, f"{name}: POSA is modelled as POS (the block waits until the "
                            "axis is in position)")
            continue
        if not ngc and name.startswith("FA["):       # positioning-axis feed (modal)
            axis = name[3:-1].strip()
            if not axis or not ip.is_axis_name(axis):
                raise ip.err(st, w.col, f"{name}: '{axis}' is not an axis name")
            val = ip.ev(st, w.value, w.col)
            if not 0.0 < val * ip.lin(axis) <= MAX_FEED_MM_MIN:
                raise ip.err(st, w.col, f"{name}={val:g}: the positioning feed must be > 0 "
                                        f"and at most {MAX_FEED_MM_MIN:g} mm/min")
            ip.fa[axis] = val * ip.lin(axis) / 60.0
            continue
        if not ngc and "[" in name:                  # R[i]=, ATOL[X]=, ARRAY[i]=
            _indexed_assignment(ip, st, w)
            continue
        if not ngc and name in ip.declared:          # a DEF variable, also if one letter
            ip.vars[name] = ip.ev(st, w.value, w.col)
            continue
        if not ngc and len(name) > 1 or (not ngc and name not in "GMFSTDHIJKPQRLXYZABCUVWEN"):
            if name in ("CR", "ADIS", "ADISPOS", "TURN", "CTOL", "OTOL", "DISC", "AR", "RPL",
                        "STOLF", "RND", "RNDM", "SF", "OFFN"):
                named[name] = (ip.ev(st, w.value, w.col), w.col)
                once(name, named[name][0], w.col)
                continue
            if name.startswith("R") and name[1:].isdigit():
                ip.vars[name] = ip.ev(st, w.value, w.col)
                continue
            if name in ip.declared:
                ip.vars[name] = ip.ev(st, w.value, w.col)
                continue
            if ip.is_axis_name(name):
                ip.add_axis(name)
                axis_words.append((name, ip.ev(st, w.value, w.col), w.mode, w.col))
                once(name, axis_words[-1][1], w.col)
                continue
            # an assignment to an undeclared name: accept it as a variable, say so
            ip.declared.add(name)
            ip.vars[name] = ip.ev(st, w.value, w.col)
            ip.warn(st, f"variable {name} is assigned without DEF; taken as a REAL variable",
                    once_key=f"undeclared {name}")
            continue
        if w.value[0] == "str":                      # T="DRILL 8.5": a tool by name
            once(name, hash(w.value[1]), w.col)
            aux.append(("T", w.value[1]))
            ip.tool = w.value[1]
            t_word = True
            continue
        val = ip.ev(st, w.value, w.col)
        if not math.isfinite(val):
            # 400 nines, 1e308*10: float overflow, never a value a control accepts
            raise ip.err(st, w.col, f"the value of {name} is too large to be a number "
                                    f"({val:g})")
        if name == "G":
            g_codes.append((val, w.col))
            continue
        if name == "M":
            aux.append(("M", val))
            if ngc and val == 98.0:
                m98_col = w.col
            continue
        if name != "N":
            once(name, val, w.col)
        if name in "XYZ" or name in "ABC" or (ngc and name in "UVW") or (
                not ngc and name in "UVWE"):
            ip.add_axis(name)
            axis_words.append((name, val, w.mode, w.col))
        elif name in "IJK":
            centre[name] = (val, w.mode, w.col)
        elif name == "F":
            feed_word = (val, w.col)
        elif name in "SH":
            aux.append((name, val))
            if name == "H":
                ip.offset_no = int(val)
        elif name == "T":
            aux.append(("T", val))
            ip.tool = int(val)
            t_word = True
        elif name == "D":
            aux.append(("D", val))
            ip.offset_no = int(val)
            d_word = (val, w.col)
        elif name == "P":
            p_word = (val, w.col)
        elif name == "Q":
            q_word = (val, w.col)
        elif name == "R":
            if not ngc:
                raise ip.err(st, w.col, "R parameter needs '=' (R1=10)")
            r_word = (val, w.col)
        elif name == "L":
            l_word = (val, w.col)
        elif name == "N":
            continue                     # block numbers were taken as labels by the lexer
        else:
            raise ip.err(st, w.col, f"unknown address {name}")
    for key, value in pending:
        ip.vars[key] = value
    # --- G codes ------------------------------------------------------------------
    g9 = False
    dwell = None
    is_dwell = False
    g10 = False
    g53 = False
    g92 = False
    program_end = False
    motion_word_col = 1
    motion_set = False
    groups = _G_GROUPS_NGC if ngc else _G_GROUPS_SIN
    in_group: dict[int, float] = {}
    for g, col in g_codes:
        gi = round(g, 1)
        for k, grp in enumerate(groups):
            if gi in grp:
                if k in in_group and in_group[k] != gi:
                    raise ip.err(st, col, f"G{in_group[k]:g} and G{gi:g} are in the same modal "
                                          "group: program only one of them in a block")
                in_group[k] = gi
    for g, col in g_codes:
        gi = round(g, 1)
        if gi in (0, 1, 2, 3):
            ip.motion = f"G{int(gi)}"
            motion_word_col = col
            motion_set = True
        elif gi in _UNSUPPORTED_G:
            raise ip.err(st, col, _UNSUPPORTED_G[gi])
        elif gi == 4:
            is_dwell = True
        elif gi == 9 and not ngc:
            g9 = True
        elif gi in (17, 18, 19):
            ip.plane = f"G{int(gi)}"
        elif gi == 90:
            ip.absolute = True
        elif gi == 91:
            ip.absolute = False
        elif ngc and gi == 90.1:
            ip.ijk_absolute = True
        elif ngc and gi == 91.1:
            ip.ijk_absolute = False
        elif (not ngc and gi in (70, 700)) or (ngc and gi == 20):
            # G70 sets lengths only; G700 and NGC G20 also feeds (inch/min)
            ip.inch = True
            ip.feed_inch = gi != 70
            if not ip.out:
                ip.start_units = "inch"
        elif (not ngc and gi in (71, 710)) or (ngc and gi == 21):
            ip.inch = False
            ip.feed_inch = False
        elif not ngc and gi in _MODES10_SIN:
            ip.mode10 = _MODES10_SIN[int(gi)]
        elif not ngc and gi in (601, 602, 603):
            ip.criterion = f"G{int(gi)}"
        elif ngc and gi == 61:
            ip.mode10 = "G61"
        elif ngc and gi == 61.1:
            ip.mode10 = "G60"
        elif ngc and gi == 64:
            ip.mode10 = "G64"
            for word, letter in ((p_word, "P"), (q_word, "Q")):
                if word is not None and word[0] < 0:
                    # LinuxCNC passes a negative tolerance on as "no tolerance" (G64 alone)
                    ip.warn(st, f"G64 {letter}{word[0]:g}: a negative tolerance means no "
                                f"tolerance on LinuxCNC (as G64 without {letter}); taken so")
            p_tol = p_word[0] if p_word is not None and p_word[0] >= 0 else None
            q_tol = q_word[0] if q_word is not None and q_word[0] >= 0 else None
            ip.ctol = p_tol * ip.lin("X") if p_tol is not None else None
            ip.naive_cam = (q_tol * ip.lin("X") if q_tol is not None else ip.ctol)
            p_word = None
        elif gi in (40, 41, 42):
            ip.trc = f"G{int(gi)}"
            if ngc:
                _ngc_comp_tool(ip, st, gi, d_word, col)
        elif ngc and gi in (41.1, 42.1):         # dynamic TRC: the D word is the diameter
            ip.trc = f"G{int(gi)}"
            _ngc_comp_tool(ip, st, gi, d_word, col)
        elif not ngc and gi in (450, 451):
            ip.trc_corner = f"G{int(gi)}"
        elif ngc and gi == 10:
            g10 = True
        elif not ngc and gi == 500:              # settable frames off: zero, as modelled
            continue
        elif ngc and gi == 53 or (not ngc and gi in (53, 153)):
            g53 = True
            ip.warn(st, f"G{gi:g}: positions in machine coordinates (frames suppressed for "
                        "this block; work and tool offsets of the control are unknown)")
        elif ngc and gi in (28, 30):
            ip.warn(st, f"G{gi:g} (home move) needs the machine's home position; kept "
                        "without motion")
            axis_words = []
        elif ngc and 81 <= gi <= 89 or (ngc and gi in (73, 74)):
            raise ip.err(st, col, f"canned cycle G{gi:g} is not supported; expand it into "
                                  "G0/G1 moves")
        elif ngc and gi in _NGC_CS:
            ip.cs_active = _NGC_CS[gi]
            if ip.cs_active not in ip.cs:
                ip.warn(st, f"work offset G{gi:g} is taken as zero (its values live in the "
                            "control; set them with G10 L2 to model them)")
            _ngc_frame(ip)
        elif ngc and gi == 92:
            g92 = True
        elif ngc and gi in (92.1, 92.2):
            ip.g92 = {}
            _ngc_frame(ip)
        elif ngc and gi == 92.3:
            ip.warn(st, "G92.3 (restore saved G92 offsets) is not modelled; the offsets stay "
                        "as they are")
        elif (ngc and gi in _IGNORED_G_NGC) or (not ngc and gi in _IGNORED_G_SIN):
            why = _IGNORED_WHY.get(gi, "work offsets are taken as zero (their values live in "
                                       "the control)")
            ip.warn(st, f"G{gi:g} is kept without effect on the motion model: {why}")
        else:
            raise ip.err(st, col, f"unknown G code G{gi:g}")
    if m98_col:
        _m98(ip, st, m98_col, p_word)
    if not ngc:                                 # the cutting edge TRC uses (D, D1 after T)
        if d_word is not None:
            ip.edge = int(d_word[0])
        elif t_word:
            ip.edge = 1
    # --- flags (SINUMERIK keywords) ------------------------------------------------
    frame_cmd = None
    for flag, col in st.flags:
        if flag in ("BRISK", "SOFT", "DRIVE"):
            ip.accel_mode = flag
        elif flag in ("TRANS", "ATRANS", "ROT", "AROT"):
            frame_cmd = flag
        elif flag == "SUPA":
            g53 = True
            ip.warn(st, "SUPA: positions in machine coordinates (frames suppressed for this "
                        "block; work and tool offsets of the control are unknown)")
        elif flag == "RET":
            program_end = True
        else:
            ip.warn(st, f"{flag} is kept but not modelled")
    # --- named addresses ------------------------------------------------------------
    if "ADIS" in named:
        ip.adis = named["ADIS"][0] * ip.lin("X")
    if "ADISPOS" in named:
        ip.adispos = named["ADISPOS"][0] * ip.lin("X")
    if "CTOL" in named:
        v = named["CTOL"][0]
        ip.ctol = None if v < 0 else v * ip.lin("X")
    if "OTOL" in named:
        v = named["OTOL"][0]
        ip.otol = None if v < 0 else v
    if "AR" in named:
        raise ip.err(st, named["AR"][1], "arcs by opening angle (AR=) are not supported; "
                                         "program the end point with I/J/K or CR=")
    rnd = 0.0
    for word in ("RND", "RNDM"):
        if word in named:
            v, col = named[word]
            if v < 0:
                raise ip.err(st, col, f"{word}={v:g}: a rounding radius must be >= 0")
            if word == "RND":
                rnd = v * ip.lin("X")
            else:
                ip.rndm = v * ip.lin("X")
    for word, why in (("OFFN", "the contour offset is not applied"),
                      ("STOLF", "the G0 tolerance factor is not modelled"),
                      ("SF", "the thread start angle is not modelled")):
        if word in named:
            ip.warn(st, f"{word}={named[word][0]:g} is kept without effect: {why}")
    if "DISC" in named:
        v, col = named["DISC"]
        if not 0 <= v <= 100:
            raise ip.err(st, col, f"DISC={v:g} must be between 0 and 100")
        ip.disc = v
    # --- calls (MSG, TANG..., cycles) ------------------------------------------------
    message = st.message
    kept: list[str] = []
    for name, args, col in st.calls:
        if name == "MSG":
            a = args.strip()
            message = a.strip('"') if a else ""
            if '"' in a:
                message = a[a.find('"') + 1:a.rfind('"')]
        elif name in ("TANG", "TANGON", "TANGOF", "TLIFT", "TANGDEL"):
            _tangential(ip, st, name, args, col)
        elif not ngc and name == "$TC_DP6":
            _tool_radius_assignment(ip, st, args, col)
        elif not ngc and name in _UNSUPPORTED_MOTION_SIN and not args:
            raise ip.err(st, col + 1, f"{name} ({_UNSUPPORTED_MOTION_SIN[name]}) is not "
                                      "supported: its points would not be on the modelled "
                                      "path; convert it into G1/G2/G3 blocks")
        elif name.startswith("$"):
            kept.append(args)
            ip.warn(st, f"system variable statement '{args}' needs a real control; kept "
                        "without effect")
        else:
            text = f"{name}({args})" if args else name
            kept.append(text)
            ip.warn(st, f"{text} needs a real control (cycle or subprogram); kept as a "
                        "block without motion")
    if not ngc and l_word is not None:          # L123: subprogram call by number
        text = f"L{l_word[0]:g}"
        kept.append(text)
        ip.warn(st, f"{text} calls a subprogram that is not part of this file; kept as a "
                    "block without motion")
    # --- frames ------------------------------------------------------------------------
    if frame_cmd is not None:
        _apply_frame(ip, st, frame_cmd, axis_words, named)
        axis_words = []
    if g10:
        _apply_g10(ip, st, axis_words, l_word, p_word, r_word)
        axis_words = []
        r_word = None
    if g92:
        _apply_g92(ip, st, axis_words)
        axis_words = []
    # --- feed --------------------------------------------------------------------------
    if is_dwell:
        if ngc:
            if p_word is None:
                raise ip.err(st, 1, "G4 needs P (dwell time in seconds)")
            dwell = p_word[0]
        elif feed_word is not None:
            dwell = feed_word[0]
        elif any(a[0] == "S" for a in aux):
            revs = next(a[1] for a in aux if a[0] == "S")
            aux = [a for a in aux if a[0] != "S"]     # revolutions, not a spindle speed
            if ip.spindle_rpm:
                dwell = revs * 60.0 / ip.spindle_rpm
            else:
                kept.append(f"G4 S{revs:g}")
                ip.warn(st, f"G4 S{revs:g} (dwell in spindle revolutions) needs the spindle "
                            "speed, which no S word set before; the dwell time is not modelled")
        else:
            raise ip.err(st, 1, "G4 needs F (seconds) or S (spindle revolutions)")
        if dwell is not None and dwell < 0:
            raise ip.err(st, 1, f"negative dwell time {dwell:g} s")
        if dwell is not None and dwell > MAX_DWELL_S:
            raise ip.err(st, 1, f"dwell time {dwell:g} s is above {MAX_DWELL_S:g} s "
                                f"({MAX_DWELL_S / 86400:.1f} days): check the number")
        feed_word = None
    else:
        for a in aux:
            if a[0] == "S" and a[1] > 0:
                ip.spindle_rpm = a[1]
    if feed_word is not None and not is_dwell:   # a dwell's F is its time, not a feed
        f, col = feed_word
        if f < 0:
            raise ip.err(st, col, f"negative feed F{f:g}")
        mm_min = f * (MM_PER_INCH if ip.feed_inch else 1.0)
        if mm_min > MAX_FEED_MM_MIN:
            raise ip.err(st, col, f"feed F{f:g} is above {MAX_FEED_MM_MIN:g} mm/min, faster "
                                  "than any machine by orders of magnitude: check the number")
        ip.feed = mm_min / 60.0
    # --- motion ------------------------------------------------------------------------
    start = tuple(ip.pos[a] for a in ip.axes)
    centre_out = None
    plane_basis = None
    motion = None
    turns = 0
    if positioning:
        # A positioning axis moves on its own and the block waits for it. Modelled as
        # its own block: the axis alone at its FA feed or at rapid, the path at rest
        # before and after (prepare stops at both ends); a path move in the same block
        # would run concurrently, which this path model cannot express.
        if axis_words or motion_set or centre:
            col = (axis_words[0][3] if axis_words else motion_word_col)
            raise ip.err(st, col, f"POS[{positioning[0][0]}] with path motion in the same "
                                  "block is not supported: program the positioning axis "
                                  "in a block of its own")
        axis_words = positioning
        aux.append(("POS", " ".join(a[0] for a in positioning)))
        # one axis with its FA moves at that feed; otherwise (no FA, or several axes,
        # which the control moves independently) at rapid, each axis at its own limits
        if len(positioning) == 1 and positioning[0][0] in ip.fa:
            block_feed = ip.fa[positioning[0][0]]
        elif any(a[0] in ip.fa for a in positioning):
            ip.warn(st, "several positioning axes in one block are modelled as one rapid "
                        "move; their FA feeds are not applied")
    if axis_words or (motion_set and ip.motion in ("G2", "G3") and centre):
        if ip.motion is None and not positioning:
            raise ip.err(st, axis_words[0][3] if axis_words else 1,
                         "axis move without a motion command (G0/G1/G2/G3)")
        motion = ("G1" if block_feed is not None else "G0") if positioning else ip.motion
        if motion != "G0" and ip.feed is None:
            col = motion_word_col if motion_set else (axis_words[0][3] if axis_words else 1)
            raise ip.err(st, col, f"{motion} with no feed: program F before or in this block")
        if motion != "G0" and ip.feed == 0.0:
            # both controls refuse a feed move at F0 (it would never end); F0 alone is a
            # setting and only the move that uses it is an error
            col = feed_word[1] if feed_word is not None else (
                motion_word_col if motion_set else (axis_words[0][3] if axis_words else 1))
            raise ip.err(st, col, f"{motion} with feed F0: the move would never end; "
                                  "program a feed > 0")
        prog = ip.program_pos() if not g53 else dict(ip.pos)
        target = dict(prog)
        for name, val, mode, col in axis_words:
            v = val * ip.lin(name)
            incremental = (mode == "IC") or (mode != "AC" and not ip.absolute)
            target[name] = prog.get(name, 0.0) + v if incremental else v
        identity = ip.frame.identity
        machine = target if (g53 or identity) else ip.frame.to_machine(target)
        _check_range(ip, st, machine, axis_words, "position", motion_word_col)
        if motion in ("G2", "G3"):
            for word, rad in (("CR", named.get("CR")), ("R", r_word)):
                if rad is not None and not abs(rad[0] * ip.lin("X")) <= MAX_COORDINATE_MM:
                    raise ip.err(st, rad[1], f"arc radius {word}{'=' if len(word) > 1 else ''}"
                                             f"{rad[0]:g} is beyond {MAX_COORDINATE_MM:g} mm, "
                                             "larger than any machine: check the number")
            centre_out, plane_basis, turns = _arc(ip, st, motion, prog, target, centre,
                                                  named, r_word, p_word, motion_word_col)
            if ip.frame.tilt is not None and not g53:
                # a tilted frame tilts the working plane: the arc lies in R * (plane)
                u, v, _ = _PLANE_AXES[ip.plane]
                unit = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
                plane_basis = (ip.frame.rotate_vec(unit[u]), ip.frame.rotate_vec(unit[v]))
            if centre_out is not None:
                cols = [c[2] for c in centre.values()] + (
                    [named["CR"][1]] if "CR" in named else []) + (
                    [r_word[1]] if r_word is not None else [])
                col = min(cols, default=motion_word_col)
                _check_range(ip, st, dict(zip(ip.axes, centre_out)), (), "arc centre", col)
        ip.pos.update(machine)
    end = tuple(ip.pos[a] for a in ip.axes)
    tang = ip.tang_defs.get(ip.tang_active) if ip.tang_active else None
    modal_values = (ip.plane, ip.mode10, ip.criterion, ip.adis, ip.adispos, ip.ctol, ip.otol,
                    tuple(sorted(ip.atol.items())), ip.naive_cam, ip.accel_mode, ip.trc,
                    ip.trc_corner, ip.disc, ip.tool, ip.offset_no, tang, ip.rndm,
                    *_trc_tool(ip))
    if ip.last_modal_values == modal_values:
        modal = ip.modal
    else:
        modal = Modal(*modal_values)
        ip.last_modal_values = modal_values
        ip.modal = modal
    if (centre_out is None and not turns and dwell is None and not aux and message is None
            and not st.comment and not kept and plane_basis is None and not rnd):
        extra = NO_EXTRA
    else:
        extra = BlockExtra(center=centre_out, turns=turns, dwell_s=dwell, aux=tuple(aux),
                           message=message, comment=st.comment, kept_unmodelled=tuple(kept),
                           column_of_motion=motion_word_col, plane_basis=plane_basis,
                           rnd_mm=rnd)
    ip.last_end = end
    ip.out.append(Block(len(ip.out), st.line, st.text, st.label, motion, start, end,
                        ip.feed if block_feed is None else block_feed,
                        (ip.mode10 == "G60") or g9, modal, extra))
    if ngc and ("M", 99.0) in aux:
        ip.warn(st, "M99 in the main program repeats it on the control; taken as the end of "
                    "the program")
        return True
    return program_end or any(a == ("M", 2.0) or a == ("M", 30.0) or
                              (not ngc and a == ("M", 17.0)) for a in aux)


#: SINUMERIK motion commands (G group 1) besides G0..G3 that the model does not
#: interpolate; a block under them would silently become a straight line.
_UNSUPPORTED_MOTION_SIN = {"ASPLINE": "Akima spline", "BSPLINE": "B spline",
                           "CSPLINE": "cubic spline", "POLY": "polynomial interpolation",
                           "CIP": "circle through an intermediate point",
                           "CT": "circle with tangential transition"}


def _m98(ip: _Interp, st: Stmt, col: int, p_word) -> None:
    """NGC ``M98 P<n>``: a Fanuc-style subprogram call, which the model does not run.

    LinuxCNC calls the subprogram ``O<n>`` of the same file (M98/M99) and refuses the
    block when there is none; either way the moves of the call would be missing here,
    so it is an error naming which of the two it is.
    """
    if p_word is None:
        raise ip.err(st, col, "M98 needs P (the number of the subprogram O<n> to call)")
    num = p_word[0]
    label = f"O{int(num)}" if num == int(num) else ""
    if label and any(s.label == label for s in ip.stmts):
        raise ip.err(st, col, f"M98 P{num:g}: Fanuc-style subprogram calls (M98/M99) are "
                              "not supported; write the subprogram as an O-word sub "
                              f"(o{int(num)} sub ... o{int(num)} endsub, o{int(num)} call)")
    raise ip.err(st, p_word[1], f"M98 P{num:g}: there is no subprogram O{num:g} in this "
                                "file")


def _check_range(ip: _Interp, st: Stmt, where: dict, axis_words, what: str,
                 col: int) -> None:
    """Every coordinate within :data:`MAX_COORDINATE_MM` (else an error at the word)."""
    for name, v in where.items():
        if not -MAX_COORDINATE_MM <= v <= MAX_COORDINATE_MM:
            c = next((w[3] for w in axis_words if w[0] == name),
                     axis_words[0][3] if axis_words else col)
            unit = "deg" if name in ROTARY else "mm"
            raise ip.err(st, c, f"{what} {name} = {v:g} {unit} is beyond "
                                f"+-{MAX_COORDINATE_MM:g} {unit}, farther than any machine "
                                "travels: check the number")


def _indexed_assignment(ip: _Interp, st: Stmt, w: Word) -> None:
    """SINUMERIK ``R[i]=v``, ``ATOL[axis]=v`` and ``NAME[i]=v``."""
    base, idx = w.name[:-1].split("[", 1)
    value = ip.ev(st, w.value, w.col)
    if base == "ATOL":
        ax = idx.strip()
        if value < 0:                          # a negative value deletes it
            ip.atol.pop(ax, None)
        else:
            ip.atol[ax] = value * ip.lin(ax)
        return
    try:
        node = parse_expr(Cursor(idx))
    except ExprError as exc:
        raise ip.err(st, w.col, str(exc)) from None
    i = int(ip.ev(st, node, w.col))
    ip.vars[f"R{i}" if base == "R" else f"{base}[{i}]"] = value


def _tangential(ip: _Interp, st: Stmt, name: str, args: str, col: int) -> None:
    parts = [a.strip().strip('"').upper() for a in args.split(",")] if args.strip() else []
    if not parts:
        raise ip.err(st, col, f"{name} needs the following axis, e.g. {name}(C)")
    axis = parts[0]
    if name == "TANG":
        if len(parts) < 3:
            raise ip.err(st, col, "TANG needs (following axis, leading axis 1, leading axis 2"
                                  "[, coupling])")
        coupling = _call_number(ip, st, parts[3], col, "TANG coupling") if (
            len(parts) > 3 and parts[3]) else 1.0
        ip.tang_defs[axis] = Tangential(axis=axis, leading=(parts[1], parts[2]),
                                        coupling=coupling)
        ip.add_axis(axis)
    elif name in ("TANGON", "TLIFT", "TANGOF", "TANGDEL"):
        if axis not in ip.tang_defs:
            raise ip.err(st, col, f"{name}({axis}) without a TANG({axis}, ...) definition")
        d = ip.tang_defs[axis]
        if name == "TANGON":
            off = _call_number(ip, st, parts[1], col, "TANGON angle") if (
                len(parts) > 1 and parts[1]) else 0.0
            ip.tang_defs[axis] = Tangential(d.axis, d.leading, d.coupling, off, d.tlift)
            ip.tang_active = axis
        elif name == "TLIFT":
            ip.tang_defs[axis] = Tangential(d.axis, d.leading, d.coupling, d.offset_deg, True)
        elif name == "TANGOF":
            if ip.tang_active == axis:
                ip.tang_active = None
        else:
            if ip.tang_active == axis:
                raise ip.err(st, col, f"TANGDEL({axis}) while tangential control is on; "
                                      "TANGOF first")
            del ip.tang_defs[axis]


def _call_number(ip: _Interp, st: Stmt, text: str, col: int, what: str) -> float:
    """A numeric argument of a call such as ``TANG(C, X, Y, R1*2)``: an expression."""
    try:
        cur = Cursor(text)
        node = parse_expr(cur)
        if cur.peek():
            raise ExprError(f"unexpected '{cur.peek()}'", cur.pos)
    except ExprError as exc:
        raise ip.err(st, col + 1, f"{what} '{text}': {exc}") from None
    val = ip.ev(st, node, col + 1)
    if not math.isfinite(val):
        raise ip.err(st, col + 1, f"{what} '{text}' is not a finite number")
    return val


def _tool_radius_assignment(ip: _Interp, st: Stmt, text: str, col: int) -> None:
    """SINUMERIK ``$TC_DP6[t, d] = r``: the radius of cutting edge ``d`` of tool ``t``.

    Tool data are in the control's basic system (metric assumed: mm, also under G70);
    a negative radius is kept (it moves the tool to the other side, as on the control).
    A calculation in block preparation: it adds no stop to the path.
    """
    head, eq, value = text.partition("=")
    lb, rb = head.find("["), head.rfind("]")
    if not eq or lb < 0 or rb < lb or head[rb + 1:].strip():
        raise ip.err(st, col + 1, f"'{text}': expected $TC_DP6[tool, edge] = radius")
    index = [a for a in head[lb + 1:rb].split(",")]
    if len(index) != 2:
        raise ip.err(st, col + 1, f"'{text}': $TC_DP6 needs two indices [tool, edge]")
    tool, edge = (_call_number(ip, st, a.strip(), col, "$TC_DP6 index") for a in index)
    if tool != int(tool) or edge != int(edge) or tool < 0 or edge < 1:
        raise ip.err(st, col + 1, f"'{text}': tool and edge must be whole numbers, tool >= 0 "
                                  "and edge >= 1")
    radius = _call_number(ip, st, value.strip(), col, "$TC_DP6 value")
    if not abs(radius) <= MAX_COORDINATE_MM:
        raise ip.err(st, col + 1, f"'{text}': a tool radius of {radius:g} mm is not a tool")
    ip.tool_data[(int(tool), int(edge))] = radius


def _ngc_comp_tool(ip: _Interp, st: Stmt, gi: float, d_word, col: int) -> None:
    """NGC G40/G41/G42/G41.1/G42.1: where the compensation radius comes from (LinuxCNC
    ``convert_cutter_compensation_on``): G41/G42 ``D<tool>`` names a tool of the tool
    table (default: the current tool), G41.1/G42.1 ``D<diameter>`` gives the diameter."""
    ip.ngc_comp_tool = None
    ip.ngc_comp_radius = None
    if gi == 40:
        return
    if gi in (41.1, 42.1):
        if d_word is None:
            raise ip.err(st, col, f"G{gi:g} with no D word (D is the tool diameter)")
        ip.ngc_comp_radius = d_word[0] * ip.lin("X") / 2.0
        return
    if d_word is not None:
        if d_word[0] != int(d_word[0]) or d_word[0] < 0:
            raise ip.err(st, d_word[1], f"G{gi:g} D{d_word[0]:g}: D must be a whole tool "
                                        "number >= 0")
        ip.ngc_comp_tool = int(d_word[0])


def _trc_tool(ip: _Interp) -> tuple:
    """``(trc_tool, tool_radius_mm)`` of the modal state (see :class:`Modal`)."""
    if ip.ngc:
        if ip.ngc_comp_radius is not None:
            return None, ip.ngc_comp_radius
        tool = ip.ngc_comp_tool if ip.ngc_comp_tool is not None else ip.tool
        if tool is None:
            return None, None
        return (tool, 1), ip.tool_data.get((tool, 1))
    if ip.tool is None and ip.offset_no is None:
        return None, None
    key = (ip.tool, ip.edge)
    if ip.edge == 0:
        return key, 0.0                       # D0: no tool offset
    return key, ip.tool_data.get(key)

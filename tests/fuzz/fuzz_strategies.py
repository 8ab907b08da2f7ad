"""Hypothesis strategies of the fuzz suite: NC programs in both dialects, machine files.

Programs are small (1 to ~30 blocks, loops of at most 3 passes) so that ``compare``, which
runs the oracle, stays fast per example. Most blocks are well-formed, so that examples get
past the parser into the path, the planner and the oracle; arcs are made consistent by
construction (the end point on the circle about the centre, or a radius at least half the
chord), with an occasional deliberately inconsistent one. Numbers are mostly plausible,
sometimes extreme (0, 1e-9, 1e7, 400 digits, negative feeds), and a block may be replaced
by a hostile word (:data:`HOSTILE_SIN`, :data:`HOSTILE_NGC`).

Machine files are TOML text built from the bundled default machine with a few edits: a
key set to a value across and beyond its plausible range (including 1e-300, inf, nan,
negative), a value of the wrong type, an unknown key, a deleted key or section, a strange
axis name; now and then the text itself is broken (truncated, not UTF-8, UTF-16).
"""

from __future__ import annotations

import json
import math
import tomllib
from importlib import resources

from hypothesis import strategies as st

# -- numbers -----------------------------------------------------------------------------


def fmt(x: float) -> str:
    """A number as NC text: fixed point, no exponent (``1e-05`` is not G-code)."""
    if x == int(x) and abs(x) < 1e15:
        return str(int(x))
    return f"{x:.6f}".rstrip("0").rstrip(".")


#: Plausible coordinates (mm), a 3-decimal grid as CAM output has.
_coord_plain = st.integers(-200_000, 200_000).map(lambda k: k / 1000.0)
#: Extreme coordinates: tiny, huge, exactly representable oddities.
_coord_extreme = st.sampled_from([0.0, 1e-6, -1e-6, 0.0005, 12345.678, -99999.999, 1e6])
coords = _coord_plain.map(fmt)
wild_coords = st.one_of(_coord_plain, _coord_plain, _coord_plain, _coord_extreme).map(fmt)

#: Feeds, mm/min: plausible mostly; 0 and negative are errors at the line; tiny and huge
#: are legal but extreme (the planner must cap at the axis limits).
feeds = st.integers(10, 20_000).map(str)
wild_feeds = st.one_of(feeds, feeds, feeds, st.sampled_from(
    ["0", "-100", "0.001", "1", "999999", "1000000000", "1.5", "0.0"]))

#: Values that stress the number scanner.
HUGE_WORDS = ["9" * 400, "123456789012345678901234567890", "1e308", "0.000000000001",
              ".5", "5.", "-.5", "+3", "1.2.3", "--1"]

# -- hostile words: one replaces a block now and then -----------------------------------

#: SINUMERIK words and blocks a user (or a broken file) may write; each must end in a
#: clean result or a clean error at its line. The 500-deep nesting is the recursion limit
#: probe of issue 9.
HOSTILE_SIN = [
    "X1e308", "F0", "G2 X1 I0 J0", "G1 X5 F0", "X" + "9" * 400, "X=" + "(" * 500 + "1"
    + ")" * 500, "G1 X123456789012345678901234567890", "BSPLINE X10 Y5", "R1=1/0",
    "X=R999999", "X=SQRT(-1)", "X=LN(0)", "G3 CR=0 X1", "G2 X10 Y0 CR=1", "G4 F-1", "G4",
    "T=\"DRILL 8.5\"", "POS[A]=90", "ROT Y-90", "ROT", "TRANS X1e9", "SCALE X0",
    "N99999999999999999999", "GOTOB NOWHERE", "GOTOF NOWHERE", "ENDWHILE", "ENDIF", "ELSE",
    "WHILE", "IF", "DEF REAL", "DEF REAL A=", "R1=", "=5", "X=", "G", "G999", "M98 P1000",
    "X#99999", "\t", "\x00", "\x7f", "ÄÖÜ", "\u202eX1", "X1 X2", "G0 G1 G2 X1",
    "G17 G18 G19", "G1 A=360000 F100", "S1e400", "F=1/3", "X=1E400", "X=1EX400",
    "X=1EX-400", "X=2EX307*10", "CIP X1 Y1 I1=0 J1=0", "G1 X1 ;" + "x" * 5000,
    "G2 X0 Y0 Z10 I5 J0 TURN=999999",
]
#: LinuxCNC words and blocks, the same idea.
HOSTILE_NGC = [
    "X1e308", "F0", "G2 X1 I0 J0", "G1 X5 F0", "X" + "9" * 400, "X" + "[" * 500 + "1"
    + "]" * 500, "G1 X123456789012345678901234567890", "#1=[1/0]", "G1 X#99999",
    "G1 X[SQRT[-1]]", "G1 X[LN[0]]", "G1 X[1/0]", "G2 X10 Y0 R0", "G2 X10 Y0 R1", "G4 P-1",
    "G4", "G64 P-1", "G64 Q-1", "M98 P1000", "o100 endwhile", "o100 endif", "o100 else",
    "o100 while", "o100 call", "o<nowhere> call", "#=5", "#1=", "X#", "G", "G999", "G1 G2",
    "(unclosed comment", ")", "\t", "\x00", "\x7f", "ÄÖÜ", "N99999999999999999999",
    "X1 X2", "G17 G18", "G1 A360000 F100", "S1e400", "G1 X1 (" + "x" * 5000 + ")",
    "G92 X1e9", "G10 L2 P1 X1e9", "G20 G1 X1000000", "G2 X0 Y0 Z10 I5 J0 P1000000",
]

#: Tool radius compensation and tangential control statements.
TRC_SIN = ["$TC_DP6[1,1]=2\nT1 D1", "$TC_DP6[1,1]=-1.5\nT1 D1", "T1 D1", "G41", "G42",
           "G40", "G450", "G451", "G450 DISC=30", "G41 G1 X5 Y5", "G40 G1 X0 Y0", "D0",
           "$TC_DP6[2,1]=0.5\nT2", "G42 G0 X-10 Y-10"]
TRC_NGC = ["G10 L1 P1 R2\nT1 M6", "G41", "G42", "G40", "G41.1 D4", "G42.1 D3",
           "G40 G1 X0 Y0", "G41 D1 G1 X-10 Y-10", "G42.1 D0.5 G0 X5 Y-5"]
TANG_SIN = ["TANG(C, X, Y, 1)\nTANGON(C, 0)", "TANG(C, X, Y, 2)\nTANGON(C, 45)\nTLIFT(C)",
            "TLIFT(C)", "TANGOF(C)", "TANGON(C, 90)"]

# -- programs ----------------------------------------------------------------------------

_PLANES = {"G17": ("X", "Y", "I", "J", "Z", "K"), "G18": ("Z", "X", "K", "I", "Y", "J"),
           "G19": ("Y", "Z", "J", "K", "X", "I")}


@st.composite
def _arc(draw, dialect: str, plane: str, absolute: bool, pos: dict | None, wild: bool):
    """One arc block (G2/G3) in the current plane, consistent unless drawn otherwise.

    Returns the block text and the new position (``None`` when it cannot be tracked).
    """
    a1, a2, ci, cj, ax3, ck = _PLANES[plane]
    g = draw(st.sampled_from(["G2", "G3"]))
    kind = draw(st.sampled_from(["centre", "centre", "radius", "full"]
                                + (["broken"] if wild else [])))
    r = draw(st.integers(1, 50_000)) / 1000.0                     # 0.001 .. 50 mm
    phi0 = draw(st.integers(0, 359)) * math.pi / 180.0            # start angle about c
    sweep = draw(st.integers(1, 359)) * math.pi / 180.0
    # centre offset from the start point, and the end point's offset from the start
    ci_v, cj_v = -r * math.cos(phi0), -r * math.sin(phi0)
    d1 = ci_v + r * math.cos(phi0 + sweep)
    d2 = cj_v + r * math.sin(phi0 + sweep)
    words = [g]
    helix = draw(st.sampled_from([None, None, None, 0.5, -2.0]))
    if kind == "full":
        d1 = d2 = 0.0
    if kind == "radius":
        chord = math.hypot(d1, d2)
        rad = max(chord / 2.0 * draw(st.sampled_from([1.0, 1.01, 1.5, 4.0])), 0.001)
        rad_s = fmt(round(rad + 0.0005, 3))                    # never below half the chord
        if draw(st.booleans()):
            rad_s = "-" + rad_s                                 # the long way round
        words.append(f"CR={rad_s}" if dialect == "sin" else f"R{rad_s}")
    elif kind == "broken":
        words += [f"{c}{draw(st.integers(-9, 9))}" for c in (ci, cj)]
    else:
        words += [f"{ci}{fmt(round(ci_v, 6))}", f"{cj}{fmt(round(cj_v, 6))}"]
    new_pos, restore = None, []
    if kind == "full" and helix is None:
        new_pos = pos                                           # no end point: back home
    elif absolute and pos is not None:
        e1, e2 = pos[a1] + d1, pos[a2] + d2
        words[1:1] = [f"{a1}{fmt(round(e1, 6))}", f"{a2}{fmt(round(e2, 6))}"]
        new_pos = dict(pos, **{a1: round(e1, 6), a2: round(e2, 6)})
    elif not absolute:
        words[1:1] = [f"{a1}{fmt(round(d1, 6))}", f"{a2}{fmt(round(d2, 6))}"]
        new_pos = None if pos is None else dict(
            pos, **{a1: pos[a1] + round(d1, 6), a2: pos[a2] + round(d2, 6)})
    else:
        # absolute with an unknown position: an incremental arc in a block of its own
        words[1:1] = [f"{a1}{fmt(round(d1, 6))}", f"{a2}{fmt(round(d2, 6))}"]
        words.insert(0, "G91")
        restore = ["G90"]
    if helix is not None:
        words.insert(3, f"{ax3}{fmt(helix)}")
        new_pos = None
        turns = draw(st.sampled_from([None, 1, 2]))
        if turns is not None:
            words.append(f"TURN={turns}" if dialect == "sin" else f"P{turns + 1}")
    if draw(st.integers(0, 3)) == 0:
        words.append(f"F{draw(wild_feeds if wild else feeds)}")
    return "\n".join([" ".join(words)] + restore), new_pos


@st.composite
def _line(draw, dialect: str, state: dict) -> str:
    """One linear block (G0/G1) with 1-3 axis words; updates the tracked position."""
    g = draw(st.sampled_from(["G1", "G1", "G1", "G0", ""]))
    axes = draw(st.lists(st.sampled_from(["X", "Y", "Z"]), min_size=1, max_size=3,
                         unique=True))
    words = [g] if g else []
    pos = state["pos"]
    for ax in axes:
        v = draw(wild_coords if state["wild"] else coords)
        words.append(f"{ax}{v}" if dialect == "ngc" or draw(st.integers(0, 4)) else
                     f"{ax}={v}")
        if pos is not None:
            pos = dict(pos, **{ax: float(v) if state["absolute"] else pos[ax] + float(v)})
    state["pos"] = pos
    if draw(st.integers(0, 2)) == 0:
        words.append(f"F{draw(wild_feeds if state['wild'] else feeds)}")
    return " ".join(words)


_SIN_OPS = ["+", "-", "*", "/"]
_NGC_OPS = ["+", "-", "*", "/", "MOD"]


@st.composite
def _expr(draw, dialect: str, params: list[str], depth: int = 0) -> str:
    """An arithmetic expression over numbers, defined parameters and functions."""
    leaf = st.one_of(st.integers(-100, 100).map(str),
                     st.integers(1, 9999).map(lambda k: fmt(k / 100.0)),
                     *([st.sampled_from(params)] if params else []))
    if depth >= 2 or draw(st.integers(0, 2)) == 0:
        return draw(leaf)
    a = draw(_expr(dialect, params, depth + 1))
    b = draw(_expr(dialect, params, depth + 1))
    op = draw(st.sampled_from(_SIN_OPS if dialect == "sin" else _NGC_OPS))
    form = draw(st.integers(0, 3))
    if dialect == "sin":
        if form == 0:
            return f"SIN({a})" if draw(st.booleans()) else f"ABS({a})"
        return f"({a}{op}{b})"
    if form == 0:
        return f"SIN[{a}]" if draw(st.booleans()) else f"ABS[{a}]"
    return f"[{a} {op} {b}]"


@st.composite
def _statement(draw, dialect: str, state: dict, depth: int) -> list[str]:
    """One statement: a motion, a mode, a dwell, a comment, an assignment, a bounded loop,
    an IF, or a hostile word. Returns its lines."""
    sin = dialect == "sin"
    kind = draw(st.sampled_from(
        ["line"] * 6 + ["arc"] * 4 + ["feed", "mode", "plane", "dwell", "comment", "assign",
                                       "assign_move", "loop", "if", "hostile", "trc",
                                       "tang"]))
    if kind == "line":
        return [draw(_line(dialect, state))]
    if kind == "arc":
        text, state["pos"] = draw(_arc(dialect, state["plane"], state["absolute"],
                                       state["pos"], state["wild"]))
        return text.split("\n")
    if kind == "feed":
        return [f"F{draw(wild_feeds if state['wild'] else feeds)}"]
    if kind == "mode":
        # a mode inside a loop or IF body may not run: G90/G91 only at the top level,
        # where the generator can track it
        top = ["G90", "G91"] if depth == 0 else []
        word = draw(st.sampled_from(
            top + ["G64", "G60", "G9 G1 X1", "G641 ADIS=0.1", "G601", "G602"] if sin else
            top + ["G64", "G64 P0.01", "G64 P0.05 Q0.01", "G61", "G61.1", "G90.1", "G91.1"]))
        if word in ("G90", "G91"):
            state["absolute"] = word == "G90"
        if word.startswith("G9 "):
            state["pos"] = None
        if word in ("G90.1",):
            # absolute arc centres: the generator writes incremental centres
            return ["G91.1"]
        return [word]
    if kind == "plane":
        plane = draw(st.sampled_from(list(_PLANES)))
        state["plane"] = plane
        return [plane]
    if kind == "dwell":
        t = draw(st.sampled_from(["0.1", "0", "0.5", "2", "0.001"]))
        return [f"G4 F{t}" if sin else f"G4 P{t}"]
    if kind == "comment":
        text = draw(st.text(st.characters(min_codepoint=32, max_codepoint=0x2FF,
                                          exclude_characters="()\n\r;"), max_size=30))
        return [f"; {text}" if sin or draw(st.booleans()) else f"({text})"]
    if kind in ("assign", "assign_move"):
        n = draw(st.integers(1, 20))
        name = f"R{n}" if sin else f"#{n}"
        lines = [f"{name}={draw(_expr(dialect, state['params']))}"]
        if name not in state["params"]:
            state["params"].append(name)
        if kind == "assign_move":
            ax = draw(st.sampled_from(["X", "Y", "Z"]))
            lines.append(f"G1 {ax}={name}" if sin else f"G1 {ax}{name}")
            state["pos"] = None
        return lines
    if kind == "trc":
        # tool radius compensation: tool data, G41/G42/G40, corner modes; random
        # contours often make the tool not fit (the collision alarm: exit 2 naming the
        # line), which is what is under test besides the compensated path itself
        word = draw(st.sampled_from(TRC_SIN if sin else TRC_NGC))
        if " X" in word:
            state["pos"] = None
        return word.split("\n")
    if kind == "tang" and sin:
        return draw(st.sampled_from(TANG_SIN)).split("\n")
    if kind == "loop" and depth < 2:
        return draw(_loop(dialect, state, depth))
    if kind == "if" and depth < 2:
        return draw(_if(dialect, state, depth))
    if kind == "hostile" and state["wild"]:
        state["pos"] = None
        return [draw(st.sampled_from(HOSTILE_SIN if sin else HOSTILE_NGC))]
    return [draw(_line(dialect, state))]


@st.composite
def _body(draw, dialect: str, state: dict, depth: int, max_statements: int) -> list[str]:
    n = draw(st.integers(1, max_statements))
    lines: list[str] = []
    for _ in range(n):
        lines += draw(_statement(dialect, state, depth))
    return lines


@st.composite
def _loop(draw, dialect: str, state: dict, depth: int) -> list[str]:
    """A loop of 1-3 passes over 1-3 statements: WHILE (SIN) or o-word while (NGC)."""
    passes = draw(st.integers(1, 3))
    k = 50 + depth
    state["pos"] = None                  # the position after the loop is not tracked
    body = draw(_body(dialect, state, depth + 1, 3))
    state["pos"] = None
    if dialect == "sin":
        return ([f"R{k}=0", f"WHILE R{k}<{passes}"] + body
                + [f"R{k}=R{k}+1", "ENDWHILE"])
    o = 100 + depth
    return ([f"#{k}=0", f"o{o} while [#{k} LT {passes}]"] + body
            + [f"#{k}=[#{k}+1]", f"o{o} endwhile"])


@st.composite
def _if(draw, dialect: str, state: dict, depth: int) -> list[str]:
    """IF ... ELSE ... ENDIF on a comparison of numbers or parameters."""
    a = draw(_expr(dialect, state["params"]))
    op = draw(st.sampled_from(["<", ">", "==", "<>"] if dialect == "sin"
                              else ["LT", "GT", "EQ", "NE"]))
    state["pos"] = None
    then = draw(_body(dialect, state, depth + 1, 2))
    other = draw(_body(dialect, state, depth + 1, 2)) if draw(st.booleans()) else []
    state["pos"] = None
    if dialect == "sin":
        return ([f"IF {a}{op}5"] + then + (["ELSE"] + other if other else []) + ["ENDIF"])
    o = 200 + depth
    return ([f"o{o} if [{a} {op} 5]"] + then + ([f"o{o} else"] + other if other else [])
            + [f"o{o} endif"])


@st.composite
def programs(draw, dialect: str) -> str:
    """A whole small program (``dialect`` "sin" or "ngc") as text."""
    sin = dialect == "sin"
    # one program in three is wild: extreme numbers, hostile words, broken arcs; the
    # others are well-formed, to reach the planner and the oracle with random geometry
    state = {"pos": {"X": 0.0, "Y": 0.0, "Z": 0.0}, "absolute": True, "plane": "G17",
             "params": [], "wild": draw(st.integers(0, 2)) == 0}
    head = ["G90 G17"] if draw(st.integers(0, 4)) else []
    lines = head + [f"G1 X0 Y0 Z0 F{draw(feeds)}"] if draw(st.integers(0, 7)) else head
    if not lines or not lines[-1].startswith("G1 X0"):
        state["pos"] = None
    n = draw(st.integers(1, 14))
    for _ in range(n):
        lines += draw(_statement(dialect, state, 0))
    if draw(st.integers(0, 3)):
        lines.append("M30" if sin else "M2")
    numbered = draw(st.integers(0, 3)) == 0
    if numbered:
        lines = [f"N{10 * (i + 1)} {ln}" if ln and not ln.startswith((";", "(", "o"))
                 else ln for i, ln in enumerate(lines)]
    eol = draw(st.sampled_from(["\n", "\n", "\n", "\r\n"]))
    return eol.join(lines) + (eol if draw(st.integers(0, 5)) else "")


# -- machine files -----------------------------------------------------------------------


def default_machine() -> dict:
    """The bundled default machine as a TOML dict (the base of every edit)."""
    text = resources.files("reference.machines").joinpath("default.toml").read_text()
    return tomllib.loads(text)


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if v != v:
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {_toml_value(x)}"
                               for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_text(data: dict) -> str:
    """A machine dict as TOML (sections ``[machine]``, ``[channel]``, ``[axis.NAME]``)."""
    out: list[str] = []
    for sec, tbl in data.items():
        if sec == "axis" and isinstance(tbl, dict):
            for ax, keys in tbl.items():
                if isinstance(keys, dict):
                    out.append(f"[axis.{json.dumps(ax)}]")
                    out += [f"{json.dumps(k)} = {_toml_value(v)}" for k, v in keys.items()]
                else:
                    out.append(f"[axis]\n{json.dumps(ax)} = {_toml_value(keys)}")
        elif isinstance(tbl, dict):
            out.append(f"[{json.dumps(sec)}]")
            out += [f"{json.dumps(k)} = {_toml_value(v)}" for k, v in tbl.items()]
        else:
            out.insert(0, f"{json.dumps(sec)} = {_toml_value(tbl)}")
    return "\n".join(out) + "\n"


#: Numbers across and beyond every key's plausible range (the ranges reach from 1e-6 to
#: 1e7): zero, negative, denormal-small, huge, non-finite.
_numbers = st.one_of(
    st.floats(min_value=1e-3, max_value=1e4),
    st.sampled_from([0, 0.0, -1, -1e-9, 1e-300, 5e-324, 1e-12, 1e-6, 1e-4, 1e-3, 0.01,
                     0.5, 1, 1.0, 2, 10, 99.999, 100, 1000, 1e5, 1e7, 1e9, 1e300,
                     float("inf"), float("-inf"), float("nan")]),
    st.integers(-10, 10**6))
_wrong_types = st.sampled_from(["fast", "", True, False, [1.0, 2.0], [], {"a": 1},
                                "2.0", "1e3", [True], ["SOFT"]])
_names = st.one_of(st.sampled_from(["X", "Y", "Z", "A", "B", "C", "U", "E", "ELX", "x", "",
                                    " ", "X Y", "Ä", "<b>", "1", "axis"]),
                   st.text(max_size=6))


@st.composite
def machine_texts(draw) -> bytes:
    """Machine-data file contents: the default machine with 1-4 edits, as bytes."""
    data = default_machine()
    # one machine in three only rescales numbers by up to 10x either way (plausible data
    # that loads, so that plan and compare run on it); the others break rules
    plausible = draw(st.integers(0, 2)) == 0
    for _ in range(draw(st.integers(1, 4))):
        edit = "scale" if plausible else draw(st.sampled_from(
            ["value", "value", "value", "type", "unknown", "delete", "axis", "section",
             "adapt", "mode", "scale"]))
        axes = data.get("axis")
        sections = [("machine", data.get("machine")), ("channel", data.get("channel"))] + [
            (f"axis.{ax}", t) for ax, t in (axes.items() if isinstance(axes, dict) else ())]
        sections = [(n, t) for n, t in sections if isinstance(t, dict)]
        if not sections:
            break
        name, tbl = draw(st.sampled_from(sections))
        keys = sorted(tbl) or ["MAX_AX_VELO"]
        key = draw(st.sampled_from(keys))
        if edit == "scale":
            old = tbl.get(key)
            if isinstance(old, (int, float)) and not isinstance(old, bool):
                tbl[key] = old * draw(st.sampled_from([0.1, 0.3, 0.5, 0.9, 1.1, 2.0, 3.0,
                                                       10.0]))
        elif edit == "value":
            tbl[key] = draw(_numbers)
        elif edit == "type":
            tbl[key] = draw(_wrong_types)
        elif edit == "unknown":
            tbl[draw(st.sampled_from(["MAX_AX_ACC", "max_ax_velo", "FOO", "ipo_cycle",
                                      "LOOKAHEAD", "Name"]))] = draw(_numbers)
        elif edit == "delete":
            tbl.pop(key, None)
        elif edit == "axis" and isinstance(data.get("axis", {}), dict):
            axes = data.setdefault("axis", {})
            new = draw(_names)
            axes[new] = dict(axes.get("X", {"MAX_AX_VELO": 1000.0}))
            if draw(st.booleans()) and len(axes) > 1:
                axes.pop(draw(st.sampled_from(sorted(axes))))
        elif edit == "section":
            which = draw(st.sampled_from(["machine", "channel", "axis", "spindle"]))
            if which in data and draw(st.booleans()):
                data.pop(which)
            else:
                data[which] = draw(st.one_of(_numbers, _wrong_types))
        elif edit in ("adapt", "mode") and not isinstance(data.get("channel", {}), dict):
            continue
        elif edit == "adapt":
            data.setdefault("channel", {})["ADAPT_PATH_DYNAMIC"] = draw(st.lists(
                _numbers, max_size=3))
        else:
            data.setdefault("channel", {})["acceleration_mode"] = draw(st.sampled_from(
                ["BRISK", "SOFT", "brisk", "", "JERK"]))
    raw = toml_text(data).encode("utf-8")
    damage = draw(st.sampled_from(["none"] * 6 + ["truncate", "latin1", "utf16", "bom",
                                                  "garbage", "nul"]))
    if damage == "truncate":
        raw = raw[:draw(st.integers(0, len(raw)))]
    elif damage == "latin1":
        raw = raw.replace(b"# ", b"# \xe4\xf6\xfc ") + b"# Stra\xdfe\n"
    elif damage == "utf16":
        raw = raw.decode("utf-8").encode("utf-16")
    elif damage == "bom":
        raw = b"\xef\xbb\xbf" + raw
    elif damage == "garbage":
        at = draw(st.integers(0, len(raw)))
        raw = raw[:at] + draw(st.binary(min_size=1, max_size=8)) + raw[at:]
    elif damage == "nul":
        raw = raw + b"\x00"
    return raw

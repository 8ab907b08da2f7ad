"""The fast lane: plain ``G0/G1/G2/G3`` lines of X/Y/Z/I/J/K/F/S/M words (NGC also R)
with no frame active, the bulk of CAM output, turned into blocks without per-word objects.

:func:`_fast_block` produces exactly the blocks of the full treatment
(:func:`reference.nc.block._block`); it declines any line it does not handle (returns
False, changing nothing), so every error message comes from the full treatment.
"""

from __future__ import annotations

from ..core.units import MM_PER_INCH
from .arcs import _fast_arc_centre
from .lines import Stmt
from .program import NO_EXTRA, Block, BlockExtra
from .state import _END_M, _PLANE_AXES, MAX_COORDINATE_MM, MAX_FEED_MM_MIN, _Interp

_INF = float("inf")
_MAX_F = MAX_FEED_MM_MIN / MM_PER_INCH     # in either unit: the full path checks exactly


def _fast_block(ip: _Interp, st: Stmt, fast: list[tuple[str, str]]) -> bool:
    """Plain G0/G1/G2/G3 line of X/Y/Z/I/J/K/F/S/M words (NGC also R) with no frame
    active: the bulk of CAM output.

    Reuses the current :class:`Modal` object and the previous end tuple, and builds no
    per-word objects. Returns False (changing nothing) whenever the line needs the full
    treatment, which also produces every error message.
    """
    frame = ip.frame
    if frame.theta_deg != 0.0 or frame.offset or frame.tilt is not None:
        return False
    motion = ip.motion
    x = y = z = f = g = ci = cj = ck = r = spindle = None
    aux = None
    for letter, text in fast:
        if letter == "X":
            if x is not None:
                return False
            x = float(text)
        elif letter == "Y":
            if y is not None:
                return False
            y = float(text)
        elif letter == "Z":
            if z is not None:
                return False
            z = float(text)
        elif letter == "G":
            if g is not None:
                return False
            g = float(text)
            if g == 1.0:
                motion = "G1"
            elif g == 0.0:
                motion = "G0"
            elif g == 2.0:
                motion = "G2"
            elif g == 3.0:
                motion = "G3"
            else:
                return False
        elif letter == "F":
            if f is not None:
                return False
            f = float(text)
            if not 0.0 < f < _MAX_F:           # F0, too large: the full path says why
                return False
        elif letter == "I":
            if ci is not None:
                return False
            ci = float(text)
        elif letter == "J":
            if cj is not None:
                return False
            cj = float(text)
        elif letter == "K":
            if ck is not None:
                return False
            ck = float(text)
        elif letter == "R" and ip.ngc:
            if r is not None:
                return False
            r = float(text)
        elif letter == "M":
            m = float(text)
            if m in _END_M or abs(m) == _INF:  # program end or overflow: the full path
                return False
            if aux is None:
                aux = []
            aux.append(("M", m))
        elif letter == "S":
            if spindle is not None:
                return False
            spindle = float(text)
            if abs(spindle) == _INF:           # overflow: the full path says why
                return False
            if aux is None:
                aux = []
            aux.append(("S", spindle))
        else:
            return False
    feed = ip.feed
    if f is not None:
        feed = f * (MM_PER_INCH if ip.feed_inch else 1.0) / 60.0
    arc = motion == "G2" or motion == "G3"
    if arc:
        if ci is None and cj is None and ck is None and r is None:
            return False
        if x is None and y is None and z is None and g is None:
            return False                       # no axis and no G word: not a move
    elif (x is None and y is None and z is None) or ci is not None or cj is not None or (
            ck is not None or r is not None or (motion != "G1" and motion != "G0")):
        return False
    if not feed and motion != "G0":            # no feed or F0: the full path says why
        return False
    pos = ip.pos
    k = MM_PER_INCH if ip.inch else 1.0
    ex = pos["X"] if x is None else (x * k if ip.absolute else pos["X"] + x * k)
    ey = pos["Y"] if y is None else (y * k if ip.absolute else pos["Y"] + y * k)
    ez = pos["Z"] if z is None else (z * k if ip.absolute else pos["Z"] + z * k)
    lim = MAX_COORDINATE_MM
    if not (-lim <= ex <= lim and -lim <= ey <= lim and -lim <= ez <= lim):
        return False                           # out of range (or NaN): the full path says why
    if arc:
        centre = _fast_arc_centre(ip, motion == "G2", ex, ey, ez, ci, cj, ck, r, k)
        if centre is None or not (-lim <= centre[0] <= lim and -lim <= centre[1] <= lim):
            return False
    ip.feed = feed
    ip.motion = motion
    if spindle is not None and spindle > 0:
        ip.spindle_rpm = spindle
    start = ip.last_end
    if start is None:
        start = tuple([pos[a] for a in ip.axes])
    pos["X"], pos["Y"], pos["Z"] = ex, ey, ez
    axes = ip.axes
    if len(axes) == 3:
        end = (pos["X"], pos["Y"], pos["Z"])
    else:
        end = tuple([pos[a] for a in axes])
    ip.last_end = end
    if arc or aux is not None or st.comment:
        center = None
        if arc:
            cu, cv = centre
            u, v, _ = _PLANE_AXES[ip.plane]
            c = list(start)
            c[axes.index(u)] = cu
            c[axes.index(v)] = cv
            center = tuple(c)
        up = st.text.upper()
        col = up.find("G", up.find(":") + 1) + 1 if g is not None else 1
        extra = BlockExtra(center=center, aux=() if aux is None else tuple(aux),
                           comment=st.comment, column_of_motion=col)
    else:
        extra = NO_EXTRA
    out = ip.out
    out.append(Block(len(out), st.line, st.text, st.label, motion, start, end, feed,
                     ip.mode10 == "G60", ip.modal, extra))
    return True

"""Arcs: the centre of a G2/G3 block from its centre words (I/J/K) or its radius
(``CR=``, NGC ``R``), checked against the start and end point, plus the plane basis and
the extra turns.

:func:`_arc` serves the full treatment of a line (:mod:`reference.nc.block`) and reports
every error; :func:`_fast_arc_centre` applies the same rules in the fast lane
(:mod:`reference.nc.fastlane`) and returns None where the full treatment must speak.
Units: mm.
"""

from __future__ import annotations

import math

from ..core.tolerances import ARC_RADIUS_REL_TOL, ARC_RADIUS_TOL_MM, POS_TOL_MM
from .lines import Stmt
from .state import _CENTER_WORD, _PLANE_AXES, _Interp


def _fast_arc_centre(ip: _Interp, cw: bool, ex: float, ey: float, ez: float, ci, cj, ck, r,
                     k: float) -> tuple[float, float] | None:
    """Plane coordinates of the centre of a fast-lane arc, or None to take the full path
    (which then reports what is wrong). Same rules as :func:`_arc`."""
    u, v, _ = _PLANE_AXES[ip.plane]
    pos = ip.pos
    su, sv = pos[u], pos[v]
    end = {"X": ex, "Y": ey, "Z": ez}
    eu, ev = end[u], end[v]
    if r is not None:
        if ci is not None or cj is not None or ck is not None:
            return None
        r *= k
        chord = math.hypot(eu - su, ev - sv)
        if chord <= POS_TOL_MM or abs(r) <= POS_TOL_MM or chord / 2 > abs(r) + ARC_RADIUS_TOL_MM:
            return None
        return _radius_centre(su, sv, eu, ev, r, cw)
    words = {"X": ci, "Y": cj, "Z": ck}
    wu, wv = words[u], words[v]
    if ip.ngc and ip.ijk_absolute:
        cu = 0.0 if wu is None else wu * k
        cv = 0.0 if wv is None else wv * k
    else:
        cu = su if wu is None else su + wu * k
        cv = sv if wv is None else sv + wv * k
    r0 = math.hypot(su - cu, sv - cv)
    r1 = math.hypot(eu - cu, ev - cv)
    if r0 <= POS_TOL_MM or abs(r1 - r0) > max(ARC_RADIUS_TOL_MM, ARC_RADIUS_REL_TOL * r0):
        return None
    return cu, cv


def _radius_centre(su: float, sv: float, eu: float, ev: float, r: float,
                   cw: bool) -> tuple[float, float]:
    """Centre of the arc of signed radius ``r`` (negative: more than 180 degrees) from
    (su, sv) to (eu, ev), clockwise for G2; the chord must be in reach (checked before)."""
    du, dv = eu - su, ev - sv
    chord = math.hypot(du, dv)
    half = chord / 2
    h = math.sqrt(max(r * r - half * half, 0.0))
    nu, nv = -dv / chord, du / chord             # left normal of the chord
    side = (1.0 if not cw else -1.0) * (1.0 if r > 0 else -1.0)
    return su + du / 2 + side * h * nu, sv + dv / 2 + side * h * nv


def _arc(ip: _Interp, st: Stmt, motion: str, prog: dict, target: dict, centre: dict,
         named: dict, r_word, p_word, col: int):
    """Centre (machine coordinates), plane basis and extra turns of one arc."""
    u, v, w = _PLANE_AXES[ip.plane]
    su, sv = prog.get(u, 0.0), prog.get(v, 0.0)
    eu, ev = target.get(u, 0.0), target.get(v, 0.0)
    radius_word = named.get("CR") if not ip.ngc else r_word
    cw = motion == "G2"
    if radius_word is None and not centre:
        raise ip.err(st, col, f"{motion} needs a centre ({_CENTER_WORD[u]}, {_CENTER_WORD[v]})"
                              f" or a radius ({'R' if ip.ngc else 'CR='})")
    if radius_word is not None and not centre:
        r, rcol = radius_word
        r *= ip.lin(u)
        du, dv = eu - su, ev - sv
        chord = math.hypot(du, dv)
        if chord <= POS_TOL_MM:
            raise ip.err(st, rcol, "a full circle cannot be programmed with a radius; "
                                   "use the centre (I, J, K)")
        if abs(r) <= POS_TOL_MM:
            raise ip.err(st, rcol, "arc radius is zero")
        half = chord / 2
        if half > abs(r) + ARC_RADIUS_TOL_MM:
            raise ip.err(st, rcol, f"arc radius {abs(r):.6g} mm cannot reach the end point: "
                                   f"the chord is {chord:.6g} mm, so the radius must be at "
                                   f"least {half:.6g} mm ({half - abs(r):.3g} mm more)")
        cu, cv = _radius_centre(su, sv, eu, ev, r, cw)
    else:
        def off(ax: str, s_val: float) -> float:
            key = _CENTER_WORD[ax]
            if key not in centre:
                return s_val if not (ip.ngc and ip.ijk_absolute) else 0.0
            val, mode, _ = centre[key]
            val *= ip.lin(ax)
            absolute = mode == "AC" or (ip.ngc and ip.ijk_absolute)
            return val if absolute else s_val + val
        cu, cv = off(u, su), off(v, sv)
        r0 = math.hypot(su - cu, sv - cv)
        r1 = math.hypot(eu - cu, ev - cv)
        if r0 <= POS_TOL_MM:
            raise ip.err(st, col, "arc with zero radius (centre on the start point)")
        if abs(r1 - r0) > max(ARC_RADIUS_TOL_MM, ARC_RADIUS_REL_TOL * r0):
            raise ip.err(st, col, f"arc start radius {r0:.6g} mm and end radius {r1:.6g} mm "
                                  f"differ by {abs(r1 - r0):.3g} mm (more than "
                                  f"{max(ARC_RADIUS_TOL_MM, ARC_RADIUS_REL_TOL * r0):.3g} mm): "
                                  "check the centre")
    turns = 0
    if ip.ngc and p_word is not None:
        p = p_word[0]
        if p < 1 or p != int(p):
            raise ip.err(st, p_word[1], f"arc P{p:g} must be a whole number of turns >= 1")
        turns = int(p) - 1
    if not ip.ngc and "TURN" in named:
        t = named["TURN"][0]
        if t < 0 or t != int(t):
            raise ip.err(st, named["TURN"][1], f"TURN={t:g} must be a whole number >= 0")
        turns = int(t)
    c_prog = dict(prog)
    c_prog[u], c_prog[v] = cu, cv
    c_mach = ip.frame.to_machine(c_prog)
    centre_out = tuple(c_mach.get(a, 0.0) for a in ip.axes)
    basis = None
    if ip.frame.theta_deg and ip.plane != "G17":
        unit = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
        basis = (ip.frame.rotate_vec(unit[u]), ip.frame.rotate_vec(unit[v]))
    return centre_out, basis, turns

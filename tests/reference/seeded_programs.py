"""Seeded NC program bodies shared by the planner tests and the rounding benchmark."""

from __future__ import annotations

import numpy as np


def polyline(n: int, seed: int) -> str:
    """``n`` seeded lines of 0.5..5 mm with turns of 5..120 degrees (body only: ``X.. Y..``
    words, one line each, then ``M30``)."""
    rng = np.random.default_rng(seed)
    heading, x, y, out = 0.0, 0.0, 0.0, []
    for _ in range(n):
        heading += np.radians(rng.uniform(5.0, 120.0)) * rng.choice((-1.0, 1.0))
        step = rng.uniform(0.5, 5.0)
        x += step * np.cos(heading)
        y += step * np.sin(heading)
        out.append(f"X{x:.4f} Y{y:.4f}")
    return "\n".join(out) + "\nM30\n"



def _tangent_arc(x: float, y: float, heading: float, r: float, turn: float):
    """The arc of radius ``r`` leaving ``(x, y)`` along ``heading`` (rad) and turning by
    ``turn`` (rad, > 0 counter-clockwise): its word (``G2``/``G3``, end, centre as ``I J``,
    12 decimals), its end and the heading there."""
    side = np.sign(turn)                            # +1: counter-clockwise (G3)
    cx, cy = x - side * r * np.sin(heading), y + side * r * np.cos(heading)
    i_, j_ = cx - x, cy - y
    heading += turn
    x, y = cx + side * r * np.sin(heading), cy - side * r * np.cos(heading)
    word = "G3" if side > 0 else "G2"
    return f"{word} X{x:.12f} Y{y:.12f} I{i_:.12f} J{j_:.12f}", x, y, heading


def line_arc_chain(n: int, seed: int, kink_deg: float = 0.0) -> str:
    """``n`` seeded blocks alternating a line of 1..5 mm and an arc tangent to it (radius
    1..20 mm, turning 10..120 degrees, either way), each line tangent to the arc before
    it: a CAM-like contour of tangential line-arc transitions (body only, ``G1``/``G2``/
    ``G3`` words with the centre as ``I J``, 12 decimals so that the transitions are
    tangential to far below the planner's 1e-7 rad, then ``M30``). With ``kink_deg > 0``
    each line leaves its arc at a corner of ``kink_deg/2 .. kink_deg`` degrees, either
    way (arc-line corners; the arcs still start tangent to their lines)."""
    rng = np.random.default_rng(seed)
    heading, x, y, out = 0.0, 0.0, 0.0, []
    for i in range(n):
        if i % 2 == 0:
            if kink_deg > 0 and i:
                heading += (np.radians(rng.uniform(kink_deg / 2, kink_deg))
                            * rng.choice((-1.0, 1.0)))
            step = rng.uniform(1.0, 5.0)
            x += step * np.cos(heading)
            y += step * np.sin(heading)
            out.append(f"G1 X{x:.12f} Y{y:.12f}")
            continue
        r = rng.uniform(1.0, 20.0)
        turn = np.radians(rng.uniform(10.0, 120.0)) * rng.choice((-1.0, 1.0))
        word, x, y, heading = _tangent_arc(x, y, heading, r, turn)
        out.append(word)
    return "\n".join(out) + "\nM30\n"


def arc_chain(n: int, seed: int, kink_deg: float = 60.0) -> str:
    """``n`` seeded arcs (radius 1..20 mm, turning 10..120 degrees, either way), each
    leaving the one before at a corner of ``kink_deg/2 .. kink_deg`` degrees, either way:
    a contour of corners between two arcs (body only, ``G2``/``G3`` words with the centre
    as ``I J``, 12 decimals, then ``M30``)."""
    rng = np.random.default_rng(seed)
    heading, x, y, out = 0.0, 0.0, 0.0, []
    for _ in range(n):
        heading += np.radians(rng.uniform(kink_deg / 2, kink_deg)) * rng.choice((-1.0, 1.0))
        r = rng.uniform(1.0, 20.0)
        turn = np.radians(rng.uniform(10.0, 120.0)) * rng.choice((-1.0, 1.0))
        word, x, y, heading = _tangent_arc(x, y, heading, r, turn)
        out.append(word)
    return "\n".join(out) + "\nM30\n"


def s_bend_chain(n: int, seed: int, r_min: float = 20.0, r_max: float = 200.0) -> str:
    """``n`` seeded tangent arcs (radius ``r_min..r_max`` mm, turning 20..60 degrees), each
    curving the other way from the one before: a chain of S-bends, tangential transitions
    between arcs whose curvatures have opposite signs (body only, ``G1 X0 Y0`` then
    ``G2``/``G3`` words with the centre as ``I J``, 12 decimals, then ``M30``)."""
    rng = np.random.default_rng(seed)
    heading, x, y, out, side = 0.0, 0.0, 0.0, ["G1 X0 Y0"], 1.0
    for _ in range(n):
        r = rng.uniform(r_min, r_max)
        turn = np.radians(rng.uniform(20.0, 60.0)) * side
        word, x, y, heading = _tangent_arc(x, y, heading, r, turn)
        out.append(word)
        side = -side
    return "\n".join(out) + "\nM30\n"


def same_way_chain(n: int, seed: int, r_min: float = 5.0, r_max: float = 200.0) -> str:
    """``n`` seeded tangent arcs all curving the same way (radius log-uniform in ``r_min ..
    r_max`` mm, turning 15..45 degrees): a chain of tangential transitions between arcs
    whose curvatures have one sign and jump in size (body only, ``G1 X0 Y0`` then ``G3``
    words with the centre as ``I J``, 12 decimals, then ``M30``)."""
    rng = np.random.default_rng(seed)
    heading, x, y, out = 0.0, 0.0, 0.0, ["G1 X0 Y0"]
    for _ in range(n):
        r = float(np.exp(rng.uniform(np.log(r_min), np.log(r_max))))
        turn = np.radians(rng.uniform(15.0, 45.0))
        word, x, y, heading = _tangent_arc(x, y, heading, r, turn)
        out.append(word)
    return "\n".join(out) + "\nM30\n"

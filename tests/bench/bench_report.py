"""Size and render time of the HTML report for large programs (``make bench``).

Rows, all measured in this run: for 10^3, 10^4 (and with ``--full`` 10^5) blocks of a
seeded CAM-like program of G1 lines and G2/G3 arcs (``make_mixed_program``), the size of
the page in MB and bytes per block, and the time :func:`compare.report_html.render_report`
takes; then the scaling exponent k of size ~ N^k (1 = linear; the report aggregates its
plots and limits its table, so k is well below 1). The comparison itself uses the fast
stand-in engines of the compare tests, so that the row measures the report alone; the
real heuristic and oracle at 10^5 blocks take minutes (``--real``).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path as FsPath

import numpy as np

ROOT = FsPath(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

#: Size target of the issue: a 10^5-block report stays under 10 MB.
TARGET_MB_AT_1E5 = 10.0


def make_mixed_program(n: int, seed: int = 7) -> str:
    """``n`` motion blocks of a CAM-like contour: G1 lines and G2/G3 arcs with ``CR``.

    The tool wanders in XY with steps of 0.5..5 mm; about a third of the blocks are
    arcs whose radius is 1..4 times the chord (so each arc is well defined), at F8000
    on G64 continuous-path mode.

    Parameters
    ----------
    n : int
        Number of motion blocks.
    seed : int
        Seed of the random generator (same seed, same program).

    Returns
    -------
    str
        SINUMERIK program text (``n + 2`` lines).
    """
    rng = np.random.default_rng(seed)
    steps = rng.uniform(0.5, 5.0, n)
    ang = np.cumsum(rng.normal(0.0, 0.35, n))
    xy = np.cumsum(np.c_[steps * np.cos(ang), steps * np.sin(ang)], axis=0)
    arc = rng.uniform(size=n) < 0.33
    ccw = rng.uniform(size=n) < 0.5
    rad = steps * rng.uniform(1.0, 4.0, n)
    lines = ["N1 G90 G64 G17 F8000"]
    for i, (x, y) in enumerate(xy):
        if arc[i]:
            g = "G3" if ccw[i] else "G2"
            lines.append(f"{g} X{x:.4f} Y{y:.4f} CR={rad[i]:.4f}")
        else:
            lines.append(f"G1 X{x:.4f} Y{y:.4f}")
    lines.append("M30")
    return "\n".join(lines) + "\n"

"""Size and render time of the HTML report for large programs (``make bench``).

Rows, all measured in this run: for 10^3 and 10^4 (with ``--full`` also 10^5) blocks of
a seeded CAM-like program of G1 lines and G2/G3 arcs (:func:`make_mixed_program`) on the
default machine, compared with the real heuristic and oracle
(:func:`compare.pipeline.compare_program`): the size of the report page in MB and bytes
per block, the time :func:`compare.report_html.write_report` takes, and the scaling
exponent k of size ~ N^k (1 = linear; the report reduces its plots to the screen and
limits its table, so k is near 0). At 10^5 blocks the page must stay under
:data:`TARGET_MB_AT_1E5` (the comparison alone takes a minute or two there).
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


def _measure(n: int, folder: FsPath) -> tuple[float, float, float, str, float]:
    """Compare an ``n``-block program (real heuristic and oracle) and write its report.

    Returns
    -------
    compare_s, render_s, size_mb, status, bracket
        Wall times, page size, oracle status and its bracket ``UB/LB - 1``.
    """
    from compare.pipeline import compare_program
    from compare.report_html import write_report
    from reference.nc import parse_text

    program = parse_text(make_mixed_program(n), f"mixed_{n}.mpf", "sinumerik")
    t0 = time.perf_counter()
    c = compare_program(program, None)
    t1 = time.perf_counter()
    page = write_report(folder / f"mixed_{n}.html", c,
                        links={"JSON": f"mixed_{n}.json", "CSV": f"mixed_{n}.csv"})
    t2 = time.perf_counter()
    o = c.oracle
    return t1 - t0, t2 - t1, page.stat().st_size / 1e6, o.status, \
        o.upper_bound_s / o.lower_bound_s - 1.0


def main(argv: list[str]) -> int:
    """Print the size rows; ``--full`` adds 10^5 blocks (a minute or two more)."""
    import tempfile

    sizes = [1_000, 10_000] + ([100_000] if "--full" in argv else [])
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            cs, rs, mb, status, br = _measure(n, FsPath(tmp))
            rows.append((n, mb))
            print(f"   report {n:>7} blocks: {mb:6.2f} MB ({1e6 * mb / n:7.0f} B/block), "
                  f"render {rs:5.2f} s (compare {cs:6.1f} s, oracle {status}, "
                  f"bracket {100 * br:.2f} %)", flush=True)
    (n0, m0), (n1, m1) = rows[0], rows[-1]
    k = math.log(m1 / m0) / math.log(n1 / n0)
    print(f"   report size ~ N^{k:.2f} from {n0} to {n1} blocks (1 = linear)")
    if n1 >= 100_000:
        ok = m1 <= TARGET_MB_AT_1E5
        print(f"   10^5 blocks: {m1:.2f} MB vs target {TARGET_MB_AT_1E5:g} MB: "
              f"{'ok' if ok else 'ABOVE TARGET'}")
        return 0 if ok else 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))

"""The report's plots: matplotlib figures (no pyplot state) embedded as SVG ``data:`` URIs.

Every plot is reduced for the screen before it is drawn, so its size depends on the
plot width, not on the program: time series and the speed over path length are min/max
envelopes per pixel column (:mod:`compare.report.envelope`: every peak stays visible),
markers are thinned per column, and a tool path with more points than a vector drawing
should hold is rasterized (a PNG inside the SVG; labels and markers stay vector).

Units: mm, s, mm/s; accelerations in m/s^2 and jerks in m/s^3 on the axes plots.
"""

from __future__ import annotations

import base64
import io
from typing import Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from reference.core.geometry import KIND_CODES
from reference.core.tolerances import MOVING_AXIS_TOL

from ..kinematics import axis_motion, limit_curve
from ..result import INSERTED_KINDS, ComparedBlock, Comparison
from .envelope import N_COLUMNS, chunked_envelopes, column_extremes, envelope

#: Colours: the planner under test, the oracle, limits, inserted blocks, worst blocks.
C_REF, C_OPT, C_LIM, C_INS, C_WORST = "#d62728", "#1f77b4", "#555555", "#ff7f0e", "#9400d3"
AXIS_COLOURS = ("#1f77b4", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2")
#: Rows with the largest positive gap that are marked in the path and gap plots.
N_WORST = 5
#: Most profile samples evaluated per plot curve: every knot and every interior speed
#: extremum up to this many (a 10^5-block profile has ~10^6 knots), evenly thinned
#: beyond. With 1200 columns that is still ~800 samples per pixel column.
SAMPLE_BUDGET = 1_000_000
#: Uniform samples added to the knots (resolves long intervals of short profiles).
UNIFORM_SAMPLES = 4 * N_COLUMNS
#: Corner-limit markers and stop lines drawn at most this many per plot (one per group
#: of pixel columns: a 4 pt marker covers ~5 columns).
N_MARKERS = 300
#: Up to this many per-block bars, each bar is drawn (and coloured) on its own.
MAX_BARS = 200
#: Up to this many blocks, the gap plot labels every block with its source line.
MAX_LINE_TICKS = 40
#: Tool-path points above which the path lines are rasterized (a vector polyline of
#: 10^6 points is ~30 MB of SVG; the raster is ~0.1 MB whatever the program).
MAX_VECTOR_POINTS = 20_000
#: Resolution of rasterized parts, dots per inch (11 in wide: ~1650 px, sharp on HiDPI).
RASTER_DPI = 150
#: Geometric offset used to evaluate the limit curve just inside each segment (the
#: limit is discontinuous at segment breaks), mm; far below any drawn resolution.
BREAK_OFFSET_MM = 1e-9


def svg_uri(fig: Figure) -> str:
    """The figure as an SVG ``data:`` URI (rasterized artists at :data:`RASTER_DPI`)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="svg", bbox_inches="tight", metadata={"Date": None},
                dpi=RASTER_DPI)
    return "data:image/svg+xml;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def who(c: Comparison) -> str:
    """What the planner under test is called on the page."""
    return "recorded trajectory" if c.reference_name == "recorded" else "heuristic"


def profile_times(prof, budget: int = SAMPLE_BUDGET) -> np.ndarray:
    """Times that carry every feature of a profile's speed: knots, the interior speed
    extrema of each constant-jerk interval, and a uniform grid.

    Parameters
    ----------
    prof : Profile
    budget : int
        Most samples returned (evenly thinned beyond; the uniform grid is always kept).

    Returns
    -------
    numpy.ndarray, shape (N,)
        Sorted unique times, s.
    """
    t0, t1 = float(prof.t[0]), float(prof.t[-1])
    uni = np.linspace(t0, t1, UNIFORM_SAMPLES)
    if prof.n_intervals == 0:
        return uni
    h = np.diff(prof.t)
    jj = prof.j
    with np.errstate(divide="ignore", invalid="ignore"):
        ts = np.where(jj != 0, -prof.a / np.where(jj != 0, jj, 1.0), -1.0)
    inside = (ts > 0) & (ts < h)
    feat = np.concatenate([prof.t, prof.t[:-1][inside] + ts[inside]])
    if feat.size > budget:
        feat = np.sort(feat)[np.linspace(0, feat.size - 1, budget).astype(np.int64)]
    return np.unique(np.concatenate([feat, uni]))


def _moving_axes(c: Comparison) -> list[int]:
    if not c.path.n_segments:
        return []
    q = c.path.evaluate(np.linspace(0, c.path.total_length, 400))[0]
    return [i for i in range(c.path.n_axes) if np.ptp(q[:, i]) > MOVING_AXIS_TOL]


def _thin_marks(x: np.ndarray, y: np.ndarray, x0: float, x1: float
                ) -> tuple[np.ndarray, np.ndarray]:
    """At most one mark per group of columns: the lowest (the binding limit)."""
    if x.size <= N_MARKERS:
        return x, y
    xc, lo, _ = column_extremes(x, y, x0, x1, N_MARKERS)
    ok = np.isfinite(lo)
    return xc[ok], lo[ok]


# --------------------------------------------------------------------- speed
def dense(c: Comparison) -> bool:
    """True when the path has more segments than a quarter of the pixel columns: its
    curves then oscillate inside every column, and a line through the envelope would
    paint a solid block, so they are drawn as translucent min–max bands instead."""
    return c.path.n_segments > N_COLUMNS // 4


def draw_band(ax, x, y, x0: float, x1: float, n_columns: int, **style) -> None:
    """A min–max band per pixel column (``fill_between``) of a series."""
    xc, lo, hi = column_extremes(x, y, x0, x1, n_columns)
    ok = np.isfinite(lo)
    ax.fill_between(xc[ok], lo[ok], hi[ok], step="mid", lw=0, **style)


def mean_speed(prof, x1: float, n_columns: int = N_COLUMNS) -> tuple[np.ndarray, np.ndarray]:
    """Mean path speed per column of path length: column width over the time the motion
    spends in it (holds included), mm/s; the ratio of two planners' curves is the local
    gap. Returns column centres and speeds, shape (C,)."""
    edges = np.linspace(0.0, x1, n_columns + 1)
    dt = np.diff(prof.time_at(np.clip(edges, prof.s[0], prof.s[-1])))
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.where(dt > 0, np.diff(edges) / dt, np.nan)
    return 0.5 * (edges[:-1] + edges[1:]), v


def plot_speed(c: Comparison) -> str:
    """Path speed over path length: both planners and the limit curve (SVG URI).

    Up to a few hundred segments the curves are lines through their per-column
    envelopes; on denser paths each planner is a translucent min–max band with its mean
    speed per column as the line, and the limit curve is its per-column maximum (shaded
    above) and minimum (dotted).
    """
    fig = Figure(figsize=(11, 3.8))
    ax = fig.add_subplot()
    L = c.path.total_length
    x1 = max(L, 1e-9)
    vmax = 1.0
    band = dense(c)
    for prof, colour, label, ls in ((c.reference_profile, C_REF, who(c), "-"),
                                    (c.oracle.profile, C_OPT, "oracle (verified)", "--")):
        if prof is None:
            continue

        def series(t, prof=prof):
            s, v, _, _ = prof.state(t)
            yield s, v

        (s, v), = chunked_envelopes(profile_times(prof), series, 0.0, x1)
        vmax = max(vmax, float(np.max(v)) if v.size else 0.0)
        if band:
            draw_band(ax, s, v, 0.0, x1, N_COLUMNS, color=colour, alpha=0.22,
                      label=f"{label}: min–max per column")
            xm, vm = mean_speed(prof, x1)
            ax.plot(xm, vm, color=colour, lw=1.4, ls=ls, label=f"{label}: mean speed")
        else:
            ax.plot(s, v, color=colour, lw=1.2, ls=ls, label=label)
    if c.path.n_segments:
        sg = np.unique(np.concatenate([
            np.linspace(0, L, 2 * N_COLUMNS), c.path.s_breaks[:-1] + BREAK_OFFSET_MM,
            c.path.s_breaks[1:] - BREAK_OFFSET_MM]))
        sg = np.clip(sg, 0, L)

        def lim_series(s):
            yield s, limit_curve(c.path, c.limits, s)["limit"]

        (sl, lc), = chunked_envelopes(sg, lim_series, 0.0, x1)
        cap = 1.25 * vmax
        if band:
            xc, lo, hi = column_extremes(sl, lc, 0.0, x1, N_COLUMNS)
            ok = np.isfinite(hi)
            ax.fill_between(xc[ok], np.minimum(hi[ok], cap), cap, step="mid",
                            color="#e8e8e8", lw=0, label="above the limit curve")
            ax.plot(xc[ok], np.minimum(hi[ok], cap), color=C_LIM, lw=0.8,
                    drawstyle="steps-mid", label="limit curve: highest in the column")
            ax.plot(xc[ok], np.minimum(lo[ok], cap), color="#8a8f96", lw=0.5, alpha=0.7,
                    drawstyle="steps-mid", label="limit curve: lowest in the column")
        else:
            ax.fill_between(sl, np.minimum(lc, cap), cap, color="#e8e8e8", lw=0,
                            label="above the limit curve")
            ax.plot(sl, np.minimum(lc, cap), color=C_LIM, lw=0.8,
                    label="limit curve (feed, axis velocity, centripetal acceleration)")
        sc, vc = corner_limits(c)
        sc, vc = _thin_marks(sc, vc, 0.0, x1)
        if sc.size:
            ax.plot(sc, np.minimum(vc, cap), "v", color=C_LIM, ms=4, ls="none",
                    label="corner limit (velocity jump, MD32310)"
                    + (": lowest per group" if band else ""))
        ax.set_ylim(0, cap)
    k_stop = np.flatnonzero(c.path.stop[1:c.path.n_segments]) + 1
    stops = c.path.s_breaks[k_stop] if k_stop.size else np.zeros(0)
    if stops.size > N_MARKERS:                # one line per group of columns
        xc, lo, _ = column_extremes(stops, stops, 0.0, x1, N_MARKERS)
        stops = lo[np.isfinite(lo)]
    for sx in stops:
        ax.axvline(sx, color="#999", lw=0.6, ls=":")
    ax.set_xlim(0, x1)
    ax.set_xlabel("path length s [mm]")
    ax.set_ylabel("path speed [mm/s]")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=3, fontsize=8,
              frameon=False)
    return svg_uri(fig)


def corner_limits(c: Comparison) -> tuple[np.ndarray, np.ndarray]:
    """Path positions of non-tangential corners and the speed the jump rule allows there."""
    path = c.path
    if path.n_segments < 2:
        return np.zeros(0), np.zeros(0)
    lim = c.limits.for_axes(path.axes)
    t_in, t_out = path.junction_tangents()
    d = np.abs(t_out - t_in)
    corner = np.any(d > 1e-9, axis=1) & ~path.stop[1:-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        v = np.min(np.where(d > 1e-9, lim.jump[None, :] / d, np.inf), axis=1)
    return path.s_breaks[1:-1][corner], v[corner]


# --------------------------------------------------------------------- axes
def plot_axes(c: Comparison) -> str:
    """Axis acceleration and jerk over time for both planners (SVG URI)."""
    lim = c.limits.for_axes(c.path.axes)
    profs = [(who(c), c.reference_profile)]
    if c.oracle.profile is not None:
        profs.append(("oracle (verified)", c.oracle.profile))
    fig = Figure(figsize=(11, 5.6))
    axs = fig.subplots(2, len(profs), sharex=True, sharey="row", squeeze=False)
    t_end = max(max(p.duration for _, p in profs), 1e-9)
    moving = _moving_axes(c)
    cols = N_COLUMNS // len(profs)            # each subplot is that wide
    band = dense(c)
    for col, (name, prof) in enumerate(profs):

        def series(t, prof=prof):
            m = axis_motion(c.path, prof, t)
            for i in moving:
                yield m.t, m.acc[:, i] / 1e3
                yield m.t, m.jerk[:, i] / 1e3

        curves = chunked_envelopes(profile_times(prof), series, 0.0, t_end, cols) \
            if moving else []
        for k, i in enumerate(moving):
            colour = AXIS_COLOURS[i % len(AXIS_COLOURS)]
            (ta, acc), (tj, jer) = curves[2 * k], curves[2 * k + 1]
            if band:                  # oscillates inside every column: bands
                draw_band(axs[0, col], ta, acc, 0.0, t_end, cols, color=colour,
                          alpha=0.35, label=c.path.axes[i])
                draw_band(axs[1, col], tj, jer, 0.0, t_end, cols, color=colour,
                          alpha=0.35, label=c.path.axes[i])
            else:
                axs[0, col].plot(ta, acc, color=colour, lw=1.0, label=c.path.axes[i])
                axs[1, col].plot(tj, jer, color=colour, lw=1.0, label=c.path.axes[i])
            for row, limit in ((0, lim.a_max[i]), (1, lim.j_max[i])):
                for sgn in (1, -1):
                    axs[row, col].axhline(sgn * limit / 1e3, color=colour, lw=0.7, ls=":")
        axs[0, col].set_title(name, fontsize=10)
        axs[1, col].set_xlabel("time [s]")
        for row in (0, 1):
            axs[row, col].grid(alpha=0.3)
            axs[row, col].set_xlim(0, t_end)
    axs[0, 0].set_ylabel("axis acceleration [m/s²]")
    axs[1, 0].set_ylabel("axis jerk [m/s³]")
    jmax = max((lim.j_max[i] for i in moving), default=1.0) / 1e3
    axs[1, 0].set_ylim(-2.5 * jmax, 2.5 * jmax)
    if moving:
        axs[0, -1].legend(loc="upper right", fontsize=8,
                          title="axis (dotted: ± limit)" + (", min–max per column"
                                                            if band else ""),
                          title_fontsize=8)
    fig.tight_layout()
    return svg_uri(fig)


# --------------------------------------------------------------------- gaps
def moving_rows(c: Comparison) -> list:
    """Rows with path length or time: the blocks of the gap plot, in execution order."""
    return [r for r in c.rows if r.length_mm > 0 or r.t_reference_s > 0 or r.t_oracle_s > 0]


def plot_gaps(c: Comparison, worst: Sequence[ComparedBlock] | None = None) -> str:
    """Per-block gaps in execution order and the accumulated gap (SVG URI).

    The x axis is the block's place in the executed program (a loop's lines appear once
    per pass, so source lines cannot label it); with more blocks than pixel columns each
    column shows the largest and the most negative gap of its blocks, so a single bad
    block stays a visible spike. The worst blocks carry their source line, and the
    accumulated gap (right axis) shows where the total time is lost.
    """
    worst = c.worst_blocks(N_WORST) if worst is None else worst
    rows = moving_rows(c)
    fig = Figure(figsize=(11, 3.4))
    ax = fig.add_subplot()
    n = len(rows)
    if rows:
        x = np.arange(1, n + 1, dtype=np.float64)          # 1-based, as the table's #
        gap = np.nan_to_num(np.array([1e3 * r.gap_s for r in rows]))
        if n <= MAX_BARS:
            colours = [C_INS if r.inserted else (C_REF if g >= 0 else C_OPT)
                       for r, g in zip(rows, gap)]
            ax.bar(x, gap, color=colours, width=0.85, lw=0)
        else:                          # per-column extremes: two polygons, not n bars
            xc, lo, hi = column_extremes(x, gap, 0.5, n + 0.5, min(n, N_COLUMNS))
            ok = np.isfinite(hi)
            ax.fill_between(xc[ok], 0, np.maximum(hi[ok], 0), step="mid", color=C_REF,
                            lw=0)
            ax.fill_between(xc[ok], np.minimum(lo[ok], 0), 0, step="mid", color=C_OPT,
                            lw=0)
        ax.axhline(0, color="#333", lw=0.7)
        if n <= MAX_LINE_TICKS:
            ax.set_xticks(x)
            ax.set_xticklabels([str(r.line) for r in rows], fontsize=7, rotation=90)
            ax.set_xlabel("block (source line), in program order")
        else:
            ax.xaxis.set_major_locator(MaxNLocator(nbins=12, integer=True))
            ax.set_xlabel(f"block in execution order (1 … {n}; loops and inserted blocks "
                          "repeat lines, so only the worst blocks are labelled with their "
                          "source line)")
            y0, y1 = ax.get_ylim()            # room for the labels above the spikes
            ax.set_ylim(y0, y1 + 0.12 * (y1 - y0))
            pos = {id(r): k for k, r in enumerate(rows)}
            for r in worst:
                k = pos.get(id(r))
                if k is not None:
                    ax.annotate(f"line {r.line}", (k + 1, 1e3 * r.gap_s), xytext=(0, 6),
                                textcoords="offset points", ha="center", fontsize=7,
                                color=C_WORST)
        ax.set_xlim(0.4, n + 0.6)
        cum = np.cumsum(gap) / 1e3
        xe, ce = envelope(x, cum, 0.5, n + 0.5)
        ax2 = ax.twinx()
        ax2.plot(xe, ce, color="#333", lw=1.0, label="accumulated gap")
        ax2.set_ylabel("accumulated [s]", fontsize=8)
        ax2.tick_params(labelsize=7)
        ax2.legend(loc="upper left", fontsize=8, frameon=False)
    ax.set_ylabel("t_ref − t_opt [ms]")
    ax.grid(alpha=0.3, axis="y")
    return svg_uri(fig)


# --------------------------------------------------------------------- tool path
def _plane(c: Comparison, q: np.ndarray) -> tuple[int, int]:
    cand = [i for i, a in enumerate(c.path.axes) if a in ("X", "Y", "Z")] or \
        list(range(c.path.n_axes))
    if len(cand) < 2:
        return cand[0], cand[0]
    ext = {i: np.ptp(q[:, i]) for i in cand}
    if "X" in c.path.axes and "Y" in c.path.axes:
        ix, iy = c.path.axes.index("X"), c.path.axes.index("Y")
        if ext[ix] + ext[iy] > 0:
            return ix, iy
    best = sorted(cand, key=lambda i: -ext[i])[:2]
    return tuple(sorted(best))  # type: ignore[return-value]


def _path_points(path) -> tuple[np.ndarray, np.ndarray]:
    """Points along every segment (2 per line, arcs every 0.05 mm, 8..400 per arc) and
    the segment of each point: ``q`` shape (N, n), ``seg`` shape (N,)."""
    n_pts = np.where(path.radius == 0, 2, np.clip(
        np.ceil(np.abs(path.omega) * path.length / 0.05).astype(np.int64), 8, 400))
    seg = np.repeat(np.arange(path.n_segments), n_pts)
    first = np.concatenate(([0], np.cumsum(n_pts)[:-1]))
    frac = (np.arange(seg.size) - first[seg]) / (n_pts[seg] - 1)
    s = path.s_breaks[seg] + frac * path.length[seg]
    return path.evaluate(s, segment=seg)[0], seg


def plot_toolpath(c: Comparison, worst: Sequence[ComparedBlock] | None = None) -> str:
    """The tool path in its main plane (SVG URI): the programmed contour (before tool
    radius compensation and rounding, ``c.programmed``) under the planned path both
    planners run on, with inserted and worst blocks marked."""
    fig = Figure(figsize=(11, 6.0))
    ax = fig.add_subplot()
    path = c.path
    if path.n_segments == 0:
        ax.text(0.5, 0.5, "no path motion", ha="center", transform=ax.transAxes)
        return svg_uri(fig)
    qs = path.evaluate(np.linspace(0, path.total_length, 500))[0]
    i, j = _plane(c, qs)
    worst_rows = c.worst_blocks(N_WORST) if worst is None else worst
    # the segments of each worst row, by its stretch of the path (an inserted block's row
    # and its corner block's row share the block index)
    mid_seg = 0.5 * (path.s_breaks[:-1] + path.s_breaks[1:])
    in_worst = np.zeros(path.n_segments, bool)
    row_segs = []
    for r in worst_rows:
        sel = np.flatnonzero((mid_seg > r.s_start) & (mid_seg < r.s_start + r.length_mm))
        in_worst[sel] = True
        row_segs.append(sel)
    # points of every segment (arcs finely), NaN-separated per drawing style
    q, seg = _path_points(path)
    prog = c.programmed
    if prog is not None and (prog.n_segments == 0 or prog.axes != path.axes):
        prog = None
    q_prog = _path_points(prog)[0] if prog is not None else None
    raster = seg.size + (0 if q_prog is None else q_prog.shape[0]) > MAX_VECTOR_POINTS
    kinds = np.array([KIND_CODES[int(k)] for k in path.kind])
    style_of = np.where(in_worst, "worst",
                        np.where(np.isin(kinds, INSERTED_KINDS), "inserted",
                                 np.where(path.rapid, "rapid", "program")))
    if q_prog is not None:
        # drawn first, under the planned path: where the two coincide only the planned
        # path shows; at a rounded corner the programmed corner stands out beside it
        ax.plot(q_prog[:, i], q_prog[:, j], color="#8fb3d9", lw=3.2 if not raster else 1.6,
                zorder=1, solid_capstyle="round", rasterized=raster,
                label="programmed contour (before compensation and rounding)")
    styles = {"program": dict(color="#2b3440", lw=1.1 if not raster else 0.6, zorder=2,
                              label="planned path (G1/G2/G3)"),
              "rapid": dict(color="#9aa0a8", lw=1.0, ls="--", zorder=2, label="rapid (G0)"),
              "inserted": dict(color=C_INS, lw=2.2 if not raster else 1.2, zorder=3,
                               label="inserted blocks (rounding, TRC)"),
              "worst": dict(color=C_WORST, lw=3.0, zorder=4,
                            label=f"largest block gaps (up to {N_WORST})")}
    for name, style in styles.items():
        segs = np.flatnonzero(style_of == name)
        if segs.size == 0:
            continue
        pts = np.isin(seg, segs)
        x, y = q[pts, i].copy(), q[pts, j].copy()
        # break the line between segments that do not follow each other
        brk = np.flatnonzero(np.diff(seg[pts]) > 1) + 1
        x, y = np.insert(x, brk, np.nan), np.insert(y, brk, np.nan)
        ax.plot(x, y, rasterized=raster and name != "worst", **style)
    for r, segs in zip(worst_rows, row_segs):
        if segs.size == 0:
            continue
        mid = path.evaluate(path.s_breaks[segs[0]] + 0.5 * path.length[segs[0]])[0][0]
        ax.annotate(f"line {r.line}\n{1e3 * r.gap_s:+.0f} ms", (mid[i], mid[j]),
                    xytext=(8, 8), textcoords="offset points", fontsize=8,
                    color=C_WORST, zorder=5,
                    bbox=dict(boxstyle="round,pad=0.2", fc="white", ec=C_WORST, lw=0.6))
    stops = np.flatnonzero(path.stop)
    if stops.size:
        qb = path.evaluate(np.clip(path.s_breaks[stops], 0, path.total_length))[0]
        ax.plot(qb[:, i], qb[:, j], "s", ms=5 if stops.size <= N_MARKERS else 2,
                color="#111", zorder=6, label="required stop",
                rasterized=stops.size > N_MARKERS)
    q0 = path.evaluate(0.0)[0][0]
    ax.plot([q0[i]], [q0[j]], "o", ms=7, mfc="none", mec="#2ca02c", mew=2, zorder=6,
            label="start")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{path.axes[i]} [mm]")
    ax.set_ylabel(f"{path.axes[j]} [mm]")
    ax.grid(alpha=0.3)
    inset = q_prog is not None and _corner_inset(fig, ax, c, q, seg, q_prog, i, j,
                                                  style_of, styles)
    if inset:
        # the zoom sits in the lower right of the plot: the legend goes below the axes,
        # where it can cover neither the zoom nor the path
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=3, fontsize=8,
                  framealpha=0.9)
    else:
        # "best" scans every drawn point for a free spot: seconds at 10^6 points
        ax.legend(loc="upper right" if raster else "best", fontsize=8, framealpha=0.9)
    return svg_uri(fig)


def _corner_inset(fig, ax, c: Comparison, q: np.ndarray, seg: np.ndarray,
                  q_prog: np.ndarray, i: int, j: int, style_of: np.ndarray,
                  styles: dict) -> bool:
    """A zoom on the rounded corner whose rounding lies farthest from the programmed
    corner (relative to the plot's size), so the rounding is visible beside the
    programmed corner even where it is far below the plot's resolution. Returns whether
    it was drawn."""
    table = c.path.rounding
    if table is None or not table.inserted.any():
        return False
    k = int(np.flatnonzero(table.inserted)[np.argmax(table.deviation_mm[table.inserted])])
    rnd = np.flatnonzero(c.path.kind == KIND_CODES.index("rounding"))
    # the rounding segment of that corner: the one attributed to its block
    own = rnd[c.path.block[rnd] == table.block[k]]
    if own.size == 0:
        return False
    r = int(own[0])
    a, b = c.path.segment(r).start, c.path.segment(r).end
    half = 1.6 * max(table.distance_mm[k], 1e-6)
    centre = 0.5 * (a + b)
    x0, x1 = centre[i] - half, centre[i] + half
    y0, y1 = centre[j] - half, centre[j] + half
    span = max(np.ptp(q[:, i]), np.ptp(q[:, j]), 1e-12)
    if half / span > 0.05:             # visible in the main plot already
        return False
    sub = fig.add_axes([0.70, 0.14, 0.2, 0.3])

    def near(pts: np.ndarray, owner: np.ndarray) -> np.ndarray:
        """Points of the pieces whose bounding box meets the zoom window (a line has
        only its two end points: the axes clip it)."""
        cut = np.flatnonzero(np.diff(owner)) + 1
        starts = np.concatenate(([0], cut))
        lo_x, hi_x = (np.minimum.reduceat(pts[:, i], starts),
                      np.maximum.reduceat(pts[:, i], starts))
        lo_y, hi_y = (np.minimum.reduceat(pts[:, j], starts),
                      np.maximum.reduceat(pts[:, j], starts))
        hit = (hi_x >= x0) & (lo_x <= x1) & (hi_y >= y0) & (lo_y <= y1)
        return np.repeat(hit, np.diff(np.concatenate((starts, [owner.size]))))

    def draw(pts: np.ndarray, owner: np.ndarray, keep: np.ndarray, **style) -> None:
        sel = np.flatnonzero(keep)
        if sel.size == 0:
            return
        x, y = pts[sel, i], pts[sel, j]
        brk = np.flatnonzero(np.diff(owner[sel]) != 0) + 1
        sub.plot(np.insert(x, brk, np.nan), np.insert(y, brk, np.nan), **style)

    prog_owner = _path_points(c.programmed)[1]
    draw(q_prog, prog_owner, near(q_prog, prog_owner), color="#8fb3d9", lw=3.2, zorder=1)
    close = near(q, seg)
    for name in ("program", "rapid", "inserted", "worst"):
        st = {key: v for key, v in styles[name].items() if key != "label"}
        draw(q, seg, close & np.isin(seg, np.flatnonzero(style_of == name)), **st)
    sub.set_xlim(x0, x1)
    sub.set_ylim(y0, y1)
    sub.set_aspect("equal", adjustable="box")
    sub.tick_params(labelsize=6)
    sub.set_title(f"corner {c_line(c, int(table.block[k]))}/"
                  f"{c_line(c, int(table.next_block[k]))}: {table.mode[k]}, deviation "
                  f"{table.deviation_mm[k]:.3g} mm", fontsize=7)
    ax.indicate_inset_zoom(sub, edgecolor="#555")
    return True


def c_line(c: Comparison, block: int) -> int:
    """Source line of a program block (0 if unknown)."""
    return next((sp.line for sp in c.path.blocks if sp.block == block), 0)

"""Self-contained HTML reports: one page per program, an index for several.

A page needs no network: plots are SVG made with matplotlib (``Figure`` objects with
no pyplot state, the backend-neutral canvas) and embedded as ``data:`` URIs, CSS and
the table-sorting script are inline. Every piece of text that comes from the program
or the user (file names, comments, labels, notes) is HTML-escaped.

Page layout: summary (times, gap interval, verdict, violations, notes), path speed of
both planners over path length with the limit curve, axis acceleration and jerk over
time, per-block gap bars, the tool path in its main plane with inserted blocks and the
worst blocks marked, a sortable block table whose rows link to the source listing at
the end of the page.
"""

from __future__ import annotations

import base64
import html
import io
import math
from datetime import datetime, timezone
from pathlib import Path as FsPath
from typing import Mapping, Sequence

import numpy as np
from matplotlib.figure import Figure

from reference.core.constraints import BOUND_SETS

from reference.core.geometry import KIND_CODES

from .comparison import INSERTED_KINDS, Comparison, describe_violation, format_interval
from .kinematics import axis_motion, limit_curve, sample_times

#: Colours: the planner under test, the oracle, limits, inserted blocks, worst blocks.
C_REF, C_OPT, C_LIM, C_INS, C_WORST = "#d62728", "#1f77b4", "#555555", "#ff7f0e", "#9400d3"
AXIS_COLOURS = ("#1f77b4", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2")
#: Largest number of points drawn per curve (keeps the SVG small).
MAX_POINTS = 3000
#: Rows with the largest positive gap that are marked in the path plot.
N_WORST = 5

_CSS = """
body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,Helvetica,Arial,sans-serif;
 margin:0;color:#1d2330;background:#f4f5f7;line-height:1.4}
main{max-width:1280px;margin:0 auto;padding:18px 24px 40px}
h1{font-size:1.45rem;margin:.2em 0 .1em}
h2{font-size:1.1rem;margin:1.6em 0 .5em;border-bottom:1px solid #d6d9df;padding-bottom:.2em}
.sub{color:#5a6270;font-size:.9rem}
.cards{display:flex;flex-wrap:wrap;gap:12px;margin:14px 0}
.card{background:#fff;border:1px solid #dde0e5;border-radius:6px;padding:10px 14px;
 min-width:170px;flex:1}
.card .k{font-size:.78rem;color:#5a6270;text-transform:uppercase;letter-spacing:.04em}
.card .v{font-size:1.35rem;font-weight:600;margin-top:2px}
.card .d{font-size:.8rem;color:#5a6270}
.verdict{border-radius:6px;padding:10px 14px;font-weight:600;margin:10px 0}
.verdict.ok{background:#e3f4e6;border:1px solid #8ccf98;color:#17561f}
.verdict.fail{background:#fde6e6;border:1px solid #e39a9a;color:#7a1414}
.notes li{margin:.25em 0;font-size:.9rem}
figure{background:#fff;border:1px solid #dde0e5;border-radius:6px;margin:10px 0;padding:8px}
figure img{width:100%;height:auto;display:block}
figcaption{font-size:.85rem;color:#4a5260;padding:4px 6px}
table{border-collapse:collapse;font-size:.82rem;background:#fff;width:100%}
th,td{border:1px solid #e1e4e8;padding:3px 6px;text-align:right;white-space:nowrap}
td.t,th.t{text-align:left}
th{background:#eef0f3;position:sticky;top:0;cursor:pointer;user-select:none}
th.sorted-asc::after{content:' \\25B2'}th.sorted-desc::after{content:' \\25BC'}
tr.neg td.gap{color:#1f5fa8}tr.pos td.gap{color:#a11}
tr.worst td{background:#fbf0ff}tr.ins td{background:#fff6ea}
table.hide-idle tr.idle{display:none}tr.idle td{color:#9aa0a8}
td.note{white-space:normal;text-align:left;font-size:.76rem;color:#4a5260;min-width:260px}
.tablewrap{max-height:640px;overflow:auto;border:1px solid #dde0e5;border-radius:6px}
pre.src{background:#fff;border:1px solid #dde0e5;border-radius:6px;padding:8px 0;
 font-size:.8rem;max-height:600px;overflow:auto}
pre.src span{display:block;padding:0 10px}
pre.src span:target{background:#fff3b0}
pre.src span.hot{background:#fbf0ff}
pre.src a{color:#8a919c;text-decoration:none;display:inline-block;width:3.5em}
.viol{color:#7a1414}
code{background:#eef0f3;padding:0 3px;border-radius:3px}
a{color:#1f5fa8}
"""

_JS = """
(function(){
 var box=document.getElementById('show-idle');
 if(box){box.addEventListener('change',function(){
  document.getElementById('blocks').classList.toggle('hide-idle',!box.checked);});}
 function mark(img){img.setAttribute('data-drawn',img.naturalWidth+'x'+img.naturalHeight);}
 document.querySelectorAll('img.plot').forEach(function(img){
  if(img.complete)mark(img);else img.addEventListener('load',function(){mark(img);});});
 function val(td){var v=td.getAttribute('data-v');if(v===null)v=td.textContent;
  var n=parseFloat(v);return isNaN(n)?v.toLowerCase():n;}
 document.querySelectorAll('table.sortable').forEach(function(t){
  var ths=t.querySelectorAll('thead th');
  ths.forEach(function(th,i){th.addEventListener('click',function(){
   var asc=!th.classList.contains('sorted-asc');
   ths.forEach(function(h){h.classList.remove('sorted-asc','sorted-desc');});
   th.classList.add(asc?'sorted-asc':'sorted-desc');
   var body=t.tBodies[0],rows=Array.prototype.slice.call(body.rows);
   rows.sort(function(a,b){var x=val(a.cells[i]),y=val(b.cells[i]);
    if(typeof x!==typeof y){x=String(x);y=String(y);}
    return (x<y?-1:x>y?1:0)*(asc?1:-1);});
   rows.forEach(function(r){body.appendChild(r);});
  });});
 });
})();
"""

_e = html.escape


def _svg_uri(fig: Figure) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="svg", bbox_inches="tight", metadata={"Date": None})
    return "data:image/svg+xml;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _figure(uri: str, alt: str, caption: str, name: str) -> str:
    return (f'<figure id="fig-{name}"><img class="plot" alt="{_e(alt)}" src="{uri}">'
            f"<figcaption>{caption}</figcaption></figure>")


def _thin(*arrays: np.ndarray, n: int = MAX_POINTS) -> tuple[np.ndarray, ...]:
    m = arrays[0].shape[0]
    if m <= n:
        return arrays
    idx = np.unique(np.linspace(0, m - 1, n).astype(np.int64))
    return tuple(a[idx] for a in arrays)


def _who(c: Comparison) -> str:
    return "recorded trajectory" if c.reference_name == "recorded" else "heuristic"


# --------------------------------------------------------------------- plots
def plot_speed(c: Comparison) -> str:
    """Path speed over path length: both planners and the limit curve (SVG URI)."""
    fig = Figure(figsize=(11, 3.8))
    ax = fig.add_subplot()
    L = c.path.total_length
    vmax = 1.0
    for prof, colour, label, ls in ((c.reference_profile, C_REF, _who(c), "-"),
                                    (c.oracle.profile, C_OPT, "oracle (verified)", "--")):
        if prof is None:
            continue
        t = sample_times(prof, 4 * MAX_POINTS)
        s, v, _, _ = prof.state(t)
        s, v = _thin(s, v)
        ax.plot(s, v, color=colour, lw=1.4, ls=ls, label=label)
        vmax = max(vmax, float(np.max(v)))
    if c.path.n_segments:
        sg = np.unique(np.concatenate([np.linspace(0, L, 2 * MAX_POINTS),
                                       c.path.s_breaks[:-1] + 1e-9, c.path.s_breaks[1:] - 1e-9]))
        sg = np.clip(sg, 0, L)
        lc = limit_curve(c.path, c.limits, sg)["limit"]
        cap = 1.25 * vmax
        ax.fill_between(sg, np.minimum(lc, cap), cap, color="#e8e8e8", lw=0,
                        label="above the limit curve")
        ax.plot(sg, np.minimum(lc, cap), color=C_LIM, lw=0.8,
                label="limit curve (feed, axis velocity, centripetal acceleration)")
        sc, vc = corner_limits(c)
        if sc.size:
            ax.plot(sc, np.minimum(vc, cap), "v", color=C_LIM, ms=4, ls="none",
                    label="corner limit (velocity jump, MD32310)")
        ax.set_ylim(0, cap)
    stops = [c.path.s_breaks[k] for k in range(1, c.path.n_segments) if c.path.stop[k]]
    for sx in stops:
        ax.axvline(sx, color="#999", lw=0.6, ls=":")
    ax.set_xlim(0, max(L, 1e-9))
    ax.set_xlabel("path length s [mm]")
    ax.set_ylabel("path speed [mm/s]")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=3, fontsize=8,
              frameon=False)
    return _svg_uri(fig)


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


def plot_axes(c: Comparison) -> str:
    """Axis acceleration and jerk over time for both planners (SVG URI)."""
    lim = c.limits.for_axes(c.path.axes)
    profs = [(f"{_who(c)}", c.reference_profile)]
    if c.oracle.profile is not None:
        profs.append(("oracle (verified)", c.oracle.profile))
    fig = Figure(figsize=(11, 5.6))
    axs = fig.subplots(2, len(profs), sharex=True, sharey="row", squeeze=False)
    t_end = max(p.duration for _, p in profs)
    q_all = c.path.evaluate(np.linspace(0, c.path.total_length, 400))[0] \
        if c.path.n_segments else np.zeros((1, c.path.n_axes))
    moving = [i for i in range(c.path.n_axes) if np.ptp(q_all[:, i]) > 1e-9]
    for col, (name, prof) in enumerate(profs):
        t = sample_times(prof, 4 * MAX_POINTS)
        m = axis_motion(c.path, prof, t)
        for i in moving:
            colour = AXIS_COLOURS[i % len(AXIS_COLOURS)]
            unit = "deg" if c.path.rotary[i] else "m"
            tt, acc, jer = _thin(m.t, m.acc[:, i], m.jerk[:, i])
            axs[0, col].plot(tt, acc / 1e3, color=colour, lw=1.0,
                             label=f"{c.path.axes[i]}")
            axs[1, col].plot(tt, jer / 1e3, color=colour, lw=1.0, label=c.path.axes[i])
            for row, limit in ((0, lim.a_max[i]), (1, lim.j_max[i])):
                for sgn in (1, -1):
                    axs[row, col].axhline(sgn * limit / 1e3, color=colour, lw=0.7, ls=":")
        axs[0, col].set_title(name, fontsize=10)
        axs[1, col].set_xlabel("time [s]")
        for row in (0, 1):
            axs[row, col].grid(alpha=0.3)
            axs[row, col].set_xlim(0, max(t_end, 1e-9))
    axs[0, 0].set_ylabel("axis acceleration [m/s²]")
    axs[1, 0].set_ylabel("axis jerk [m/s³]")
    jmax = max((lim.j_max[i] for i in moving), default=1.0) / 1e3
    axs[1, 0].set_ylim(-2.5 * jmax, 2.5 * jmax)
    axs[0, -1].legend(loc="upper right", fontsize=8, title="axis (dotted: ± limit)",
                      title_fontsize=8)
    fig.tight_layout()
    return _svg_uri(fig)


def plot_gaps(c: Comparison) -> str:
    """Per-block gap bars in program order (SVG URI)."""
    rows = [r for r in c.rows if r.length_mm > 0 or r.t_reference_s > 0 or r.t_oracle_s > 0]
    fig = Figure(figsize=(11, 3.2))
    ax = fig.add_subplot()
    if rows:
        x = np.arange(len(rows))
        gap = np.array([1e3 * r.gap_s for r in rows])
        gap = np.nan_to_num(gap)
        colours = [C_INS if r.inserted else (C_REF if g >= 0 else C_OPT)
                   for r, g in zip(rows, gap)]
        if len(rows) <= 200:
            ax.bar(x, gap, color=colours, width=0.85, lw=0)
        else:                                 # two polygons, not thousands of bars
            ax.fill_between(x, 0, np.maximum(gap, 0), step="mid", color=C_REF, lw=0)
            ax.fill_between(x, 0, np.minimum(gap, 0), step="mid", color=C_OPT, lw=0)
        ax.axhline(0, color="#333", lw=0.7)
        step = max(1, int(math.ceil(len(rows) / 40)))
        ax.set_xticks(x[::step])
        ax.set_xticklabels([str(r.line) for r in rows][::step], fontsize=7, rotation=90)
        ax.set_xlim(-0.6, len(rows) - 0.4)
    ax.set_xlabel("block (source line), in program order")
    ax.set_ylabel("t_ref − t_opt [ms]")
    ax.grid(alpha=0.3, axis="y")
    return _svg_uri(fig)


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


def plot_toolpath(c: Comparison) -> str:
    """The tool path in its main plane with inserted and worst blocks marked (SVG URI)."""
    fig = Figure(figsize=(11, 6.0))
    ax = fig.add_subplot()
    path = c.path
    if path.n_segments == 0:
        ax.text(0.5, 0.5, "no path motion", ha="center", transform=ax.transAxes)
        return _svg_uri(fig)
    qs = path.evaluate(np.linspace(0, path.total_length, 500))[0]
    i, j = _plane(c, qs)
    worst = {r.block for r in c.worst_blocks(N_WORST)}
    # points of every segment (arcs finely), NaN-separated per drawing style
    n_pts = np.where(path.radius == 0, 2, np.clip(
        np.ceil(np.abs(path.omega) * path.length / 0.05).astype(np.int64), 8, 400))
    seg = np.repeat(np.arange(path.n_segments), n_pts)
    first = np.concatenate(([0], np.cumsum(n_pts)[:-1]))
    frac = (np.arange(seg.size) - first[seg]) / (n_pts[seg] - 1)
    s = path.s_breaks[seg] + frac * path.length[seg]
    q = path.evaluate(s, segment=seg)[0]
    kinds = np.array([KIND_CODES[int(k)] for k in path.kind])
    style_of = np.where(np.isin(path.block, list(worst)), "worst",
                        np.where(np.isin(kinds, INSERTED_KINDS), "inserted",
                                 np.where(path.rapid, "rapid", "program")))
    styles = {"program": dict(color="#2b3440", lw=1.1, zorder=2,
                              label="programmed (G1/G2/G3)"),
              "rapid": dict(color="#9aa0a8", lw=1.0, ls="--", zorder=2, label="rapid (G0)"),
              "inserted": dict(color=C_INS, lw=2.2, zorder=3,
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
        ax.plot(x, y, **style)
    for r in c.worst_blocks(N_WORST):
        segs = np.flatnonzero(path.block == r.block)
        if segs.size == 0:
            continue
        mid = path.evaluate(path.s_breaks[segs[0]] + 0.5 * path.length[segs[0]])[0][0]
        ax.annotate(f"line {r.line}\n{1e3 * r.gap_s:+.0f} ms", (mid[i], mid[j]),
                    xytext=(8, 8), textcoords="offset points", fontsize=8,
                    color=C_WORST, zorder=5,
                    bbox=dict(boxstyle="round,pad=0.2", fc="white", ec=C_WORST, lw=0.6))
    stops = [k for k in range(path.n_segments + 1) if path.stop[k]]
    if stops:
        qb = path.evaluate(np.clip(path.s_breaks[stops], 0, path.total_length))[0]
        ax.plot(qb[:, i], qb[:, j], "s", ms=5, color="#111", zorder=6, label="required stop")
    q0 = path.evaluate(0.0)[0][0]
    ax.plot([q0[i]], [q0[j]], "o", ms=7, mfc="none", mec="#2ca02c", mew=2, zorder=6,
            label="start")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{path.axes[i]} [mm]")
    ax.set_ylabel(f"{path.axes[j]} [mm]")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8, framealpha=0.9)
    return _svg_uri(fig)


# --------------------------------------------------------------------- page
def _fmt(x: float, nd: int = 3) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "–"
    if isinstance(x, float) and math.isinf(x):
        return "∞"
    if abs(x) < 0.5 * 10.0 ** -nd:
        x = 0.0                                   # no "-0.0"
    return f"{x:.{nd}f}"


def _card(k: str, v: str, d: str = "") -> str:
    return (f'<div class="card"><div class="k">{_e(k)}</div><div class="v">{_e(v)}</div>'
            f'<div class="d">{_e(d)}</div></div>')


def _violations_html(c: Comparison) -> str:
    items = [(_who(c), v) for v in c.reference_violations] + \
        [("oracle", v) for v in c.oracle_violations]
    if not items:
        checked = ", ".join(BOUND_SETS[c.reference_bounds])
        return (f"<p>No violations: the {_e(_who(c))} profile keeps {_e(checked)}; the "
                f"oracle's verified profile keeps {_e(', '.join(BOUND_SETS[c.bounds]))} "
                f"(checked by <code>check_profile</code> inside every interval).</p>")
    lis = "".join(f'<li class="viol"><b>{_e(who)}</b>: {_e(describe_violation(v, c))}</li>'
                  for who, v in items)
    return f"<ul>{lis}</ul>"


def _info_ratios(c: Comparison) -> str:
    """Ratios of constraints the planner does not declare (information, not violations)."""
    declared = set(BOUND_SETS[c.reference_bounds])
    out = []
    for r in c.reference_report.results:
        if r.constraint not in declared and r.ratio > 1.0 + 1e-6 and r.constraint in (
                "jerk", "frequency"):
            ratio = "∞" if not math.isfinite(r.ratio) else f"{r.ratio:.2f}"
            out.append(f"{r.constraint} ratio {ratio}")
    if not out:
        return ""
    return (f"<p class='sub'>Not declared by the {_e(_who(c))} (its {_e(c.reference_bounds)} "
            f"bound set), shown for information: {_e('; '.join(out))}.</p>")


def _table(c: Comparison) -> str:
    worst = {r.block for r in c.worst_blocks(N_WORST)}
    head = ("<thead><tr><th class='t'>line</th><th class='t'>label</th><th class='t'>kind</th>"
            "<th>length mm</th><th>t ref s</th><th>t opt s</th><th>hold s</th>"
            "<th class='t'>hold</th><th>gap ms</th><th>gap %</th>"
            "<th>v in ref</th><th>v out ref</th><th>v peak ref</th>"
            "<th>v in opt</th><th>v out opt</th><th>v peak opt</th>"
            "<th class='t'>limit ref</th><th class='t'>limit opt</th><th>ratio ref</th>"
            "<th class='t'>stop</th><th class='t'>note</th><th class='t'>source</th>"
            "</tr></thead>")
    body = []
    for r in c.rows:
        cls = []
        if r.gap_s < -1e-6:
            cls.append("neg")
        elif r.gap_s > 1e-6:
            cls.append("pos")
        if r.block in worst:
            cls.append("worst")
        if r.inserted:
            cls.append("ins")
        idle = r.length_mm <= 0 and r.t_reference_s <= 0 and not (r.t_oracle_s > 0)
        if idle:
            cls.append("idle")
        kind = r.kind if not r.corner else f"{r.kind} (corner {r.corner[0]}/{r.corner[1]})"
        gap_ms = 1e3 * r.gap_s
        gap_pct = 100 * r.gap_rel
        src = r.source if len(r.source) <= 60 else r.source[:57] + "…"

        def num(x: float, nd: int) -> str:
            v = "" if (isinstance(x, float) and math.isnan(x)) else repr(float(x))
            return f"<td data-v='{v}'>{_fmt(x, nd)}</td>"

        body.append(
            f"<tr class='{' '.join(cls)}'>"
            f"<td class='t' data-v='{r.line}'><a href='#L{r.line}'>{r.line}</a></td>"
            f"<td class='t'>{_e(r.label)}</td><td class='t'>{_e(kind)}</td>"
            f"{num(r.length_mm, 3)}{num(r.t_reference_s, 4)}{num(r.t_oracle_s, 4)}"
            f"{num(r.hold_s, 4)}<td class='t'>{_e(r.hold_cause)}</td>"
            f"<td class='gap' data-v='{'' if math.isnan(gap_ms) else repr(gap_ms)}'>{_fmt(gap_ms, 1)}</td>"
            f"{num(gap_pct, 1)}"
            f"{num(r.v_entry_reference, 1)}{num(r.v_exit_reference, 1)}{num(r.v_peak_reference, 1)}"
            f"{num(r.v_entry_oracle, 1)}{num(r.v_exit_oracle, 1)}{num(r.v_peak_oracle, 1)}"
            f"<td class='t'>{_e(r.limit_reference)}</td><td class='t'>{_e(r.limit_oracle)}</td>"
            f"{num(r.ratio_reference, 3) if not idle else '<td>–</td>'}"
            f"<td class='t'>{_e(r.stop_reason)}</td><td class='note'>{_e(r.note)}</td>"
            f"<td class='t'><code>{_e(src)}</code></td></tr>")
    n_idle = sum(1 for r in c.rows if r.length_mm <= 0 and r.t_reference_s <= 0
                 and not (r.t_oracle_s > 0))
    toggle = (f"<label class='sub'><input type='checkbox' id='show-idle'> show the {n_idle} "
              f"blocks without motion or time (assignments, modal settings)</label>"
              if n_idle else "")
    return (f"{toggle}<div class='tablewrap'><table class='sortable hide-idle' id='blocks'>"
            f"{head}<tbody>{''.join(body)}</tbody></table></div>")


def _source(c: Comparison) -> str:
    if not c.program_lines:
        return "<p class='sub'>(program text not available)</p>"
    hot = {r.line for r in c.worst_blocks(N_WORST)}
    out = []
    for n, text in enumerate(c.program_lines, start=1):
        cls = " class='hot'" if n in hot else ""
        out.append(f"<span id='L{n}'{cls}><a href='#L{n}'>{n}</a>{_e(text)}</span>")
    return f"<pre class='src'>{''.join(out)}</pre>"


def render_report(c: Comparison, *, max_gap: float | None = None,
                  links: Mapping[str, str] | None = None, title: str | None = None) -> str:
    """The HTML page of one comparison.

    Parameters
    ----------
    c : Comparison
    max_gap : float, optional
        The CI gate (fraction) the verdict is taken against.
    links : Mapping[str, str], optional
        Extra links shown in the header (label -> relative URL), e.g. the JSON/CSV files.
    title : str, optional
        Page title (default: the program name).

    Returns
    -------
    str
        A complete, self-contained HTML document.
    """
    v = c.verdict(max_gap)
    who = _who(c)
    name = title or c.program
    o = c.oracle
    gap = format_interval(c) if c.certified else "unknown"
    gap_d = ("t_ref/UB − 1 … t_ref/LB − 1" if c.hold_s <= 0 else
             f"motion times: (t_ref − H)/(UB − H) − 1 … (t_ref − H)/(LB − H) − 1, "
             f"H = {c.hold_s:.4f} s of dwell and exact-stop settle on both sides") + (
        "" if c.gap_lower_valid else " (lower end: vs. the relaxation)")
    cards = "".join([
        _card(f"{who} time", f"{c.t_reference_s:.4f} s",
              f"bound set {c.reference_bounds}; {len(c.reference_violations)} violation(s)"),
        _card("optimal time", f"{_fmt(o.lower_bound_s, 4)} – {_fmt(o.upper_bound_s, 4)} s",
              f"oracle ({o.bounds}): {o.status}, {o.grid_points} grid points, "
              f"{o.solve_time_s:.2f} s"),
        _card("gap to optimum", gap, gap_d),
        _card("path", f"{c.path.total_length:.1f} mm",
              f"{sum(1 for r in c.rows if r.length_mm > 0)} moving blocks, "
              f"{sum(1 for r in c.rows if r.inserted)} inserted"),
    ])
    link_html = " · ".join(f"<a href='{_e(u)}'>{_e(k)}</a>" for k, u in (links or {}).items())
    notes = "".join(f"<li>{_e(n)}</li>" for n in c.notes)
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    speed = _figure(plot_speed(c), "path speed over path length",
                    f"Path speed of the {_e(who)} (solid red) and of the oracle's verified "
                    "profile (dashed blue) over path length, under the limit curve for "
                    "constant-speed motion (programmed feed, axis velocities, centripetal "
                    "acceleration); dotted verticals are required stops. The gap between "
                    "the two curves is where time is lost.", "speed")
    axes = _figure(plot_axes(c), "axis acceleration and jerk over time",
                   "Axis acceleration (top) and jerk (bottom) over time, per moving axis; "
                   "dotted lines are the axis limits. An acceleration-bounded motion "
                   "(BRISK, the acc oracle) has steps in acceleration, i.e. unbounded jerk "
                   "at those instants, which the jerk plot does not draw.", "axes")
    gaps = _figure(plot_gaps(c), "per-block gap bars",
                   f"Time lost per block, t_ref − t_opt: red where the {_e(who)} is slower, "
                   "blue where it is faster (see the notes in the table), orange for "
                   "inserted blocks.", "gaps")
    tool = _figure(plot_toolpath(c), "tool path",
                   "The path both planners run on, in its main plane: inserted blocks "
                   "orange, the blocks with the largest gaps violet (with the time they "
                   "lose), required stops as squares.", "path")
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>feedoracle – {_e(name)}</title><style>{_CSS}</style></head>
<body><main>
<h1>{_e(name)}</h1>
<div class="sub">machine {_e(c.machine)} · oracle bounds <b>{_e(o.bounds)}</b> ·
{_e(who)} bounds <b>{_e(c.reference_bounds)}</b> · {_e(stamp)}{' · ' + link_html if link_html else ''}</div>
<div class="verdict {'ok' if v.ok else 'fail'}">{'✔' if v.ok else '✘'} {_e(v.status)}: {_e(v.text)}</div>
<div class="cards">{cards}</div>
<h2>Violations</h2>{_violations_html(c)}{_info_ratios(c)}
{f'<h2>Notes</h2><ul class="notes">{notes}</ul>' if notes else ''}
<h2>Path speed</h2>{speed}
<h2>Axis acceleration and jerk</h2>{axes}
<h2>Time lost per block</h2>{gaps}
<h2>Tool path</h2>{tool}
<h2>Blocks</h2>
<p class="sub">One row per NC block; inserted blocks on their own rows with the corner
they replace. Click a column to sort, a line number to see the source. Gap = t_ref − t_opt
(t_opt from the oracle's verified profile, so the gaps sum to t_ref − UB); both times contain
the block's hold (dwell, exact-stop settle: the machine's wait, identical on both sides), which
is therefore never a gap; gap % is relative to the oracle's motion time; speeds in mm/s.</p>
{_table(c)}
<h2>Program</h2>{_source(c)}
<p class="sub">feedoracle · gap interval [(t_ref − H)/(UB − H) − 1, (t_ref − H)/(LB − H) − 1]
from the oracle's certified lower bound LB and verified upper bound UB (the true optimum lies
between them), on motion times: H, the imposed holds (dwell, exact-stop settle), is in every
total and not in the gap.</p>
</main><script>{_JS}</script></body></html>
"""


def write_report(file: str | FsPath, c: Comparison, *, max_gap: float | None = None,
                 links: Mapping[str, str] | None = None, title: str | None = None) -> FsPath:
    """Write :func:`render_report` to ``file`` (parents created); returns the path."""
    p = FsPath(file)
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(render_report(c, max_gap=max_gap, links=links, title=title),
                 encoding="utf-8")
    return p


def write_index(folder: str | FsPath, results: Sequence[tuple[str, Comparison]],
                max_gap: float | None = None) -> FsPath:
    """An index page linking every program's report, with the summary table.

    Parameters
    ----------
    folder : path
        Report folder (the pages are ``<stem>.html`` in it).
    results : sequence of (stem, Comparison)
    max_gap : float, optional
        The gate.

    Returns
    -------
    pathlib.Path
        The index file.
    """
    rows = []
    for stem, c in results:
        v = c.verdict(max_gap)
        gap = format_interval(c) if c.certified else "unknown"
        rows.append(
            f"<tr class='{'pos' if not v.ok else ''}'><td class='t'><a href='{_e(stem)}.html'>"
            f"{_e(c.program)}</a></td><td data-v='{c.t_reference_s!r}'>{c.t_reference_s:.4f}</td>"
            f"<td>{_fmt(c.oracle.lower_bound_s, 4)}</td><td>{_fmt(c.oracle.upper_bound_s, 4)}</td>"
            f"<td data-v='{c.gap_upper!r}'>{_e(gap)}</td>"
            f"<td>{len(c.reference_violations)}</td>"
            f"<td class='t'>{'✔ ok' if v.ok else '✘ ' + _e(v.status)}</td>"
            f"<td class='t'><a href='{_e(stem)}.json'>json</a> · <a href='{_e(stem)}.csv'>csv</a></td></tr>")
    n_fail = sum(1 for _, c in results if not c.verdict(max_gap).ok)
    gate = f" · gate: gap upper end ≤ {100 * max_gap:g} %" if max_gap is not None else ""
    doc = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>feedoracle – {len(results)} programs</title>
<style>{_CSS}</style></head><body><main>
<h1>feedoracle: {len(results)} programs</h1>
<div class="sub">{len(results) - n_fail} ok, {n_fail} failing{_e(gate)}</div>
<div class="verdict {'ok' if not n_fail else 'fail'}">{'✔ all programs pass' if not n_fail else f'✘ {n_fail} program(s) fail'}</div>
<div class='tablewrap'><table class="sortable"><thead><tr><th class='t'>program</th><th>t ref s</th>
<th>LB s</th><th>UB s</th><th>gap</th><th>violations</th><th class='t'>verdict</th><th class='t'>data</th></tr></thead>
<tbody>{''.join(rows)}</tbody></table></div>
</main><script>{_JS}</script></body></html>
"""
    p = FsPath(folder) / "index.html"
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(doc, encoding="utf-8")
    return p

"""The report page: summary, banner, plots, the block table and the program listing.

A page needs no network: plots are SVG ``data:`` URIs (:mod:`compare.report.plots`), CSS
and the table-sorting script are inline. Every piece of text that comes from the program
or the user (file names, comments, labels, notes) is HTML-escaped.

The page stays small and quick to open whatever the program size: the plots are reduced
to the screen's resolution, the block table shows at most :data:`MAX_TABLE_ROWS` rows
(the blocks with the largest gaps; every row is in the JSON and CSV), and the listing of
a long program only the lines the table links to, with context.
"""

from __future__ import annotations

import html
import math
from datetime import datetime, timezone
from pathlib import Path as FsPath
from typing import Mapping, Sequence

from reference.core.constraints import BOUND_SETS

from ..result import (GAP_ABS_TOL_S, ComparedBlock, Comparison, Verdict, describe_violation,
                      format_interval)
from .plots import (N_WORST, dense, moving_rows, plot_axes, plot_gaps, plot_speed,
                    plot_toolpath, who)

#: The rows the block table shows, see :func:`table_rows`.
Shown = tuple[list[tuple[int | None, ComparedBlock]], bool]

#: Block table: all rows up to this many, else the rows with the largest gaps (a table
#: of 10^5 rows is ~150 MB of HTML and takes a browser minutes to lay out).
MAX_TABLE_ROWS = 500
#: Program listing: shown whole up to this many lines, else only the lines the table
#: links to (with context) and the program head.
MAX_LISTING_LINES = 2000
#: Lines shown around each linked line in a shortened listing.
LISTING_CONTEXT = 2
#: First lines of a long program always shown (its settings: G90, feed, modes).
LISTING_HEAD = 10

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
.verdict.warn{background:#fff4d6;border:1px solid #e6c36a;color:#6b4b00}
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
pre.src span.skip{color:#8a919c;font-style:italic;background:#f4f5f7}
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


def _figure(uri: str, alt: str, caption: str, name: str) -> str:
    return (f'<figure id="fig-{name}"><img class="plot" alt="{_e(alt)}" src="{uri}">'
            f"<figcaption>{caption}</figcaption></figure>")


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


# --------------------------------------------------------------------- banner
def bracket(c: Comparison) -> float:
    """Relative width of the oracle's bracket, ``UB/LB − 1`` (``nan`` without bounds)."""
    lb, ub = c.oracle.lower_bound_s, c.oracle.upper_bound_s
    return ub / lb - 1.0 if math.isfinite(lb) and math.isfinite(ub) and lb > 0 else math.nan


def banner(c: Comparison, v: Verdict) -> tuple[str, str]:
    """CSS class and text of the verdict banner.

    A passing program is green only when the oracle reached its tolerance; otherwise
    (status ``gap_not_met``, ...) the banner is amber, names the status and says how wide
    the bracket ``UB/LB − 1`` is, since the gap interval is then only as tight as that.
    It is amber too where the oracle solved a stricter bound set than the planner keeps
    and the planner breaks what it adds (:attr:`Comparison.stricter_violations`).

    Returns
    -------
    cls, text : str
        ``"ok"``, ``"warn"`` or ``"fail"``, and the (unescaped) text.
    """
    o = c.oracle
    loose = ""
    if o.status != "optimal":
        b = bracket(c)
        width = f"{100 * b:.1f} %" if math.isfinite(b) else "unknown"
        loose = (f"the oracle did not reach its tolerance (status {o.status}): its bounds "
                 f"bracket the optimum only to UB/LB − 1 = {width}")
    if not v.ok:
        return "fail", f"✘ {v.status}: {v.text}" + (f"; {loose}" if loose and
                                                       c.certified else "")
    if loose:
        return "warn", f"⚠ {v.status}, with a wide bracket: {loose}; {v.text}"
    if c.stricter_violations:
        # not like with like: the gap is to an optimum the planner is not held to
        return "warn", f"⚠ {v.status}, against a stricter bound set: {v.text}"
    return "ok", f"✔ {v.status}: {v.text}"


def _short_verdict(c: Comparison, v: Verdict) -> str:
    """The verdict in a few words, for the index table."""
    if not v.ok:
        return f"✘ {v.status}"
    if c.oracle.status != "optimal":
        b = bracket(c)
        width = f"{100 * b:.1f} %" if math.isfinite(b) else "unknown"
        return f"⚠ ok, bracket {width} ({c.oracle.status})"
    if c.stricter_violations:
        return f"⚠ ok, against stricter {c.oracle.bounds}"
    return "✔ ok"


def _violations_html(c: Comparison) -> str:
    items = [(who(c), v) for v in c.reference_violations] + \
        [("oracle", v) for v in c.oracle_violations]
    if not items:
        checked = ", ".join(BOUND_SETS[c.reference_bounds])
        return (f"<p>No violations: the {_e(who(c))} profile keeps {_e(checked)}; the "
                f"oracle's verified profile keeps {_e(', '.join(BOUND_SETS[c.bounds]))} "
                f"(checked by <code>check_profile</code> inside every interval).</p>")
    lis = "".join(f'<li class="viol"><b>{_e(w)}</b>: {_e(describe_violation(v, c))}</li>'
                  for w, v in items)
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
    return (f"<p class='sub'>Not declared by the {_e(who(c))} (its {_e(c.reference_bounds)} "
            f"bound set), shown for information: {_e('; '.join(out))}.</p>")


# --------------------------------------------------------------------- table
def table_rows(c: Comparison) -> Shown:
    """The rows the block table shows, each with its place in execution order.

    Returns
    -------
    rows : list of (int or None, ComparedBlock)
        1-based position among the blocks with motion (the gap plot's x; ``None`` for
        blocks without motion or time) and the row.
    limited : bool
        True when the program has more than :data:`MAX_TABLE_ROWS` rows: then the rows
        are those with motion and the largest gaps, largest first; otherwise every row
        in program order.
    """
    order = {id(r): k for k, r in enumerate(moving_rows(c), start=1)}
    if len(c.rows) <= MAX_TABLE_ROWS:
        return [(order.get(id(r)), r) for r in c.rows], False
    moving = [r for r in c.rows if id(r) in order]
    key = [(-(r.gap_s if not math.isnan(r.gap_s) else -math.inf), order[id(r)])
           for r in moving]
    pick = sorted(range(len(moving)), key=key.__getitem__)[:MAX_TABLE_ROWS]
    return [(order[id(moving[k])], moving[k]) for k in pick], True


def _table(c: Comparison, links: Mapping[str, str] | None, shown: Shown,
           worst: Sequence[ComparedBlock]) -> str:
    worst = {r.block for r in worst}
    rows, limited = shown
    gap_sort = " class='sorted-desc'" if limited else ""
    head = ("<thead><tr><th title='place in execution order (the x of the gap plot)'>#</th>"
            "<th class='t'>line</th><th class='t'>label</th><th class='t'>kind</th>"
            "<th>length mm</th><th>t ref s</th><th>t opt s</th><th>hold s</th>"
            f"<th class='t'>hold</th><th{gap_sort}>gap ms</th><th>gap %</th>"
            "<th>v in ref</th><th>v out ref</th><th>v peak ref</th>"
            "<th>v in opt</th><th>v out opt</th><th>v peak opt</th>"
            "<th class='t'>limit ref</th><th class='t'>limit opt</th><th>ratio ref</th>"
            "<th class='t'>stop</th><th class='t' title='the rounding stage at the corner "
            "this block ends in (G641..G645, RND/RNDM): rounded, or why not'>rounding</th>"
            "<th class='t'>note</th><th class='t'>source</th>"
            "</tr></thead>")

    def num(x: float, nd: int) -> str:
        v = "" if (isinstance(x, float) and math.isnan(x)) else repr(float(x))
        return f"<td data-v='{v}'>{_fmt(x, nd)}</td>"

    body = []
    for pos, r in rows:
        cls = []
        if r.gap_s < -GAP_ABS_TOL_S:
            cls.append("neg")
        elif r.gap_s > GAP_ABS_TOL_S:
            cls.append("pos")
        if r.block in worst:
            cls.append("worst")
        if r.inserted:
            cls.append("ins")
        idle = pos is None
        if idle:
            cls.append("idle")
        kind = r.kind if not r.corner else f"{r.kind} (corner {r.corner[0]}/{r.corner[1]})"
        gap_ms = 1e3 * r.gap_s
        src = r.source if len(r.source) <= 60 else r.source[:57] + "…"
        body.append(
            f"<tr class='{' '.join(cls)}'>"
            f"<td data-v='{pos if pos is not None else ''}'>{pos if pos is not None else '–'}</td>"
            f"<td class='t' data-v='{r.line}'><a href='#L{r.line}'>{r.line}</a></td>"
            f"<td class='t'>{_e(r.label)}</td><td class='t'>{_e(kind)}</td>"
            f"{num(r.length_mm, 3)}{num(r.t_reference_s, 4)}{num(r.t_oracle_s, 4)}"
            f"{num(r.hold_s, 4)}<td class='t'>{_e(r.hold_cause)}</td>"
            f"<td class='gap' data-v='{'' if math.isnan(gap_ms) else repr(gap_ms)}'>"
            f"{_fmt(gap_ms, 1)}</td>{num(100 * r.gap_rel, 1)}"
            f"{num(r.v_entry_reference, 1)}{num(r.v_exit_reference, 1)}"
            f"{num(r.v_peak_reference, 1)}{num(r.v_entry_oracle, 1)}"
            f"{num(r.v_exit_oracle, 1)}{num(r.v_peak_oracle, 1)}"
            f"<td class='t'>{_e(r.limit_reference)}</td><td class='t'>{_e(r.limit_oracle)}</td>"
            f"{num(r.ratio_reference, 3) if not idle else '<td>–</td>'}"
            f"<td class='t'>{_e(r.stop_reason)}</td><td class='t'>{_e(r.rounding)}</td>"
            f"<td class='note'>{_e(r.note)}</td>"
            f"<td class='t'><code>{_e(src)}</code></td></tr>")
    if limited:
        data = " and ".join(f"<a href='{_e(u)}'>{_e(k)}</a>" for k, u in (links or {}).items())
        where = (f"in the {data} next to this page" if data else
                 "in the JSON and CSV that <code>feedoracle compare --report DIR</code> "
                 "(or <code>--json</code>) writes")
        intro = (f"<p class='sub' id='table-limited'>Showing the {len(rows)} blocks with the "
                 f"largest gaps of {len(c.rows)} rows (largest first; click a header to "
                 f"re-sort, <b>#</b> for execution order). The full data, one row per "
                 f"block, is {where}.</p>")
        return (f"{intro}<div class='tablewrap'><table class='sortable' id='blocks'>"
                f"{head}<tbody>{''.join(body)}</tbody></table></div>")
    n_idle = sum(1 for pos, _ in rows if pos is None)
    toggle = (f"<label class='sub'><input type='checkbox' id='show-idle'> show the {n_idle} "
              f"blocks without motion or time (assignments, modal settings)</label>"
              if n_idle else "")
    return (f"{toggle}<div class='tablewrap'><table class='sortable hide-idle' id='blocks'>"
            f"{head}<tbody>{''.join(body)}</tbody></table></div>")


# --------------------------------------------------------------------- listing
def listing_lines(c: Comparison, shown: Shown | None = None) -> list[int]:
    """1-based program lines the listing shows (sorted): all of a short program; of a
    long one the head, and every line the table links to with its context."""
    n = len(c.program_lines)
    if n <= MAX_LISTING_LINES:
        return list(range(1, n + 1))
    want = set(range(1, min(LISTING_HEAD, n) + 1))
    rows, _ = table_rows(c) if shown is None else shown
    for _, r in rows:
        for line in (r.line, *(r.corner or ())):
            want.update(range(max(1, line - LISTING_CONTEXT),
                              min(n, line + LISTING_CONTEXT) + 1))
    return sorted(want)


def _source(c: Comparison, shown: Shown, worst: Sequence[ComparedBlock]) -> str:
    if not c.program_lines:
        return "<p class='sub'>(program text not available)</p>"
    hot = {r.line for r in worst}
    shown = listing_lines(c, shown)
    out = []
    prev = 0
    for n in shown:
        if n > prev + 1:
            out.append(f"<span class='skip'>⋮ lines {prev + 1}–{n - 1} not shown</span>")
        cls = " class='hot'" if n in hot else ""
        out.append(f"<span id='L{n}'{cls}><a href='#L{n}'>{n}</a>"
                   f"{_e(c.program_lines[n - 1])}</span>")
        prev = n
    total = len(c.program_lines)
    if prev < total:
        out.append(f"<span class='skip'>⋮ lines {prev + 1}–{total} not shown</span>")
    note = "" if len(shown) == total else (
        f"<p class='sub'>{len(shown)} of {total} lines: the program head and the lines "
        f"of the blocks in the table, ±{LISTING_CONTEXT} lines.</p>")
    return f"{note}<pre class='src'>{''.join(out)}</pre>"


# --------------------------------------------------------------------- page
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
    w = who(c)
    name = title or c.program
    o = c.oracle
    gap = format_interval(c) if c.certified else "unknown"
    gap_d = ("t_ref/UB − 1 … t_ref/LB − 1" if c.hold_s <= 0 else
             f"motion times: (t_ref − H)/(UB − H) − 1 … (t_ref − H)/(LB − H) − 1, "
             f"H = {c.hold_s:.4f} s of dwell and exact-stop settle on both sides") + (
        "" if c.gap_lower_valid else " (lower end: vs. the relaxation)") + (
        f" (against the stricter {o.bounds} optimum, whose "
        f"{c.stricter_violations[0].constraint} limit the {w} breaks)"
        if c.certified and c.stricter_violations else "") + (
        f"; the {w}'s own motion meets the same limits and is faster than the oracle's, "
        "so the gap is at least 0" if c.certified and c.reference_bounds_optimum else "")
    cards = "".join([
        _card(f"{w} time", f"{c.t_reference_s:.4f} s",
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
    b_cls, b_text = banner(c, v)
    worst = c.worst_blocks(N_WORST)          # once: each call reads every row's gap
    shown = table_rows(c)
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    speed = _figure(plot_speed(c), "path speed over path length",
                    f"Path speed of the {_e(w)} (solid red) and of the oracle's verified "
                    "profile (dashed blue) over path length, under the limit curve for "
                    "constant-speed motion (programmed feed, axis velocities, centripetal "
                    "acceleration); dotted verticals are required stops. The gap between "
                    "the two curves is where time is lost. " + (
                        "The path has more segments than the plot has room for: the "
                        "bands are each planner's smallest to largest speed per pixel "
                        "column, the lines its mean speed there (column width over the "
                        "time spent in it; their ratio is the local gap), and the limit "
                        "curve is drawn as its highest and lowest value per column."
                        if dense(c) else "Every curve is a min/max envelope per pixel "
                        "column: all peaks of the data are drawn."), "speed")
    axes = _figure(plot_axes(c), "axis acceleration and jerk over time",
                   "Axis acceleration (top) and jerk (bottom) over time, per moving axis; "
                   "dotted lines are the axis limits. An acceleration-bounded motion "
                   "(BRISK, the acc oracle) has steps in acceleration, i.e. unbounded jerk "
                   "at those instants, which the jerk plot does not draw. Min/max "
                   "envelopes per pixel column, as above.", "axes")
    gaps = _figure(plot_gaps(c, worst), "per-block gap bars",
                   f"Time lost per block in execution order, t_ref − t_opt: red where the "
                   f"{_e(w)} is slower, blue where it is faster (see the notes in the "
                   "table), orange for inserted blocks (up to 200 blocks, drawn one bar "
                   "each; with more blocks than pixel columns each column shows the "
                   "largest and the most negative gap among its blocks, and the worst "
                   "blocks are labelled with their source line). The black line (right "
                   "axis) is the accumulated gap: its steep parts are where the total "
                   "time is lost.", "gaps")
    tool = _figure(plot_toolpath(c, worst), "tool path",
                   "The path both planners run on (dark), in its main plane, over the "
                   "programmed contour (light blue: the program's lines and arcs before "
                   "tool radius compensation and corner rounding, visible where the "
                   "planned path leaves it): inserted blocks orange, the blocks with the "
                   "largest gaps violet (with the time they lose), required stops as "
                   "squares.", "path")
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>feedoracle – {_e(name)}</title><style>{_CSS}</style></head>
<body><main>
<h1>{_e(name)}</h1>
<div class="sub">machine {_e(c.machine)} · oracle bounds <b>{_e(o.bounds)}</b> ·
{_e(w)} bounds <b>{_e(c.reference_bounds)}</b> · {_e(stamp)}{' · ' + link_html if link_html else ''}</div>
<div class="verdict {b_cls}" id="verdict">{_e(b_text)}</div>
<div class="cards">{cards}</div>
<h2>Violations</h2>{_violations_html(c)}{_info_ratios(c)}
{f'<h2>Notes</h2><ul class="notes">{notes}</ul>' if notes else ''}
<h2>Path speed</h2>{speed}
<h2>Axis acceleration and jerk</h2>{axes}
<h2>Time lost per block</h2>{gaps}
<h2>Tool path</h2>{tool}
<h2>Blocks</h2>
<p class="sub">One row per NC block; inserted blocks on their own rows with the corner
they replace. Click a column to sort, a line number to see the source; # is the block's place
in execution order (the x axis of the gap plot). Gap = t_ref − t_opt
(t_opt from the oracle's verified profile, so the gaps sum to t_ref − UB); both times contain
the block's hold (dwell, exact-stop settle: the machine's wait, identical on both sides), which
is therefore never a gap; gap % is relative to the oracle's motion time; speeds in mm/s.</p>
{_table(c, links, shown, worst)}
<h2>Program</h2>{_source(c, shown, worst)}
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
            f"<td class='t'>{_e(_short_verdict(c, v))}</td>"
            f"<td class='t'><a href='{_e(stem)}.json'>json</a> · <a href='{_e(stem)}.csv'>csv</a></td></tr>")
    n_fail = sum(1 for _, c in results if not c.verdict(max_gap).ok)
    n_loose = sum(1 for _, c in results
                  if c.verdict(max_gap).ok and c.oracle.status != "optimal")
    loose = (f" ({n_loose} with a bracket wider than the oracle's tolerance)"
             if n_loose else "")
    gate = f" · gate: gap upper end ≤ {100 * max_gap:g} %" if max_gap is not None else ""
    doc = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>feedoracle – {len(results)} programs</title>
<style>{_CSS}</style></head><body><main>
<h1>feedoracle: {len(results)} programs</h1>
<div class="sub">{len(results) - n_fail} ok, {n_fail} failing{_e(gate)}</div>
<div class="verdict {'fail' if n_fail else 'warn' if n_loose else 'ok'}">{'✔ all programs pass' if not n_fail else f'✘ {n_fail} program(s) fail'}{_e(loose)}</div>
<div class='tablewrap'><table class="sortable"><thead><tr><th class='t'>program</th><th>t ref s</th>
<th>LB s</th><th>UB s</th><th>gap</th><th>violations</th><th class='t'>verdict</th><th class='t'>data</th></tr></thead>
<tbody>{''.join(rows)}</tbody></table></div>
</main><script>{_JS}</script></body></html>
"""
    p = FsPath(folder) / "index.html"
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(doc, encoding="utf-8")
    return p

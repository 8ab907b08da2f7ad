"""Reports that open: plots reduced to the screen, a limited table and listing, a page
whose size does not grow with the program, and a banner that never hides a wide bracket.
"""

from __future__ import annotations

import base64
import re

import numpy as np
import pytest

from conftest import SMALL, path_of
from fakes import FakeSolution, fake_plan, fake_solution
from large import mixed_comparison

from compare.comparison import compare
from compare.report.envelope import (N_COLUMNS, chunked_envelopes, column_extremes,
                                     envelope, envelope_indices)
from compare.report.page import (LISTING_HEAD, MAX_LISTING_LINES, MAX_TABLE_ROWS,
                                 render_report, write_index)
from compare.report.plots import MAX_LINE_TICKS, moving_rows, plot_gaps
from optimal import SolveStatus


# --------------------------------------------------------------------- envelope
def _spiky(n: int, seed: int = 3):
    """Smooth noise in [-1, 1] with one spike of +7 and one dip of -5 at single samples."""
    rng = np.random.default_rng(seed)
    x = np.linspace(0.0, 100.0, n)
    y = 0.8 * np.sin(x) + 0.2 * rng.uniform(-1, 1, n)
    k_up, k_dn = n // 8 + 1, (2 * n) // 3 + 1
    y[k_up], y[k_dn] = 7.0, -5.0
    return x, y, k_up, k_dn


def test_envelope_keeps_a_single_sample_spike():
    x, y, k_up, k_dn = _spiky(1_000_003)
    xe, ye = envelope(x, y, 0.0, 100.0)
    assert xe.size <= 2 * N_COLUMNS                  # the size of the screen, not the data
    assert ye.max() == 7.0 and xe[np.argmax(ye)] == x[k_up]
    assert ye.min() == -5.0 and xe[np.argmin(ye)] == x[k_dn]
    assert np.all(np.diff(xe) >= 0)                  # still a left-to-right polyline
    # striding to the same number of points loses the spike (why the envelope exists)
    stride = y[::y.size // xe.size]
    assert stride.max() < 7.0


def test_envelope_keeps_every_columns_extremes():
    # 4 columns over [0, 4), 3 samples each (12 > 2 * 4, so it reduces): per column the
    # smallest and the largest sample survive, in their original order
    x = np.repeat(np.arange(4.0), 3) + np.tile([0.1, 0.5, 0.9], 4)
    y = np.array([3, 1, 2, 5, 6, 4, 9, 7, 8, 0, 2, 1], dtype=float)
    keep = envelope_indices(x, y, 0.0, 4.0, n_columns=4)
    assert keep.tolist() == [0, 1, 4, 5, 6, 7, 9, 10]
    # unsorted x (the general path) keeps the same samples
    perm = np.random.default_rng(0).permutation(x.size)
    keep_p = envelope_indices(x[perm], y[perm], 0.0, 4.0, n_columns=4)
    assert sorted(perm[keep_p].tolist()) == [0, 1, 4, 5, 6, 7, 9, 10]


def test_envelope_ignores_non_finite_samples():
    x = np.linspace(0, 1, 10_000)
    y = np.sin(40 * x)
    y[17] = np.nan
    y[99] = np.inf
    xe, ye = envelope(x, y, 0.0, 1.0)
    assert np.all(np.isfinite(ye)) and ye.max() <= 1.0


def test_column_extremes_by_hand():
    xc, lo, hi = column_extremes([0.1, 0.2, 2.5, 2.6, 2.7], [1.0, -2.0, 5.0, 3.0, 4.0],
                                 0.0, 3.0, 3)
    assert xc.tolist() == [0.5, 1.5, 2.5]
    assert lo[0] == -2.0 and hi[0] == 1.0
    assert np.isnan(lo[1]) and np.isnan(hi[1])       # an empty column
    assert lo[2] == 3.0 and hi[2] == 5.0


def test_chunked_envelopes_equal_the_whole_envelope():
    x, y, k_up, k_dn = _spiky(500_001)

    def series(idx):
        yield x[idx], y[idx]
        yield x[idx], -y[idx]

    (xa, ya), (xb, yb) = chunked_envelopes(np.arange(x.size), series, 0.0, 100.0,
                                           chunk=70_001)
    xe, ye = envelope(x, y, 0.0, 100.0)
    _, lo, hi = column_extremes(x, y, 0.0, 100.0)
    _, lo_a, hi_a = column_extremes(xa, ya, 0.0, 100.0)
    assert np.array_equal(lo, lo_a) and np.array_equal(hi, hi_a)
    assert ya.max() == 7.0 and yb.max() == 5.0


# --------------------------------------------------------------------- banner
def _with_bounds(machine, status, ratio):
    program, path = path_of(SMALL, machine)
    good = fake_solution(path, machine.limits)
    sol = FakeSolution(status, good.profile, good.upper_bound_s / ratio, good.upper_bound_s)
    return compare(fake_plan(path, machine.limits), sol, program=program)


def _banner(html: str) -> re.Match:
    m = re.search(r'<div class="verdict (\w+)" id="verdict">([^<]*)</div>', html)
    assert m, "no verdict banner"
    return m


def test_banner_names_a_wide_bracket_and_is_not_green(machine):
    c = _with_bounds(machine, SolveStatus.GAP_NOT_MET, 1.16)      # UB/LB - 1 = 16 %
    assert c.verdict().ok                       # the gate passes on the upper end ...
    m = _banner(render_report(c))
    cls, text = m.group(1), m.group(2)
    assert cls == "warn"                        # ... but the banner is not green
    assert "gap_not_met" in text and "UB/LB − 1 = 16.0 %" in text
    assert not text.startswith("✔")


def test_banner_green_only_when_the_oracle_met_its_tolerance(machine):
    c = _with_bounds(machine, SolveStatus.OPTIMAL, 1.002)
    m = _banner(render_report(c))
    assert m.group(1) == "ok" and m.group(2).startswith("✔ ok:")
    assert "bracket" not in m.group(2)


def test_failing_banner_with_wide_bracket_says_both(machine):
    c = _with_bounds(machine, SolveStatus.GAP_NOT_MET, 1.16)
    m = _banner(render_report(c, max_gap=1e-4))
    assert m.group(1) == "fail" and "gap above gate" in m.group(2)
    assert "UB/LB − 1 = 16.0 %" in m.group(2)


def test_index_names_the_bracket(machine, tmp_path):
    c = _with_bounds(machine, SolveStatus.GAP_NOT_MET, 1.16)
    index = write_index(tmp_path, [("a", c)]).read_text()
    assert "⚠ ok, bracket 16.0 % (gap_not_met)" in index
    assert '<div class="verdict warn">' in index and "✔ all programs pass" in index


# --------------------------------------------------------------------- size and table
@pytest.fixture(scope="module")
def big():
    return {n: mixed_comparison(n) for n in (1_000, 10_000)}


@pytest.fixture(scope="module")
def pages(big):
    return {n: render_report(c, links={"JSON": "m.json", "CSV": "m.csv"})
            for n, c in big.items()}


def test_page_size_does_not_grow_with_the_program(big, pages):
    size = {n: len(h.encode("utf-8")) for n, h in pages.items()}
    assert len(big[10_000].rows) > 10_000
    # linear growth would be a factor 10; the plots and the table are bounded
    assert size[10_000] < 1.5 * size[1_000], size
    assert size[10_000] < 5e6, size             # 5 MB at 10^4 blocks (10 MB target at 10^5)


def test_plots_stay_small(pages):
    for uri in re.findall(r'src="data:image/svg\+xml;base64,([^"]*)"', pages[10_000]):
        assert len(uri) < 1.5e6                 # base64 of ~1.1 MB SVG at most


def test_table_shows_the_largest_gaps_with_a_pointer_to_the_full_data(big, pages):
    c, html = big[10_000], pages[10_000]
    body = html[html.index("id='blocks'"):html.index("</table>", html.index("id='blocks'"))]
    lines = [int(v) for v in re.findall(r"<td class='t' data-v='(\d+)'><a href='#L", body)]
    assert len(lines) == MAX_TABLE_ROWS
    gaps = np.array(re.findall(r"<td class='gap' data-v='([^']*)'>", body), dtype=float)
    # independent check: the shown gaps are the MAX_TABLE_ROWS largest of all rows
    all_gaps = np.sort([1e3 * r.gap_s for r in c.rows if r.length_mm > 0])[::-1]
    np.testing.assert_allclose(np.sort(gaps)[::-1], all_gaps[:MAX_TABLE_ROWS], rtol=1e-12)
    assert np.all(np.diff(gaps) <= 0)           # largest first
    assert "Showing the 500 blocks with the largest gaps" in html
    assert "<a href='m.json'>JSON</a> and <a href='m.csv'>CSV</a>" in html
    assert "table class='sortable' id='blocks'" in html   # the sorter still applies


def test_every_table_link_has_its_source_line(big, pages):
    c, html = big[10_000], pages[10_000]
    body = html[html.index("id='blocks'"):html.index("</table>", html.index("id='blocks'"))]
    linked = set(int(v) for v in re.findall(r"<a href='#L(\d+)'>", body))
    listed = set(int(v) for v in re.findall(r"<span id='L(\d+)'", html))
    assert linked <= listed
    assert len(c.program_lines) > MAX_LISTING_LINES
    assert set(range(1, LISTING_HEAD + 1)) <= listed
    assert len(listed) < len(c.program_lines) // 2
    assert "not shown</span>" in html


def test_small_program_keeps_every_row_and_line(pages, big):
    c, html = big[1_000], pages[1_000]
    listed = set(int(v) for v in re.findall(r"<span id='L(\d+)'", html))
    assert listed == set(range(1, len(c.program_lines) + 1))


def test_gap_plot_labels_blocks_not_lines_when_large():
    c = mixed_comparison(1_000)
    assert len(moving_rows(c)) > MAX_LINE_TICKS
    svg = base64.b64decode(plot_gaps(c).split("base64,", 1)[1]).decode()
    assert "execution order" in svg


def test_terminal_verdict_names_a_wide_bracket_too(machine):
    """The text verdict (terminal, JSON) says how wide the bracket is, not a bare ok."""
    c = _with_bounds(machine, SolveStatus.GAP_NOT_MET, 1.16)
    v = c.verdict()
    assert v.ok and "gap_not_met" in v.text and "UB/LB - 1 = 16.00 %" in v.text
    assert "bracket" not in _with_bounds(machine, SolveStatus.OPTIMAL, 1.001).verdict().text

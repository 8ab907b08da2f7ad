"""A large report in headless Chromium: it opens quickly, every plot is drawn, the table
is limited and its sorter still works (skipped without a browser, like
``test_report_browser.py``).

The report is of a 10^4-block mixed program; a 10^5-block report was measured by hand
(see ``tests/bench/bench_report.py``) since the comparison alone takes a minute.
"""

from __future__ import annotations

import re
import time

import pytest

from large import mixed_comparison
from test_report_browser import BROWSER, _chromium

from compare.report.page import MAX_TABLE_ROWS
from compare.report_html import write_report

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(BROWSER is None, reason="no headless browser: install Debian's "
                       "'chromium' (.ci/run does) to render the report"),
]

#: Wall time allowed for Chromium to start, load and lay out the page, s (the
#: 150 MB page of 10^5 blocks took 93 s before the report was reduced; this one ~2 s).
OPEN_BUDGET_S = 30.0

#: A page that loads the report in a frame, clicks the table's "line" header twice
#: (descending) and writes the first rows' line numbers into its own DOM.
_PROBE = """<!DOCTYPE html><html><body><pre id="out">pending</pre>
<iframe id="f" src="REPORT" width="1400" height="900"></iframe>
<script>
document.getElementById('f').addEventListener('load', function () {
  var d = this.contentDocument, out = document.getElementById('out');
  var th = d.querySelectorAll('#blocks thead th')[1];
  th.click(); th.click();
  var lines = Array.prototype.map.call(d.querySelectorAll('#blocks tbody tr'),
      function (r) { return r.cells[1].getAttribute('data-v'); });
  out.textContent = 'rows=' + lines.length + ' head=' + lines.slice(0, 5).join(',') +
      ' class=' + th.className.replace(/ /g, '+');
});
</script></body></html>"""


@pytest.fixture(scope="module")
def large_page(tmp_path_factory):
    c = mixed_comparison(10_000)
    page = write_report(tmp_path_factory.mktemp("large") / "large.html", c,
                        links={"JSON": "large.json", "CSV": "large.csv"})
    return c, page


def test_large_report_opens_and_draws_every_plot(large_page):
    c, page = large_page
    assert page.stat().st_size < 5e6
    t0 = time.perf_counter()
    r = _chromium("--dump-dom", page.as_uri())
    elapsed = time.perf_counter() - t0
    assert r.returncode == 0, r.stderr[-2000:]
    assert elapsed < OPEN_BUDGET_S
    drawn = re.findall(r'<img class="plot"[^>]*data-drawn="(\d+)x(\d+)"', r.stdout)
    assert len(drawn) == 4, r.stdout[:2000]
    assert all(int(w) > 300 and int(h) > 100 for w, h in drawn)
    assert r.stdout.count("<tr class=") == MAX_TABLE_ROWS


def test_large_report_table_sorts_in_the_browser(large_page, tmp_path):
    c, page = large_page
    probe = tmp_path / "probe.html"
    probe.write_text(_PROBE.replace("REPORT", page.as_uri()))
    r = _chromium("--allow-file-access-from-files", "--dump-dom", probe.as_uri())
    assert r.returncode == 0, r.stderr[-2000:]
    m = re.search(r"rows=(\d+) head=([\d,]+) class=([\w+-]+)", r.stdout)
    assert m, r.stdout[:2000]
    assert int(m.group(1)) == MAX_TABLE_ROWS and "sorted-desc" in m.group(3).split("+")
    head = [int(v) for v in m.group(2).split(",")]
    # the largest line numbers among the shown rows, descending (checked against the
    # page's own rows, read without the browser)
    html = page.read_text()
    shown = sorted((int(v) for v in re.findall(r"<td class='t' data-v='(\d+)'><a href='#L",
                                               html)), reverse=True)
    assert head == shown[:5]

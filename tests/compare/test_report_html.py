"""The HTML report: self-contained, everything from the program escaped, all parts there."""

from __future__ import annotations

import re

import pytest

from conftest import path_of
from fakes import fake_plan, fake_solution

from compare.comparison import compare
from compare.report_html import render_report, write_index

HOSTILE = """; <script>alert('comment')</script> & </pre> "quoted"
N10 G90 G64 F6000 ; <img src=x onerror=alert(1)>
N20 G1 X50 Y0 ; </td></tr></table><b>bold</b>
N30 G1 X50 Y30
N40 G2 X80 Y60 CR=30
M30
"""


@pytest.fixture
def page(machine):
    program, path = path_of(HOSTILE, machine, file="we<ird>&name.mpf")
    c = compare(fake_plan(path, machine.limits), fake_solution(path, machine.limits),
                program=program, machine=machine.name)
    return c, render_report(c, max_gap=0.15, links={"JSON": "x.json"})


def test_program_text_and_names_are_escaped(page):
    c, html = page
    assert html.count("<script>") == 1                  # only the page's own script
    assert "<img src=x" not in html and "<b>bold</b>" not in html
    assert "&lt;script&gt;alert(&#x27;comment&#x27;)&lt;/script&gt;" in html
    assert "&lt;img src=x onerror=alert(1)&gt;" in html
    assert "we&lt;ird&gt;&amp;name.mpf" in html and "we<ird>" not in html


def test_page_is_self_contained(page):
    c, html = page
    assert not re.search(r"""(src|href)=["']?(https?:)?//""", html)
    assert "<link" not in html and "@import" not in html
    imgs = re.findall(r"<img class=\"plot\"[^>]*src=\"data:image/svg\+xml;base64,", html)
    assert len(imgs) == 4                                # speed, axes, gaps, tool path


def test_page_has_summary_table_and_source_links(page):
    c, html = page
    assert "✔ ok:" in html and "within the gate of 15 %" in html
    assert "gap to optimum" in html.lower()
    for r in c.rows:
        assert f"<a href='#L{r.line}'>{r.line}</a>" in html
    n_lines = len(c.program_lines)
    assert all(f"id='L{n}'" in html for n in range(1, n_lines + 1))
    assert "table class='sortable hide-idle' id='blocks'" in html
    assert html.count("<tr class=") >= len(c.rows)


def test_index_links_every_program(machine, tmp_path):
    program, path = path_of(HOSTILE, machine, file="a<b.mpf")
    c = compare(fake_plan(path, machine.limits), fake_solution(path, machine.limits),
                program=program)
    index = write_index(tmp_path, [("a_b", c), ("second", c)], max_gap=0.01).read_text()
    assert "href='a_b.html'" in index and "href='second.html'" in index
    assert "a&lt;b.mpf" in index
    assert "2 program(s) fail" in index

"""Render a report in headless Chromium and check that every plot is drawn.

Needs Debian's ``chromium`` (``.ci/run`` installs it). Where no browser exists the test
is skipped and says so. The page marks each plot image with its decoded size once the
browser has drawn it (``data-drawn="WxH"``); the test reads the DOM after rendering.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import tempfile

import pytest

from conftest import SMALL, path_of
from fakes import fake_plan, fake_solution

from compare.comparison import compare
from compare.report_html import write_report

BROWSER = next((shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome")
                if shutil.which(b)), None)

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(BROWSER is None, reason="no headless browser: install Debian's "
                       "'chromium' (.ci/run does) to render the report"),
]


def _chromium(*args: str) -> subprocess.CompletedProcess:
    with tempfile.TemporaryDirectory() as profile:
        return subprocess.run(
            [BROWSER, "--headless", "--no-sandbox", "--disable-gpu",
             "--disable-background-networking", "--disable-component-update",
             "--disable-sync", "--no-first-run", f"--user-data-dir={profile}",
             "--virtual-time-budget=5000", *args],
            capture_output=True, text=True, timeout=120)


def test_plots_are_drawn(machine, tmp_path):
    program, path = path_of(SMALL, machine)
    c = compare(fake_plan(path, machine.limits), fake_solution(path, machine.limits),
                program=program)
    page = write_report(tmp_path / "small.html", c)
    r = _chromium("--dump-dom", page.as_uri())
    assert r.returncode == 0, r.stderr[-2000:]
    drawn = re.findall(r'<img class="plot"[^>]*data-drawn="(\d+)x(\d+)"', r.stdout)
    assert len(drawn) == 4, r.stdout[:2000]
    assert all(int(w) > 300 and int(h) > 100 for w, h in drawn)
    # the table survived the script (rows and the sorter's headers are there)
    assert r.stdout.count("<tr class=") >= len(c.rows)

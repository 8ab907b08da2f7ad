"""Inserted rounding blocks on rows of their own (issue 13 item 5: "block rows carry
inserted rounding blocks with their corner"), and the programmed contour beside the
planned path in the tool-path plot ("the tool-path plot shows the programmed contour
and the rounded path").

Independent reference for the split times: the time at which each profile crosses a
path position, found by interpolating a dense time sampling of the profile (its exact
``state``), not by the profile's own ``time_at`` that the rows use.
"""

from __future__ import annotations

import numpy as np
import pytest

from compare.pipeline import compare_program
from compare.report.plots import plot_toolpath
from reference.core.geometry import KIND_CODES
from reference.nc import parse_text
from reference.prepare import prepare

ROUNDING = KIND_CODES.index("rounding")
TEXT = ("G17 G90 G642 CTOL=0.2 BRISK F4000\nG1 X0 Y0\nG1 X20\nX20.4\nX20.6\nX20.8\nX21\n"
        "Y10\nX31 Y20\nX0\nY0\nM30\n")


@pytest.fixture(scope="module")
def comparison(tmp_path_factory):
    f = tmp_path_factory.mktemp("ins") / "steps.mpf"
    f.write_text(TEXT)
    return compare_program(str(f))


def _crossing_times(prof, s_query: np.ndarray) -> np.ndarray:
    """Time the profile first reaches each ``s`` by dense sampling (1e6 points)."""
    t = np.linspace(prof.t[0], prof.t[-1], 1_000_001)
    s = prof.state(t)[0]
    s = np.maximum.accumulate(s)
    return np.interp(s_query, s, t)


def test_each_rounding_has_a_row_after_its_corner_block(comparison):
    c = comparison
    path = c.path
    n_round = int(np.sum(path.kind == ROUNDING))
    assert n_round == int(path.rounding.inserted.sum()) == 3
    assert len(c.rows) == len(path.blocks) + n_round
    # every program block still appears (spec: every input block in every output)
    assert sorted({r.block for r in c.rows}) == [sp.block for sp in path.blocks]
    ins = [k for k, r in enumerate(c.rows) if r.inserted]
    assert len(ins) == n_round
    table = path.rounding
    lines = {sp.block: sp.line for sp in path.blocks}
    for k in ins:
        r, before = c.rows[k], c.rows[k - 1]
        assert r.kind == "rounding" and before.block == r.block and not before.inserted
        i = int(np.flatnonzero(table.inserted & (table.block == r.block))[0])
        assert r.corner == (lines[int(table.block[i])], lines[int(table.next_block[i])])
        assert r.length_mm == pytest.approx(table.length_mm[i], rel=1e-12)
        assert r.s_start == pytest.approx(before.s_start + before.length_mm, abs=1e-9)


def test_split_rows_keep_the_times_and_match_an_independent_crossing(comparison):
    """The block and its rounding row sum to the block's time; each rounding row's time
    is the time between crossing its two ends (dense-sampling reference, 1e6 samples
    over ~1.6 s: 1.6 us resolution)."""
    c = comparison
    total_r = sum(r.t_reference_s for r in c.rows)
    assert total_r == pytest.approx(c.reference_profile.duration, rel=1e-12)
    total_o = sum(r.t_oracle_s for r in c.rows)
    assert total_o == pytest.approx(c.oracle.profile.duration, rel=1e-12)
    for r in c.rows:
        if not r.inserted:
            continue
        s = np.array([r.s_start, r.s_start + r.length_mm])
        for prof, t_row in ((c.reference_profile, r.t_reference_s),
                            (c.oracle.profile, r.t_oracle_s)):
            t0, t1 = _crossing_times(prof, s)
            assert t_row == pytest.approx(t1 - t0, abs=4e-6)
        # entry and exit speeds are the profile's at the rounding's ends
        v = c.reference_profile.state(_crossing_times(c.reference_profile, s))[1]
        np.testing.assert_allclose([r.v_entry_reference, r.v_exit_reference], v, rtol=1e-3)
        assert r.v_peak_reference >= max(v) * (1 - 1e-9)


def test_programmed_contour_is_the_path_before_rounding(comparison):
    c = comparison
    prog = prepare(parse_text(TEXT))
    assert c.programmed is not None
    assert c.programmed.n_segments == prog.n_segments
    np.testing.assert_allclose(c.programmed.total_length, prog.total_length, rtol=1e-15)
    # the rounded path is shorter than the programmed one at every rounded corner
    assert c.path.total_length < c.programmed.total_length
    assert not np.any(c.programmed.kind == ROUNDING)
    assert plot_toolpath(c).startswith("data:image/svg+xml")


def test_report_without_a_program_draws_the_planned_path_alone(comparison):
    from dataclasses import replace
    assert plot_toolpath(replace(comparison, programmed=None)).startswith("data:image/svg")



def test_a_clothoid_pair_is_one_inserted_row(tmp_path):
    """Under SOFT a rounding is two clothoid pieces (two inserted blocks, spec 5.1 "one
    or two intermediate blocks"); the rows show the rounding of a corner once, with the
    pair's whole length and time."""
    f = tmp_path / "soft.mpf"
    f.write_text("G17 G90 G645 CTOL=0.2 SOFT F5000\nG0 X0 Y0\nG1 X20\nX40 Y6\nX60 Y0\nM30\n")
    c = compare_program(str(f), bounds="acc")     # the rows, not the jerk bracket
    table = c.path.rounding
    assert table.g2[table.inserted].all() and int(table.inserted.sum()) == 2
    ins = [r for r in c.rows if r.inserted]
    assert len(ins) == 2
    for r in ins:
        i = int(np.flatnonzero(table.inserted & (table.block == r.block))[0])
        assert r.length_mm == pytest.approx(table.length_mm[i], rel=1e-12)
    total = sum(r.t_reference_s for r in c.rows)
    assert total == pytest.approx(c.reference_profile.duration, rel=1e-12)


# ------------------------------------------------------------------ feedoracle plan
def test_plan_rows_show_each_rounding_on_its_own_row_as_compare_does(comparison, tmp_path,
                                                                     capsys):
    """``feedoracle plan`` rows (text table and JSON) have the comparison's layout: each
    rounding on a row of its own after its corner block, with the corner's lines; the
    block's row keeps the rest of its length and time. The numbers are the comparison's
    reference side row for row; the rows sum to the plan's duration; each rounding row's
    time is the time between crossing its two ends (dense-sampling reference)."""
    import json

    import jsonschema

    from compare import cli
    from compare.export import schema

    f = tmp_path / "steps.mpf"
    f.write_text(TEXT)
    out = tmp_path / "p.json"
    assert cli.main(["plan", str(f), "--quiet", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    doc = json.loads(out.read_text())
    jsonschema.validate(doc, schema())
    rows = doc["blocks"]
    c = comparison
    assert len(rows) == len(c.rows)
    for r, cr in zip(rows, c.rows):
        assert (r["block"], r["kind"], r["line"]) == (cr.block, cr.kind, cr.line)
        assert r["length_mm"] == pytest.approx(cr.length_mm, rel=1e-12, abs=1e-12)
        assert r["t_reference_s"] == pytest.approx(cr.t_reference_s, rel=1e-9, abs=1e-12)
        assert r["v_exit_reference"] == pytest.approx(cr.v_exit_reference, rel=1e-9,
                                                      abs=1e-9)
        assert ("corner_lines" in r) == cr.inserted
        if cr.inserted:
            assert tuple(r["corner_lines"]) == cr.corner
    assert sum(r["t_reference_s"] for r in rows) == pytest.approx(doc["reference"]["time_s"],
                                                                  rel=1e-12)
    prof = c.reference_profile
    s = 0.0
    for r in rows:
        if r["kind"] == "rounding":
            t0, t1 = _crossing_times(prof, np.array([s, s + r["length_mm"]]))
            assert r["t_reference_s"] == pytest.approx(t1 - t0, abs=4e-6)
        s += r["length_mm"]
    assert sum(1 for ln in text.splitlines() if " rounding " in ln) == 3


def test_comparison_rows_name_the_rounding_decision_per_corner_block(comparison):
    """Issue 13 item 2: the cases where no rounding is inserted are "named in the trace
    and in the block rows". The comparison's rows (JSON, CSV, HTML) carry the rounding
    stage's decision on the row of the block that ends at the corner, the inserted
    rounding rows carry none; the program's last corner (X0 -> Y0 -> end) is a stop."""
    from compare.export import blocks_csv, comparison_dict
    from compare.report_html import render_report

    c = comparison
    table = c.path.rounding
    want = {int(table.block[i]): ("rounded" if table.inserted[i]
                                  else "none: " + table.reason_text(i))
            for i in range(table.n)}
    assert "rounded" in want.values() and any(v.startswith("none") for v in want.values())
    got = {r.block: r.rounding for r in c.rows if not r.inserted and r.rounding}
    assert got == want
    assert all(r.rounding == "" for r in c.rows if r.inserted)
    doc = comparison_dict(c)
    assert {r["block"]: r["rounding"] for r in doc["blocks"] if "rounding" in r} == want
    csv_text = blocks_csv(c)
    assert "rounding" in csv_text.splitlines()[0].split(",")
    html = render_report(c)
    assert ">rounding</th>" in html and "none: " in html

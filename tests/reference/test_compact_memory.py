"""Memory at scale: compact parsed statements, and results that do not depend on the
chunk sizes the large stages work in.

A program's parsed lines are all held at once while it is interpreted, so a plain word
line must stay small (slots, no kept word pairs): bounded here by bytes per line, not by
time. The checker, the profile's own checks, the block times and the JSON rows work in
chunks to bound their temporaries; shrinking every chunk to a few items must give the
very same numbers, and the block times must equal their definition (split at every
block end, label the intervals, sum).
"""

from __future__ import annotations

import math
import sys
import tracemalloc

import numpy as np
import pytest

import reference.core.constraints as constraints
import reference.core.profile as profile_mod
import reference.planner.engine as engine
import reference.planner.export as export
from reference.core.constraints import CONSTRAINTS, check_profile
from reference.machine import load_machine
from reference.nc import parse_file, parse_text
from reference.nc.lines import FullStmt, Stmt, fast_pairs, parse_ngc, parse_sinumerik
from reference.planner import plan, to_json_dict
from reference.prepare import build_path
from shared_inputs import corpus_file

PROGRAMS = ["sin_cead_arc.mpf", "sin_cead_loop.mpf", "lcnc_tangent_helix.ngc",
            "lcnc_arc_arc_sawtooth.ngc", "lcnc_test_12mmflat.ngc"]


# ----------------------------------------------------------------- statements
def test_statements_have_slots_and_no_dict():
    for cls in (Stmt, FullStmt):
        assert "__slots__" in cls.__dict__
    st = parse_sinumerik(3, "N10 G1 X1.5 Y-2 ; cut")
    assert type(st) is Stmt and not hasattr(st, "__dict__")
    assert (st.line, st.label, st.comment, st.kind, st.dialect) == (3, "N10", "cut", "block",
                                                                    "sinumerik")
    full = parse_sinumerik(4, "IF R1 > 2 GOTOF END")
    assert isinstance(full, FullStmt) and not hasattr(full, "__dict__")
    # a plain line keeps only its span; the pairs are read from the text when it runs
    assert fast_pairs(st) == [("G", "1"), ("X", "1.5"), ("Y", "-2")]
    ngc = parse_ngc(5, "g1 x 1 . 5 y2")
    assert type(ngc) is Stmt and fast_pairs(ngc) == [("G", "1"), ("X", "1.5"), ("Y", "2")]
    assert [(w.name, w.value, w.col) for w in ngc.words] == [
        ("G", ("num", 1.0), 1), ("X", ("num", 1.5), 4), ("Y", ("num", 2.0), 12)]


def test_plain_line_costs_about_a_hundred_bytes():
    # 20 000 CAM-like lines: the statements alone, measured by allocation; the line
    # text itself belongs to the program and is allocated before
    lines = [f"G1 X{math.cos(i / 50) * 50:.4f} Y{math.sin(i / 50) * 50:.4f}"
             for i in range(20_000)]
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        stmts = [parse_sinumerik(i, raw) for i, raw in enumerate(lines, 1)]
        per_line = (tracemalloc.get_traced_memory()[0] - before) / len(lines)
    finally:
        tracemalloc.stop()
    assert all(type(s) is Stmt for s in stmts)
    # object with 8 slots (~96 B) + list entry; a __dict__ and kept word pairs were ~590
    assert per_line < 160, per_line
    assert sys.getsizeof(stmts[0]) <= 112


# ----------------------------------------------------------------- chunk sizes
def _small_chunks(monkeypatch):
    monkeypatch.setattr(constraints, "_WORK_CHUNK", 7)
    monkeypatch.setattr(profile_mod, "_CHECK_CHUNK", 5)
    monkeypatch.setattr(profile_mod, "_LABEL_CHUNK", 3)
    monkeypatch.setattr(export, "_ROW_CHUNK", 4)
    monkeypatch.setattr(engine, "_ASSEMBLE_CHUNK", 2)


def _report_numbers(rep):
    out = []
    for r in rep.results:
        out.append((r.constraint, r.ratio, r.value, r.limit, r.s, r.t, r.block, r.axis))
    for c in CONSTRAINTS:
        out.append(tuple(np.asarray(rep.block_ratios[c]).tolist()))
    return out


@pytest.mark.parametrize("name", PROGRAMS)
def test_results_do_not_depend_on_chunk_sizes(name, monkeypatch):
    m = load_machine("linuxcnc_xyz" if name.endswith(".ngc") else None)
    prog = parse_file(corpus_file(name))
    p = plan(prog, m)
    doc = to_json_dict(p)
    rep = _report_numbers(check_profile(p.path, m.limits, p.profile))
    times = p.profile.block_times(p.path)
    _small_chunks(monkeypatch)
    p2 = plan(prog, m)
    assert to_json_dict(p2) == doc
    assert _report_numbers(check_profile(p.path, m.limits, p.profile)) == rep
    assert np.array_equal(p.profile.block_times(p.path), times)
    for name in ("t", "s", "v", "a", "j", "block"):
        assert np.array_equal(getattr(p2.profile, name), getattr(p.profile, name))


@pytest.mark.parametrize("name", PROGRAMS)
def test_block_times_equal_their_definition(name):
    m = load_machine("linuxcnc_xyz" if name.endswith(".ngc") else None)
    p = plan(parse_file(corpus_file(name)), m)
    path, prof = p.path, p.profile
    # the definition: split at every block end, label every interval, sum its durations
    split = prof.split_at([b.s_end for b in path.blocks if b.s_end > b.s_start])
    n_blocks = max(b.block for b in path.blocks) + 1
    want = np.bincount(split.interval_blocks(path), weights=np.diff(split.t),
                       minlength=n_blocks)
    assert np.array_equal(prof.block_times(path), want)
    assert prof.block_times(path).sum() == pytest.approx(prof.duration, rel=1e-12)


def test_junction_tangents_in_ranges_equal_the_whole():
    prog = parse_text("G90 G17 G1 F3000 X0 Y0\nG1 X5\nG3 X10 Y5 I0 J5\nG1 Y9\n"
                      "G2 X12 Y11 CR=2\nG1 X20 Y11 Z3\nM30\n", "t.mpf")
    path = build_path(prog, load_machine())
    t_in, t_out = path.junction_tangents()
    for lo, hi in [(0, 1), (1, 3), (2, 99), (0, path.n_segments - 1)]:
        a, b = path.junction_tangents(lo, hi)
        assert np.array_equal(a, t_in[lo:hi]) and np.array_equal(b, t_out[lo:hi])
    assert path.junction_tangents(3, 3)[0].shape == (0, path.n_axes)

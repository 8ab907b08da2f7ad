"""Programs written by others (../shared/corpus/): every file parses; counts checked by hand.

The corpus lives beside the repository, not in it; these tests say so and skip when the
folder is absent.
"""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path

import pytest

from reference.nc import parse_file
from shared_inputs import CORPUS_PRESENT, NO_CORPUS, corpus_cases, corpus_file, corpus_listing

SUFFIXES = (".mpf", ".spf", ".ngc", ".nc", ".tap")
IN = 25.4


def _files() -> list[Path]:
    return sorted(p for p in corpus_listing() if p.suffix.lower() in SUFFIXES)


def _load(name: str):
    return parse_file(corpus_file(name))


def _moving(prog):
    return [b for b in prog.blocks if b.moves]


def test_corpus_folder_is_there_or_skip():
    if not CORPUS_PRESENT:
        pytest.skip(NO_CORPUS)
    assert len(_files()) >= 12


@pytest.mark.parametrize("path", corpus_cases(_files()), ids=lambda p: p.name)
def test_every_corpus_program_parses(path: Path):
    prog = parse_file(path)
    assert prog.blocks, path.name
    n = len(prog.axes)
    assert prog.axes[:3] == ("X", "Y", "Z")
    for i, b in enumerate(prog.blocks):
        assert b.index == i and len(b.start) == n and len(b.end) == n
        assert all(math.isfinite(v) for v in b.start + b.end)
        if i:
            assert b.start == prog.blocks[i - 1].end          # the path is continuous
        if b.motion in ("G1", "G2", "G3") and b.moves:
            assert b.feed_mm_s is not None and b.feed_mm_s > 0
    for w in prog.warnings:
        assert 1 <= w.line <= len(prog.lines)


def test_short_segments_3000_moves_of_one_thousandth_inch():
    # 1000 steps of 0.001 in along X, then Y, then Z (tab-separated words), F999 in/min
    prog = _load("lcnc_short_segments_0.001.ngc")
    moving = _moving(prog)
    assert len(moving) == 3000 and all(b.motion == "G1" for b in moving)
    assert Counter(b.motion for b in prog.blocks)["G1"] == 3001     # plus "G1 X0 F999"
    assert all(math.dist(b.start, b.end) == pytest.approx(0.001 * IN) for b in moving)
    assert moving[-1].end == pytest.approx((IN, IN, IN))
    assert moving[0].feed_mm_s == pytest.approx(999 * IN / 60)
    assert prog.source_units == "inch"


def test_cead_loop_builds_a_raster():
    # WHILE y <= 1050 from y = 950 by 1 mm: 101 rows, each an X stroke then a 1 mm Y step
    prog = _load("sin_cead_loop.mpf")
    moving = _moving(prog)
    assert len(moving) == 3 + 2 * 101
    rows = moving[3:]
    assert [b.end[0] for b in rows[0::2]] == [1250.0, 920.0] * 50 + [1250.0]
    assert [b.end[1] for b in rows[1::2]] == [951.0 + k for k in range(101)]
    assert rows[0].feed_mm_s == pytest.approx(250 / 60)               # mes_fr
    assert moving[0].end == (920.0, 950.0, 1250.0)                     # x/y/z_start
    assert moving[0].feed_mm_s == pytest.approx(5000 / 60)            # mov_fr


def test_cead_edge_cases_positions():
    # values match the upstream interpreter's expected output (examples/edge_cases.csv)
    prog = _load("sin_cead_edge_cases.mpf")
    assert prog.axes == ("X", "Y", "Z", "A", "B", "C", "ELX", "E")
    x = [b.end[0] for b in prog.blocks if b.motion is not None]
    assert x == [1.5, 2.0, 0.0, 100.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 7.0, 7.0, 1.0, 2.0, 3.0,
                 3.0, 11.0, 2.0, 100.0, 101.0, 30.0, 40.0, 50.0, 1.0, 5.0, 7.0]
    last = prog.blocks[-1]
    assert last.aux == (("M", 30.0),)
    # Y=5 MOD 10, Z=SIN(30) then DEF REAL DEPTH = 2.5; E = IC(2*0.02988) + IC(0.25*2)
    assert last.end == pytest.approx((7.0, 5.0, 2.5, 0.0, -1.5, 90.0, 3087.022334,
                                      0.02988 + 0.5))
    assert last.feed_mm_s == pytest.approx(2628 / 60)                # F=(F_MULTI*1314)
    assert any("MATERIAL_UPDATE" in w.message for w in prog.warnings)


def test_arc_arc_sawtooth_48_radius_arcs():
    prog = _load("lcnc_arc_arc_sawtooth.ngc")
    arcs = [b for b in prog.blocks if b.is_arc]
    assert len(arcs) == 48 and [b.motion for b in arcs[:2]] == ["G2", "G3"]
    for b in arcs:                                          # R0.2 in: both radii 5.08 mm
        r0 = math.dist(b.start[:2], b.center[:2])
        r1 = math.dist(b.end[:2], b.center[:2])
        assert r0 == pytest.approx(0.2 * IN) and r1 == pytest.approx(0.2 * IN)


def test_12mmflat_g18_radius_arcs():
    prog = _load("lcnc_test_12mmflat.ngc")
    arcs = [b for b in prog.blocks if b.is_arc]
    assert len(arcs) == 39 and all(b.plane == "G18" for b in arcs)
    assert all(b.naive_cam_tol_mm == 0.0 and b.contour_tol_mm == 0.5 for b in arcs)
    first = arcs[0]                                           # R1598.76735 in the XZ plane
    assert math.hypot(first.start[0] - first.center[0],
                      first.start[2] - first.center[2]) == pytest.approx(1598.76735)


def test_sam_tolerance_issue_g18_centre_arcs_and_glued_g64():
    prog = _load("lcnc_sam_tolerance_issue.ngc")
    arcs = [b for b in prog.blocks if b.is_arc]
    assert [b.motion for b in arcs] == ["G2", "G3", "G3", "G3"]
    assert all(b.plane == "G18" for b in arcs)
    assert arcs[0].contour_tol_mm == pytest.approx(0.005 * IN)     # G64P.005 in inch


def test_full_xz_rotated_coordinate_system():
    prog = _load("lcnc_full_xz.ngc")
    arc = next(b for b in prog.blocks if b.is_arc)
    c, s = math.cos(math.radians(60)), math.sin(math.radians(60))
    assert arc.continuous_mode == "G61" and arc.plane == "G19"
    assert arc.end == pytest.approx(((-0.5 * s - 2) * IN, (0.5 * c + 1) * IN, 1.5 * IN))
    assert arc.plane_basis[0] == pytest.approx((-s, c, 0.0))


def test_tangent_helix_is_a_full_turn():
    prog = _load("lcnc_tangent_helix.ngc")
    helix = next(b for b in prog.blocks if b.is_arc)
    assert helix.start[:2] == helix.end[:2] == pytest.approx((IN, 0.0))
    assert helix.end[2] == pytest.approx(1.6835744289 * IN) and helix.turns == 0


def test_cead_arc_centres():
    prog = _load("sin_cead_arc.mpf")
    arcs = [b for b in prog.blocks if b.is_arc]
    assert [b.center[:2] for b in arcs] == [(50.0, 0.0), (50.0, 50.0), (0.0, 25.0),
                                            (80.0, 60.0)]
    assert arcs[2].end == (0.0, 0.0, 10.0)                       # helix down to Z10

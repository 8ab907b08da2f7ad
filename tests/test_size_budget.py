"""Resource limits by design (issue 9, item 3): sizes known before allocation, programs
above the budget rejected up front naming the line, the loop guard counting repetitions
only, and the checker's memory bounded on a helix of many turns."""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest

from compare import pipeline
from compare.cli import main
from reference.core.budget import grid_points
from reference.core.constraints import CHUNK_SAMPLES, check_profile
from reference.core.errors import BudgetError, NCSyntaxError
from reference.core.profile import Profile
from reference.machine import load_machine
from reference.nc import parse_text
from reference.prepare import prepare

# F100000: fast enough that 1e6 turns (3.1e7 mm) move in 1.9e4 s, inside the motion
# time one block may take (MAX_BLOCK_MOTION_S): the grid budget is what these test
HELIX_SIN = "G17 G90 G1 F100000 X0 Y0 Z0\nG2 X0 Y0 Z10 I5 J0 TURN={n}\nM30\n"
HELIX_NGC = "G17 G90 G1 F100000 X0 Y0 Z0\nG2 X0 Y0 Z10 I5 J0 P{n}\nM30\n"


@pytest.mark.parametrize("name, text, word", [
    ("helix.mpf", HELIX_SIN.format(n=1_000_000), "TURN=1000000"),
    ("helix.ngc", HELIX_NGC.format(n=1_000_000), "P1000000"),
])
@pytest.mark.parametrize("command", ["plan", "compare", "optimize"])
def test_huge_helix_is_rejected_up_front(tmp_path, capsys, name, text, word, command):
    f = tmp_path / name
    f.write_text(text)
    argv = [command, str(f), "--quiet"] + (["--no-report"] if command == "compare" else [])
    tracemalloc.start()
    try:
        code = main(argv)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    err = capsys.readouterr().err
    assert code == 2
    assert f"{f}:2: {word} gives" in err and "at line 2" in err
    assert "--max-grid-points" in err and "Traceback" not in err
    # 2 pi * 1e6 turns / 0.125 deg: 2.9e9 points, never allocated
    assert "2.9e+09 grid points" in err
    assert peak < 100e6


def test_budget_option_raises_the_limit(tmp_path, capsys):
    f = tmp_path / "h.mpf"
    f.write_text(HELIX_SIN.format(n=20))       # 21 turns: 21 * 2880 = 6e4 points
    assert main(["plan", str(f), "--quiet", "--max-grid-points", "1e4"]) == 2
    assert "TURN=20 gives" in capsys.readouterr().err
    assert main(["plan", str(f), "--quiet", "--max-grid-points", "1e5"]) == 0
    with pytest.raises(SystemExit) as exc:
        main(["plan", str(f), "--quiet", "--max-grid-points", "zero"])
    assert exc.value.code == 2


def test_grid_points_of_a_helix_by_hand():
    path = prepare(parse_text(HELIX_SIN.format(n=99)))
    # 100 full turns at 0.125 degree per sample: 100 * 2880 (+1), the line move 1 point
    assert grid_points(path).sum() == pytest.approx(100 * 2880 + 1, abs=2)


def test_csv_rows_are_budgeted_too(tmp_path, capsys):
    f = tmp_path / "long.mpf"
    f.write_text("G90 G1 F60 X0\nX1000\nM30\n")     # 1000 s at 1 mm/s: 2.5e5+ IPO rows
    assert main(["plan", str(f), "--quiet", "--csv", str(tmp_path / "o.csv"),
                 "--max-grid-points", "1e4"]) == 2
    assert "IPO cycle" in capsys.readouterr().err


def test_checker_memory_is_bounded_on_one_long_helix_interval():
    """One constant-speed interval over 100 turns needs 2.9e5 samples, more than a chunk:
    checked in pieces, its axis velocity peak is the closed form v * 2 pi r / L_turn."""
    path = prepare(parse_text(HELIX_SIN.format(n=99)))
    seg = int(np.argmax(path.length))
    v = 10.0
    L = float(path.total_length)
    T = L / v
    prof = Profile(t=np.array([0.0, T]), s=np.array([0.0, L]), v=np.array([v, v]),
                   a=np.zeros(1), j=np.zeros(1), block=np.array([int(path.block[seg])]))
    assert 100 * 2880 > 4 * CHUNK_SAMPLES
    limits = load_machine(None).limits
    tracemalloc.start()
    try:
        rep = check_profile(path, limits, prof)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    r, pitch = 5.0, 10.0 / 100
    turn = math.hypot(2 * math.pi * r, pitch)
    assert rep.worst("velocity").value == pytest.approx(v * 2 * math.pi * r / turn, rel=1e-9)
    assert peak < 100e6


# ----------------------------------------------------------------- executed-block cap
def test_loop_free_program_longer_than_the_cap_parses():
    text = "".join(f"G1 X{i} F100\n" for i in range(1, 101))
    p = parse_text(text, max_repeats=10)           # 100 lines, at most 10 repeated
    assert len(p.blocks) == 100


def test_the_cap_counts_repetitions_only():
    loop = "R1=0\nL1: G1 X=R1 F100\nR1=R1+1\nIF R1<{n} GOTOB L1\nM30\n"
    # 5 passes: the 3 looping statements run 4 times again = 12 repetitions
    assert len(parse_text(loop.format(n=5), max_repeats=12).blocks) >= 5
    with pytest.raises(NCSyntaxError, match=r"<string>:2:1: loop does not terminate"):
        parse_text(loop.format(n=5), max_repeats=11)


def test_endless_loop_still_stops_at_its_line():
    with pytest.raises(NCSyntaxError, match=r"<string>:2:1: loop does not terminate within "
                                            r"50 blocks"):
        parse_text("G90\nL1: G1 X1 F100\nGOTOB L1\n", max_repeats=50)


# ----------------------------------------------------------------- columnar rows
def test_json_rows_from_columns_equal_the_row_objects():
    """The JSON rows are built from the table's columns (no object per block); they must
    be the rows of the table's own PlannedBlock objects, value and type."""
    from reference.planner import to_json_dict
    plan = pipeline.plan_program(parse_text(
        "G90 G1 F1000 X10\nG4 F0.5\nG9 G1 X20 Y5\nG2 X30 Y5 I5 J0\nG60 G1 X40\nM30\n"))
    rows = to_json_dict(plan)["blocks"]
    by_hand = [{"block": b.block, "line": max(1, b.line), "label": b.label, "kind": b.kind,
                "length_mm": max(0.0, b.length_mm), "t_reference_s": max(0.0, b.time_s),
                "v_exit_reference": max(0.0, b.v_exit), "limit_reference": b.cause,
                "hold_s": b.hold_s, "hold_cause": plan.holds.cause_of(b.block)}
               for b in plan.blocks]
    assert rows == by_hand
    assert any(r["hold_cause"] for r in rows)
    assert all(type(r[k]) is type(h[k]) for r, h in zip(rows, by_hand) for k in r)


# ----------------------------------------------------------------- the oracle's grid
def test_oracle_initial_counts_are_the_grid_it_builds():
    from optimal.grid import initial_counts, initial_grid
    for text in (HELIX_SIN.format(n=3), "G90 G1 F1000 X10\nG2 X20 I5 J0\nG1 Y30\nM30\n"):
        path = prepare(parse_text(text))
        assert initial_counts(path).sum() == initial_grid(path).n_intervals
        for by_length in (True, False):
            assert (initial_counts(path, lines_by_length=by_length).sum()
                    == initial_grid(path, lines_by_length=by_length).n_intervals)


def test_compare_counts_the_oracle_grid(tmp_path, capsys):
    """TURN=20000 needs 5.8e7 checker points (within 1e8) but 1.3e6 oracle intervals,
    above 1e8 / 100: compare and optimize refuse it, plan (no oracle) accepts it."""
    f = tmp_path / "h.mpf"
    f.write_text(HELIX_SIN.format(n=20_000))
    assert main(["compare", str(f), "--quiet", "--no-report"]) == 2
    err = capsys.readouterr().err
    assert f"{f}:2: TURN=20000 gives 1.3e+06 oracle grid intervals" in err
    assert "--max-grid-points" in err
    path = prepare(parse_text(HELIX_SIN.format(n=20_000)))
    pipeline.require_budget(parse_text(HELIX_SIN.format(n=20_000)), path)   # plan: fine
    with pytest.raises(BudgetError, match="oracle grid intervals"):
        pipeline.require_budget(parse_text(HELIX_SIN.format(n=20_000)), path, oracle=True)

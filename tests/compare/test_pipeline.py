"""``compare.pipeline``: the CLI's work as plain functions, with the real engines.

Each function called directly gives the numbers the CLI writes as JSON for the same
program; ``optimize`` and ``check`` never run the heuristic; ``compare`` hands the
heuristic and the oracle one and the same path object.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import SMALL

import compare
from compare import cli, engines, pipeline
from compare.export import comparison_dict, dumps, profile_samples, write_samples_csv
from compare.pipeline import oracle_intervals
from reference.core.budget import DEFAULT_MAX_GRID_POINTS
from reference.machine import load_machine
from reference.nc import parse_text
from reference.planner import to_json_dict

pytestmark = pytest.mark.xdist_group("pipeline")


def _cli_json(argv, tmp_path, name="out.json"):
    js = tmp_path / name
    code = cli.main([*map(str, argv), "--quiet", "--json", str(js)])
    return code, json.loads(js.read_text())


def _as_json(doc):
    """The document as the CLI writes it (one encoding of infinities), no wall times."""
    return _drop_times(json.loads(dumps(doc)))


def _drop_times(obj):
    if isinstance(obj, dict):
        return {k: _drop_times(v) for k, v in obj.items() if k != "solve_time_s"}
    if isinstance(obj, list):
        return [_drop_times(v) for v in obj]
    return obj


def _no_heuristic(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("the heuristic ran")
    monkeypatch.setattr(engines, "run_heuristic", refuse)
    import reference.planner
    import reference.planner.engine
    monkeypatch.setattr(reference.planner, "plan", refuse)
    monkeypatch.setattr(reference.planner.engine, "plan", refuse)


def test_compare_program_equals_the_cli_json(small_program, tmp_path):
    code, doc = _cli_json(["compare", small_program, "--no-report"], tmp_path)
    c = pipeline.compare_program(small_program)             # file path, default machine
    assert code == (0 if c.verdict(None).ok else 1)
    assert _as_json(comparison_dict(c)) == _drop_times(doc)
    assert doc["oracle"]["lower_bound_s"] == c.oracle.lower_bound_s
    assert doc["reference"]["time_s"] == c.t_reference_s
    # a parsed program and a loaded machine give the same numbers as the file
    same = compare.compare_program(parse_text(SMALL, str(small_program)), load_machine(None))
    assert same.t_reference_s == c.t_reference_s
    assert (same.gap_lower, same.gap_upper) == (c.gap_lower, c.gap_upper)


def test_compare_program_runs_both_sides_on_one_path_object(small_program, monkeypatch):
    seen = {}
    real_h, real_o = engines.run_heuristic, engines.run_oracle

    def heuristic(program, machine, progress=None, *, path=None):
        seen["heuristic"] = path
        return real_h(program, machine, progress, path=path)

    def oracle(path, limits, bounds, progress=None, *, tol=None, holds=None,
               max_grid=None):
        seen["oracle"] = path
        seen["holds"] = holds
        seen["max_grid"] = max_grid
        return real_o(path, limits, bounds, progress, tol=tol, holds=holds,
                      max_grid=max_grid)

    monkeypatch.setattr(engines, "run_heuristic", heuristic)
    monkeypatch.setattr(engines, "run_oracle", oracle)
    c = pipeline.compare_program(small_program, "default")
    assert seen["heuristic"] is not None and seen["heuristic"] is seen["oracle"]
    # the oracle's interval budget follows the size budget (--max-grid-points)
    assert seen["max_grid"] == oracle_intervals(DEFAULT_MAX_GRID_POINTS)
    assert c.path is seen["oracle"]
    # the oracle waits where the heuristic waits (the small program has G9 and G4 F0.2)
    h = seen["holds"]
    assert h.cause == ("exact stop settle", "dwell") and h.duration_s[1] == 0.2


def test_compare_program_passes_tol_and_reports_progress(small_program):
    messages = []
    c = pipeline.compare_program(small_program, tol=0.05,
                                 progress=lambda m, f=-1.0: messages.append(m))
    o = c.oracle
    assert o.upper_bound_s <= 1.05 * o.lower_bound_s
    assert any(m.startswith("heuristic: ") for m in messages)
    assert any(m.startswith("oracle: ") for m in messages)


def test_plan_program_equals_the_cli_json(small_program, tmp_path):
    code, doc = _cli_json(["plan", small_program], tmp_path)
    p = pipeline.plan_program(small_program)
    assert code == (0 if p.ok else 1)
    assert _as_json(to_json_dict(p)) == _drop_times(doc)


def test_optimize_program_equals_the_cli_json_without_the_heuristic(small_program, tmp_path,
                                                                   monkeypatch):
    code, doc = _cli_json(["optimize", small_program], tmp_path)
    _no_heuristic(monkeypatch)
    res = pipeline.optimize_program(small_program, bounds="acc")
    assert code == (0 if res.certified else 1) == 0
    assert _as_json(res.to_dict()) == _drop_times(doc)
    assert res.solution.lower_bound_s == doc["oracle"]["lower_bound_s"]
    assert [r["line"] for r in res.rows()] == [r["line"] for r in doc["blocks"]]


def test_check_trajectory_equals_the_cli_json_without_the_heuristic(small_program, tmp_path,
                                                                   monkeypatch):
    machine = load_machine(None)
    p = pipeline.plan_program(small_program, machine)
    header, data = profile_samples(p.path, p.profile, machine.limits.t_ipo_s)
    csv = tmp_path / "ipo.csv"
    write_samples_csv(header, data, csv)
    code, doc = _cli_json(["check", csv, "--program", small_program], tmp_path)
    _no_heuristic(monkeypatch)
    result = pipeline.check_trajectory(csv, small_program, machine)
    assert code == (0 if result.ok else 1) == 0
    assert _as_json(result.to_dict()) == _drop_times(doc)
    assert result.comparison.t_reference_s == pytest.approx(p.profile.duration, abs=1e-9)


@pytest.mark.parametrize("smoothing", ["abc", -1.0, float("nan")])
def test_check_trajectory_refuses_a_bad_smoothing(small_program, tmp_path, smoothing):
    with pytest.raises(ValueError, match="smoothing"):
        pipeline.check_trajectory(tmp_path / "none.csv", small_program, smoothing=smoothing)


def test_load_inputs_passes_objects_through_and_lists_warnings(small_program):
    program = parse_text("N10 G90 G64 F6000\nN20 G1 X10\nN30 CYCLE800()\nM30\n", "w.mpf")
    machine = load_machine("linuxcnc_xyz")
    inp = pipeline.load_inputs(program, machine)
    assert inp.program is program and inp.machine is machine
    assert any("CYCLE800" in str(w) and w.line == 3 for w in inp.warnings)
    from_file = pipeline.load_inputs(small_program, "linuxcnc_xyz")
    assert from_file.machine.name == machine.name
    assert [b.line for b in from_file.program.blocks] == [b.line for b in
                                                          parse_text(SMALL).blocks]
    assert np.isfinite(from_file.machine.limits.t_ipo_s)


def test_prefixed_progress_passes_messages_on_with_the_prefix() -> None:
    """The one prefixing helper (pipeline, commands and check use it): ``None`` stays
    ``None``; a message keeps its fraction, and an omitted fraction is unknown (-1)."""
    assert engines.prefixed(None, "oracle: ") is None
    seen: list[tuple[str, float]] = []
    cb = engines.prefixed(lambda m, f: seen.append((m, f)), "oracle: ")
    cb("grid", 0.25)
    cb("refining")
    assert seen == [("oracle: grid", 0.25), ("oracle: refining", -1.0)]

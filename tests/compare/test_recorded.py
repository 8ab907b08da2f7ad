"""Recorded trajectories: CSV validation, projection, resampling, noise, leaving the path,
and ``feedoracle check`` exit codes (with the stand-in engines; the round trip of the
real heuristic's CSV is in test_end_to_end.py)."""

from __future__ import annotations

import json

import jsonschema
import numpy as np
import pytest

from conftest import SMALL, path_of
from fakes import fake_plan

from compare import cli
from compare.export import profile_samples, schema, write_samples_csv
from compare.recorded import (RECORDED_RATIO_TOL, estimate_noise, project, read_trajectory,
                              recorded_profile)
from reference.core.constraints import BOUND_SETS, check_profile
from reference.core.errors import TrajectoryError
from reference.core.profile import Profile
from reference.core.tolerances import POS_TOL_MM


def write_csv(path, header, rows):
    path.write_text(",".join(header) + "\n" +
                    "\n".join(",".join(repr(float(x)) for x in r) for r in rows) + "\n")
    return path


# ------------------------------------------------------------------ reading
@pytest.mark.parametrize("text, match", [
    ("", "empty file"),
    ("x,X,Y\n0,0,0\n", r":1: first column is 'x', expected 't'"),
    ("t,X[m],Y\n0,0,0\n", r":1: column 'X\[m\]': unit 'm' not supported"),
    ("t[min],X,Y\n", r":1: time unit 'min' not supported"),
    ("t,X,Y\n0,0,0\n0.1,1,0\n0.2,nan,0\n0.3,3,0\n", r":4: column 'X': 'nan' is not a finite"),
    ("t,X,Y\n0,0,0\n0.1,1\n", r":3: 2 values, the header has 3 columns"),
    ("t,X,Y\n0,0,0\n0.1,1,0\n0.1,2,0\n0.3,3,0\n", r":4: time 0.1 is not after"),
    ("t,X,Y\n0,0,0\n0.1,1,zero\n", r":3: column 'Y': 'zero' is not a number"),
    ("t,X,Y\n0,0,0\n0.1,1,0\n", "2 sample"),
    ("t,X,X\n0,0,0\n", "axis X appears twice"),
])
def test_bad_csv_names_file_and_row(tmp_path, text, match):
    f = tmp_path / "rec.csv"
    f.write_text(text)
    with pytest.raises(TrajectoryError, match=match) as exc:
        read_trajectory(f)
    assert str(f) in str(exc.value)


def test_units_comments_and_path_columns(tmp_path):
    f = tmp_path / "rec.csv"
    f.write_text("# recorded on a test bench\nt[ms],s,v,X[in],Y[mm],A[deg]\n"
                 "0,0,0,0,0,0\n4,9,9,1,2,3\n8,9,9,2,4,6\n")
    rec = read_trajectory(f)
    assert rec.axes == ("X", "Y", "A")                    # s and v are not axes
    assert rec.t.tolist() == pytest.approx([0, 0.004, 0.008])
    assert rec.q[:, 0].tolist() == pytest.approx([0, 25.4, 50.8])
    assert rec.rows.tolist() == [3, 4, 5]


# ------------------------------------------------------------------ reconstruction
@pytest.fixture
def small(machine):
    program, path = path_of(SMALL, machine)
    return program, path, fake_plan(path, machine.limits)


def _samples(path, prof, t):
    s = np.clip(prof.state(t)[0], 0, path.total_length)
    return path.evaluate(s)[0]


def _rec(tmp_path, path, prof, t, q=None, name="rec.csv"):
    q = _samples(path, prof, t) if q is None else q
    f = write_csv(tmp_path / name, ("t", *path.axes), np.column_stack([t, q]))
    return read_trajectory(f, path.axes)


def _assert_reproduces(path, limits, prof, rec_prof, block_tol):
    assert rec_prof.duration == pytest.approx(prof.duration, abs=1e-9)
    bt, bt0 = rec_prof.block_times(path), prof.block_times(path)
    assert np.abs(bt - bt0).max() <= block_tol
    rep = check_profile(path, limits, rec_prof)
    assert rep.ok(BOUND_SETS["acc"], RECORDED_RATIO_TOL), rep.violations(BOUND_SETS["acc"])


def test_ipo_samples_read_back_reproduce_the_plan(tmp_path, machine, small):
    program, path, plan = small
    header, data = profile_samples(path, plan.profile, machine.limits.t_ipo_s)
    write_samples_csv(header, data, tmp_path / "ipo.csv")
    rec = read_trajectory(tmp_path / "ipo.csv", path.axes)
    prof, proj, noise, info = recorded_profile(path, machine.limits, rec)
    assert proj.deviation.max() <= POS_TOL_MM and noise == 0.0
    _assert_reproduces(path, machine.limits, plan.profile, prof, block_tol=1e-3)


def test_resampled_at_a_varying_period(tmp_path, machine, small):
    program, path, plan = small
    rng = np.random.default_rng(1)
    T = plan.profile.duration
    t = np.concatenate(([0.0], np.cumsum(rng.uniform(0.002, 0.006, int(T / 0.002)))))
    t = np.append(t[t < T], T)
    rec = _rec(tmp_path, path, plan.profile, t)
    prof, proj, noise, info = recorded_profile(path, machine.limits, rec)
    _assert_reproduces(path, machine.limits, plan.profile, prof, block_tol=3e-3)


def test_noise_is_smoothed_not_reported_as_violations(tmp_path, machine, small):
    program, path, plan = small
    T = plan.profile.duration
    t = np.append(np.arange(0, T, 0.004), T)
    q = _samples(path, plan.profile, t)
    rng = np.random.default_rng(7)
    noisy = q + rng.normal(0.0, 0.002, q.shape) * np.array([1, 1, 0])   # 2 um in X, Y
    rec = _rec(tmp_path, path, plan.profile, t, noisy)
    prof, proj, noise, info = recorded_profile(path, machine.limits, rec)
    assert 0.0005 < noise < 0.005                      # estimated near 2 um
    assert estimate_noise(proj.s, rec.t) == pytest.approx(noise)
    assert proj.deviation.max() < 0.01
    assert prof.duration == pytest.approx(T, abs=0.02)
    bt, bt0 = prof.block_times(path), plan.profile.block_times(path)
    assert np.abs(bt - bt0).max() < 0.02
    rep = check_profile(path, machine.limits, prof)
    assert rep.ok(("velocity", "acceleration", "feed"), RECORDED_RATIO_TOL)


def test_projection_is_monotone_on_a_path_over_itself(machine):
    # plunge and retract on the same line: the samples on the way back belong to it
    program, path = path_of("G90 G64 F1200\nG1 Z-5\nG1 Z0\nG1 X10\nM30\n", machine)
    s_true = np.linspace(0, path.total_length, 400)
    proj = project(path, path.evaluate(s_true)[0])
    assert np.all(np.diff(proj.s) >= 0)
    assert np.abs(proj.s - s_true).max() < 0.05
    assert proj.deviation.max() < 1e-9


# ------------------------------------------------------------------ the command
def _check(argv, capsys):
    code = cli.main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_check_round_trip_exit_0_and_json(fake_engines, tmp_path, machine, small,
                                          small_program, capsys):
    program, path, plan = small
    header, data = profile_samples(path, plan.profile, machine.limits.t_ipo_s)
    write_samples_csv(header, data, tmp_path / "ipo.csv")
    js = tmp_path / "check.json"
    code, out, err = _check(["check", tmp_path / "ipo.csv", "--program", small_program,
                             "--json", js, "--report", tmp_path / "rep"], capsys)
    assert code == 0, out + err
    assert "deviation  ok" in out
    doc = json.loads(js.read_text())
    jsonschema.validate(doc, schema())
    assert doc["reference"]["planner"] == "recorded"
    assert doc["reference"]["time_s"] == pytest.approx(plan.profile.duration)
    assert doc["recorded"]["max_deviation_mm"] < 1e-6
    assert (tmp_path / "rep" / "ipo.html").is_file()


def test_check_harder_acceleration_exits_1_and_names_where(fake_engines, tmp_path, machine,
                                                           capsys):
    prog = tmp_path / "line.mpf"
    prog.write_text("N10 G90 G64 F6000\nN20 G1 X100\nM30\n")
    A = 1.5 * machine.limits.axis("X").a_max              # 50 % above MAX_AX_ACCEL
    v = 100.0
    ta, tc = v / A, (100.0 - v * v / A) / v
    prof = Profile.from_phases([ta, tc, ta], [A, 0.0, -A], [0, 0, 0])
    t = np.append(np.arange(0, prof.duration, 0.004), prof.duration)
    x = prof.state(t)[0]
    write_csv(tmp_path / "fast.csv", ("t", "X", "Y", "Z"),
              np.column_stack([t, x, 0 * x, 0 * x]))
    code, out, err = _check(["check", tmp_path / "fast.csv", "--program", prog], capsys)
    assert code == 1
    assert "VIOLATION acceleration on X" in out
    assert "line 2 N20" in out
    assert "FAIL" in out and "breaks a limit" in out


def test_check_trajectory_leaving_the_path_exits_1(fake_engines, tmp_path, machine, small,
                                                   small_program, capsys):
    program, path, plan = small
    T = plan.profile.duration
    t = np.append(np.arange(0, T, 0.004), T)
    q = _samples(path, plan.profile, t)
    mid = (t > 0.4 * T) & (t < 0.45 * T)
    q[mid, 2] += 0.5                                      # 0.5 mm off in Z for a while
    write_csv(tmp_path / "off.csv", ("t", "X", "Y", "Z"), np.column_stack([t, q]))
    code, out, err = _check(["check", tmp_path / "off.csv", "--program", small_program],
                            capsys)
    assert code == 1
    line = next(ln for ln in out.splitlines() if "deviation" in ln)
    assert "FAIL: largest 0.5" in line and "row " in line and "line " in line


def test_check_missing_axis_and_bad_file_exit_2(fake_engines, tmp_path, small_program,
                                                capsys):
    f = tmp_path / "xy.csv"
    f.write_text("t,X\n0,0\n0.1,1\n0.2,2\n")
    code, out, err = _check(["check", f, "--program", small_program], capsys)
    assert code == 2 and "no column for axis Y" in err
    code, out, err = _check(["check", tmp_path / "none.csv", "--program", small_program],
                            capsys)
    assert code == 2 and "none.csv" in err


def _toy_csv(tmp_path, text, machine, limits=None, name="toy.csv"):
    """IPO-rate samples of the toy planner on ``text`` (optionally other limits)."""
    from fakes import toy_profile
    program, path = path_of(text, machine)
    prof = toy_profile(path, limits or machine.limits)
    T = prof.duration
    t = np.append(np.arange(0, T, 0.004), T)
    q = _samples(path, prof, t)
    return write_csv(tmp_path / name, ("t", *path.axes), np.column_stack([t, q]))


def test_check_corner_taken_too_fast_is_named(fake_engines, tmp_path, machine, capsys):
    from dataclasses import replace
    from reference.core.limits import MachineLimits
    text = "N10 G90 G64 F6000\nN20 G1 X50\nN30 G1 Y40\nM30\n"
    loose = MachineLimits(tuple(replace(a, overload_factor=3.0) for a in machine.limits.axes),
                          machine.limits.t_ipo_s)            # 10x the corner allowance
    csv = _toy_csv(tmp_path, text, machine, loose)
    prog = tmp_path / "corner.mpf"
    prog.write_text(text)
    code, out, err = _check(["check", csv, "--program", prog], capsys)
    assert code == 1
    assert "VIOLATION velocity_jump" in out and "s = 50.000 mm" in out


def test_check_exact_stop_not_made_is_named(fake_engines, tmp_path, machine, capsys):
    csv = _toy_csv(tmp_path, "N10 G90 G64 F6000\nN20 G1 X50\nN30 G1 X100\nM30\n", machine)
    prog = tmp_path / "stop.mpf"
    prog.write_text("N10 G90 G64 F6000\nN20 G9 G1 X50\nN30 G1 X100\nM30\n")
    code, out, err = _check(["check", csv, "--program", prog], capsys)
    assert code == 1
    assert "the recording does not stop at s = 50.000 mm (exact stop G9)" in out
    assert "VIOLATION no stop where the path requires rest (exact stop G9)" in out

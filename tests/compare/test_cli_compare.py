"""``feedoracle compare``: output, report files, JSON contract, the gate, exit codes.

The heuristic and the oracle are replaced by small stand-ins here (``fake_engines``),
so these tests check the command itself; test_end_to_end.py runs the real ones.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import jsonschema
import pytest

from conftest import ROOT, SMALL

from compare import cli
from compare.commands import parse_max_gap
from compare.export import schema


def run(argv, capsys):
    code = cli.main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.mark.parametrize("text, value", [("15%", 0.15), ("15", 0.15), ("0.5", 0.005),
                                         (" 7.5 % ", 0.075), ("0", 0.0)])
def test_max_gap_is_percent(text, value):
    assert parse_max_gap(text) == pytest.approx(value)


@pytest.mark.parametrize("text", ["abc", "-3", "inf", "nan%", ""])
def test_max_gap_rejects_nonsense(text):
    with pytest.raises(argparse.ArgumentTypeError):
        parse_max_gap(text)


def test_compare_one_program_writes_report_json_csv(fake_engines, small_program, tmp_path,
                                                    capsys):
    rep = tmp_path / "rep"
    js = tmp_path / "out.json"
    code, out, err = run(["compare", small_program, "--report", rep, "--json", js], capsys)
    assert code == 0, err
    assert "gap" in out and "[t_ref/UB - 1, t_ref/LB - 1]" in out
    assert "verdict    ok" in out
    assert f"report: {rep / 'small.html'} (also small.json, small.csv); open file://" in out
    for ext in ("html", "json", "csv"):
        assert (rep / f"small.{ext}").is_file()
    doc = json.loads(js.read_text())
    jsonschema.validate(doc, schema())
    assert doc["program"] == str(small_program)
    assert doc["bounds"] == "acc"
    assert doc["gap"]["lower"] < doc["gap"]["upper"]
    assert doc["verdict"]["ok"] is True
    assert json.loads((rep / "small.json").read_text()) == doc
    csv_lines = (rep / "small.csv").read_text().splitlines()
    assert csv_lines[0].startswith("block,line,label,kind")
    assert len(csv_lines) == 1 + len(doc["blocks"])


def test_gate_fails_with_offending_blocks(fake_engines, small_program, tmp_path, capsys):
    code, out, err = run(["compare", small_program, "--no-report", "--max-gap", "1%"], capsys)
    assert code == 1
    assert f"FAIL {small_program}: gap above gate" in err
    assert "line 3 N20 (G1):" in err                        # an offending block, by line
    assert "ms, heuristic limited by" in err
    assert not (tmp_path / "reports").exists()


def test_gate_passes_above_the_upper_end(fake_engines, small_program, capsys):
    code, out, err = run(["compare", small_program, "--no-report", "--max-gap", "90"], capsys)
    assert code == 0, err
    assert "within the gate of 90 %" in out


def test_several_programs_one_table_one_index(fake_engines, tmp_path, capsys):
    a = tmp_path / "a" / "part.mpf"
    b = tmp_path / "b" / "part.mpf"
    c = tmp_path / "line.ngc"
    for p in (a, b):
        p.parent.mkdir()
        p.write_text(SMALL)
    c.write_text("G21 G90 G64\nG1 X40 F1200\nG1 Y30\nM2\n")
    rep = tmp_path / "rep"
    js = tmp_path / "all.json"
    code, out, err = run(["compare", a, b, c, "--report", rep, "--json", js,
                          "--max-gap", "50%"], capsys)
    assert code == 0, err
    lines = out.splitlines()
    assert lines[0].split()[:4] == ["program", "t_ref_s", "LB_s", "UB_s"]
    assert sum(str(p) in out for p in (a, b, c)) == 3
    assert "gate: gap upper end (t_ref-H)/(LB-H) - 1 <= 50 %" in out
    assert f"report: {rep / 'index.html'}; open file://" in out
    index = (rep / "index.html").read_text()
    for stem in ("a_part", "b_part", "line"):                # colliding stems kept apart
        assert f"href='{stem}.html'" in index
        assert (rep / f"{stem}.html").is_file()
    docs = json.loads(js.read_text())
    assert isinstance(docs, list) and len(docs) == 3
    for d in docs:
        jsonschema.validate(d, schema())


def test_quiet_and_piped_output_is_clean(fake_engines, small_program, capsys):
    for extra in ([], ["--quiet"]):
        code, out, err = run(["compare", small_program, "--no-report", *extra], capsys)
        assert code == 0
        assert "\r" not in out + err and "\x1b" not in out + err


def test_progress_on_a_terminal(fake_engines, small_program, monkeypatch, capsys):
    seen = []

    class TTYProgress(cli.Progress):
        def __call__(self, message, fraction=-1.0):
            seen.append(message)

    monkeypatch.setattr(cli, "Progress", TTYProgress)
    assert cli.main(["compare", str(small_program), "--report",
                     str(small_program.parent / "r")]) == 0
    assert any("writing report" in m for m in seen)


def _cli(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "compare", *map(str, args)],
                          capture_output=True, text=True, cwd=cwd)


@pytest.mark.parametrize("case", ["missing", "syntax", "bounds", "max_gap", "machine"])
def test_bad_input_exits_2_without_traceback(case, tmp_path):
    prog = tmp_path / "p.mpf"
    prog.write_text("G1 X10 F1000\nG1 Y10\n")
    args = {"missing": ["compare", tmp_path / "nope.mpf"],
            "syntax": ["compare", tmp_path / "bad.mpf"],
            "bounds": ["compare", prog, "--bounds", "snap", "--no-report"],
            "max_gap": ["compare", prog, "--max-gap", "lots"],
            "machine": ["compare", prog, "--machine", tmp_path / "m.toml"]}[case]
    (tmp_path / "bad.mpf").write_text("G1 X10 F100\nG1 Y1O\n")
    (tmp_path / "m.toml").write_text("[machine]\nipo_cycle_ms = -4\n")
    r = _cli(*args)
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr
    assert r.stderr.strip()
    if case == "missing":
        assert "nope.mpf" in r.stderr
    if case == "syntax":
        assert f"{tmp_path / 'bad.mpf'}:2:" in r.stderr
    if case == "bounds":
        # every bound set is solvable now (jerk+freq since issue 12): an unknown one
        assert "snap" in r.stderr
    if case == "max_gap":
        assert "--max-gap 'lots'" in r.stderr

"""``feedoracle inspect`` on the corpus and its error behaviour (exit 2, no traceback)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from compare.cli import main
from shared_inputs import NO_CORPUS, corpus_listing

ROOT = Path(__file__).resolve().parents[1]
CORPUS_FILES = sorted(p for p in corpus_listing("*") if p.suffix.lower() in
                      (".mpf", ".spf", ".ngc", ".nc", ".tap"))


@pytest.mark.skipif(not CORPUS_FILES, reason=NO_CORPUS)
@pytest.mark.parametrize("prog", CORPUS_FILES, ids=lambda p: p.name)
def test_inspect_every_corpus_program(prog: Path, capsys) -> None:
    assert main(["inspect", str(prog)]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"program {prog}")
    assert "segments" in out.splitlines()[0]


def test_inspect_table_lists_every_block(tmp_path: Path, capsys) -> None:
    prog = tmp_path / "p.mpf"
    prog.write_text("N10 G90 G64 F6000\nN20 G1 X10 Y0\nN30 G4 F0.5\nN40 G9 G1 X20\n"
                    "N50 G2 X30 CR=5\nM30\n")
    assert main(["inspect", str(prog)]) == 0
    out = capsys.readouterr().out.splitlines()
    rows = out[2:]
    assert [r.split()[0] for r in rows] == ["1", "2", "3", "4", "5", "6"]
    assert "dwell G4 0.5 s" in rows[2]
    assert "exact stop G9" in rows[3]


def test_syntax_error_is_file_line_col_and_exit_2(tmp_path: Path) -> None:
    prog = tmp_path / "bad.mpf"
    prog.write_text("G1 X10 F100\nG1 Y1O\n")
    r = subprocess.run([sys.executable, "-m", "compare", "inspect", str(prog)],
                       capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 2
    assert r.stderr.startswith(f"feedoracle: {prog}:2:")
    assert "Traceback" not in r.stderr


def test_bad_machine_data_exit_2(tmp_path: Path) -> None:
    prog = tmp_path / "p.mpf"
    prog.write_text("G1 X10 F100\n")
    m = tmp_path / "m.toml"
    m.write_text("[machine]\nipo_cycle_ms = 4\n[axis.X]\nMAX_AX_VELO = 1000\n")
    r = subprocess.run([sys.executable, "-m", "compare", "inspect", str(prog),
                        "--machine", str(m)], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 2
    assert "axis.X.MAX_AX_ACCEL = None: is required" in r.stderr
    assert "Traceback" not in r.stderr


def test_missing_program_file_exit_2(tmp_path: Path) -> None:
    r = subprocess.run([sys.executable, "-m", "compare", "inspect", str(tmp_path / "no.mpf")],
                       capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 2 and "no.mpf" in r.stderr and "Traceback" not in r.stderr


def test_usage_error_exit_2() -> None:
    r = subprocess.run([sys.executable, "-m", "compare", "inspect"], capture_output=True,
                       text=True, cwd=ROOT)
    assert r.returncode == 2 and "Traceback" not in r.stderr


def test_an_internal_error_exits_3_with_one_line_and_the_traceback_only_with_debug(
        monkeypatch, capsys):
    """A bug is never bad input (2) nor a gap (1): exit 3, one line, --debug for more."""
    from compare import cli

    def broken(*args, **kwargs):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(cli, "load_inputs", broken)
    assert cli.main(["inspect", "whatever.mpf"]) == 3
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "internal error" in err and "--debug" in err
    assert "Traceback" not in err
    assert cli.main(["inspect", "whatever.mpf", "--debug"]) == 3
    err = capsys.readouterr().err
    assert "Traceback" in err and "ZeroDivisionError" in err

"""The real heuristic and the real oracle through compare, reports, JSON and exit codes.

One program (the bundled demo) goes through plan + solve + compare + HTML + JSON schema
validation + exit codes; the heuristic's own IPO-cycle CSV read back by ``check``
reproduces its numbers; the CI gate's thresholds in examples/gate.txt hold.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import jsonschema
import numpy as np
import pytest

from conftest import ROOT

from compare import cli
from compare.commands import parse_max_gap
from compare.comparison import compare
from compare.export import schema
from reference.machine import load_machine
from reference.nc import parse_file

DEMO = ROOT / "examples" / "demo.mpf"
SLOT = ROOT / "examples" / "slot.ngc"
GATE = ROOT / "examples" / "gate.txt"

pytestmark = pytest.mark.xdist_group("end_to_end")


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    """``feedoracle compare examples/demo.mpf`` with report and JSON (run once)."""
    out = tmp_path_factory.mktemp("demo")
    r = subprocess.run([sys.executable, "-m", "compare", "compare", str(DEMO), "--report",
                        str(out / "rep"), "--json", str(out / "demo.json")],
                       capture_output=True, text=True, cwd=ROOT, timeout=600)
    return r, out


def test_demo_compare_exit_0_report_and_valid_json(demo):
    r, out = demo
    assert r.returncode == 0, r.stdout + r.stderr
    assert "Traceback" not in r.stderr
    doc = json.loads((out / "demo.json").read_text())
    jsonschema.validate(doc, schema())
    ref, orc, gap = doc["reference"], doc["oracle"], doc["gap"]
    assert orc["status"] == "optimal"
    assert 0 < orc["lower_bound_s"] <= orc["upper_bound_s"] <= ref["time_s"]
    # the gap compares motion times: the holds (the G9 settle, the G4 dwell) are in
    # both totals and in no gap
    H = sum(b["hold_s"] for b in doc["blocks"])
    assert H == pytest.approx(gap["hold_s"], rel=1e-12) and H > 0.2      # dwell 0.2 s + settle
    assert gap["lower"] == pytest.approx((ref["time_s"] - H) / (orc["upper_bound_s"] - H) - 1)
    assert gap["upper"] == pytest.approx((ref["time_s"] - H) / (orc["lower_bound_s"] - H) - 1)
    assert ref["violations"] == [] and orc["violations"] == []
    # per-block accounting on both sides
    assert sum(b["t_reference_s"] for b in doc["blocks"]) == pytest.approx(ref["time_s"],
                                                                          rel=1e-9)
    assert sum(b["t_oracle_s"] for b in doc["blocks"]) == pytest.approx(
        orc["upper_bound_s"], rel=1e-9)
    causes = {b["limit_reference"] for b in doc["blocks"]} | \
        {b["limit_oracle"] for b in doc["blocks"]}
    assert causes <= {"feed", "axis velocity", "axis acceleration", "jerk", "frequency",
                      "corner rule", "look-ahead horizon", "IPO-cycle cap", "exact stop",
                      "forced stop", "dwell", "exact stop settle", "none", "-"}
    holds = {b["line"]: (b["hold_cause"], b["hold_s"]) for b in doc["blocks"] if b["hold_s"]}
    assert set(holds) == {24, 25}                     # N200 G9 and N210 G4 F0.2
    assert holds[24][0] == "exact stop settle" and holds[25] == ("dwell", 0.2)
    html = (out / "rep" / "demo.html").read_text()
    assert html.count('<img class="plot"') == 4
    assert f"report: {out / 'rep' / 'demo.html'}" in r.stdout


def test_library_api_block_times_sum_to_totals():
    from reference.planner import plan
    import optimal
    machine = load_machine(None)
    program = parse_file(DEMO)
    p = plan(program, machine)
    sol = optimal.solve(p.path, machine.limits, bounds="acc", holds=p.holds)
    c = compare(p, sol, program=program)
    assert sum(r.t_reference_s for r in c.rows) == pytest.approx(p.profile.duration, rel=1e-12)
    assert sum(r.t_oracle_s for r in c.rows) == pytest.approx(sol.upper_bound_s, rel=1e-12)
    assert c.gap_lower <= c.gap_upper
    assert not c.gap_lower_valid                     # SOFT heuristic vs the acc oracle
    assert c.verdict(None).ok
    by_line = {r.line: r for r in c.rows}
    assert by_line[24].stop_reason == "exact stop G9" and by_line[24].v_exit_reference == 0.0


def test_gate_fails_and_names_blocks(tmp_path, capsys):
    code = cli.main(["compare", str(DEMO), "--no-report", "--quiet", "--max-gap", "5%"])
    err = capsys.readouterr().err
    assert code == 1
    assert f"FAIL {DEMO}: gap above gate" in err
    # the G9 block's settle is the machine's wait, not a gap: the largest gap is elsewhere
    assert "  line 27 N230 (G2):" in err and "line 24 N200" not in err


def test_heuristic_csv_read_back_reproduces_its_numbers(tmp_path, capsys):
    csv, pj, cj = tmp_path / "ipo.csv", tmp_path / "plan.json", tmp_path / "check.json"
    assert cli.main(["plan", str(DEMO), "--csv", str(csv), "--json", str(pj)]) == 0
    code = cli.main(["check", str(csv), "--program", str(DEMO), "--json", str(cj)])
    out = capsys.readouterr().out
    assert code == 0, out
    plan_doc, check_doc = json.loads(pj.read_text()), json.loads(cj.read_text())
    jsonschema.validate(plan_doc, schema())
    jsonschema.validate(check_doc, schema())
    assert check_doc["reference"]["time_s"] == pytest.approx(plan_doc["reference"]["time_s"],
                                                             abs=1e-9)
    t_plan = {b["block"]: b["t_reference_s"] for b in plan_doc["blocks"]}
    err = [abs(b["t_reference_s"] - t_plan[b["block"]]) for b in check_doc["blocks"]]
    t_ipo = load_machine(None).limits.t_ipo_s
    assert max(err) <= t_ipo                          # within one IPO cycle per block
    assert check_doc["recorded"]["max_deviation_mm"] < 1e-6
    assert check_doc["reference"]["violations"] == []


def test_optimize_json_and_csv(tmp_path, capsys):
    js, csv = tmp_path / "o.json", tmp_path / "o.csv"
    assert cli.main(["optimize", str(SLOT), "--json", str(js), "--csv", str(csv)]) == 0
    doc = json.loads(js.read_text())
    jsonschema.validate(doc, schema())
    assert doc["bounds"] == "acc" and doc["oracle"]["status"] == "optimal"
    data = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert csv.read_text().splitlines()[0] == "t,s,v,X,Y,Z"
    assert data[-1, 0] == pytest.approx(doc["oracle"]["upper_bound_s"])


def test_gate_thresholds_hold_today():
    lines = [ln.split() for ln in GATE.read_text().splitlines()
             if ln.strip() and not ln.startswith("#")]
    assert lines
    for prog, gap in lines:
        r = subprocess.run([sys.executable, "-m", "compare", "compare", prog, "--no-report",
                            "--quiet", "--max-gap", gap], capture_output=True, text=True,
                           cwd=ROOT, timeout=600)
        assert r.returncode == 0, f"{prog}: {r.stdout}{r.stderr}"
        assert parse_max_gap(gap) > 0


def test_compare_with_jerk_bounds(tmp_path, capsys):
    """``--bounds jerk``: the jerk oracle end to end; ``auto`` picks ``jerk`` for a SOFT
    program (issue 11 item 5: the gap under the planner's own limits) and ``acc`` for the
    same program under BRISK."""
    prog = tmp_path / "soft.mpf"
    prog.write_text("N10 G90 G64 SOFT F3000\nN20 G1 X20\nN30 G1 Y10\nN40 G1 X30\nM30\n")
    js = tmp_path / "j.json"
    assert cli.main(["compare", str(prog), "--bounds", "jerk", "--no-report", "--json",
                     str(js)]) == 0
    doc = json.loads(js.read_text())
    jsonschema.validate(doc, schema())
    assert doc["bounds"] == "jerk"
    orc, ref = doc["oracle"], doc["reference"]
    assert orc["status"] == "optimal"
    assert orc["upper_bound_s"] <= orc["lower_bound_s"] * 1.01
    # the heuristic keeps jerk limits too, so it can be no faster than the jerk LB
    assert 0 < orc["lower_bound_s"] <= orc["upper_bound_s"]
    assert orc["lower_bound_s"] <= ref["time_s"]
    js2 = tmp_path / "a.json"
    assert cli.main(["compare", str(prog), "--no-report", "--json", str(js2)]) == 0
    doc2 = json.loads(js2.read_text())
    assert doc2["bounds"] == "jerk"
    assert doc2["oracle"]["lower_bound_s"] == pytest.approx(orc["lower_bound_s"], rel=1e-9)
    brisk = tmp_path / "brisk.mpf"
    brisk.write_text(prog.read_text().replace("SOFT", "BRISK"))
    js3 = tmp_path / "b.json"
    assert cli.main(["compare", str(brisk), "--no-report", "--json", str(js3)]) in (0, 1)
    assert json.loads(js3.read_text())["bounds"] == "acc"
    capsys.readouterr()

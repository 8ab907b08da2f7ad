"""The compiled LookAhead loops (reference.planner.lookahead_kernel) give the speeds and
merges of the Python passes, bit for bit.

The reference is the Python implementation in :mod:`reference.planner.lookahead` (the
vectorised decisions plus the chains walked one step at a time), run with
``compiled=False`` on the same inputs: random units of every mode (BRISK, SOFT, DRIVE
with a knee, mixed; caps with zeros, equal neighbours and ``inf``), and the units and
merges the planner builds for the seeded programs of ``tests/bench/bench_rounding.py``
(rounded and not, BRISK and SOFT).
"""

from __future__ import annotations

import tomllib
from importlib import resources

import numpy as np
import pytest

import reference.planner.engine as engine
import reference.planner.lookahead as lookahead
from reference.machine import load_machine, machine_from_dict
from reference.nc import parse_text
from reference.planner import plan
from reference.planner.lookahead import Units, lookahead_passes
from seeded_programs import (arc_chain, line_arc_chain, polyline, s_bend_chain,
                             same_way_chain)

FIELDS = ("v", "backward", "origin_cause", "accel_limited")


def _same(a, b) -> None:
    for f in FIELDS:
        x, y = getattr(a, f), getattr(b, f)
        assert x.dtype == y.dtype and x.shape == y.shape, f
        assert np.array_equal(x, y), (f, np.flatnonzero(x != y)[:10])


def random_units(seed: int, n: int, kind: str) -> Units:
    """``n`` units of ``kind`` ('brisk', 'soft', 'drive' or 'mixed') with random lengths,
    limits and node caps (some zero, some equal to a neighbour, some ``inf``)."""
    rng = np.random.default_rng(seed)
    length = rng.uniform(0.001, 5.0, n) * rng.choice([1.0, 0.01], n)
    acc = rng.uniform(200.0, 5000.0, n)
    jerk = rng.uniform(2e3, 1e5, n)
    pick = {"brisk": 0, "soft": 1, "drive": 2}
    mode = rng.integers(0, 3, n) if kind == "mixed" else np.full(n, pick[kind])
    jerk = np.where(mode == 1, jerk, np.inf)
    knee = np.where(mode == 2, rng.uniform(10.0, 80.0, n), np.inf)
    ratio = np.where(mode == 2, rng.uniform(0.2, 1.0, n), 1.0)
    cap = rng.uniform(0.0, 150.0, n + 1)
    cap[rng.random(n + 1) < 0.05] = 0.0
    eq = np.flatnonzero(rng.random(n) < 0.05)
    cap[eq + 1] = cap[eq]
    cap[rng.random(n + 1) < 0.02] = np.inf
    cap[0] = cap[-1] = 0.0
    acc_dn = acc * rng.uniform(0.5, 1.0, n)
    jerk_dn = jerk * rng.uniform(0.5, 1.0, n)
    z = np.zeros(n, dtype=bool)
    cause = rng.integers(0, 5, n + 1)
    return Units(first_segment=np.arange(n), n_segments=np.ones(n, dtype=np.int64),
                 node_break=np.arange(n + 1), s_start=np.cumsum(length) - length,
                 length=length, cap=np.full(n, 150.0), cap_cause=np.zeros(n, np.int64),
                 acc_up=acc, jerk_up=jerk, acc_dn=acc_dn, jerk_dn=jerk_dn,
                 frequency=np.full(n, 10.0), jerk_limited=np.isfinite(jerk), node_cap=cap,
                 node_cause=cause, adapted_up=z, adapted_dn=z.copy(), knee=knee,
                 knee_ratio=ratio)


@pytest.mark.parametrize("kind", ("brisk", "soft", "drive", "mixed"))
@pytest.mark.parametrize("seed", range(4))
def test_compiled_passes_equal_the_python_passes_on_random_units(kind, seed):
    units = random_units(seed, 3000, kind)
    py = lookahead_passes(units, compiled=False)
    _same(py, lookahead_passes(units, compiled=True))
    # not vacuous: both passes bind somewhere
    assert np.any(py.backward < units.node_cap) and py.accel_limited.any()


def _programs():
    """Name -> (program text, PATH_TRANS_POS_TOL in mm or None for the machine's)."""
    n = 300
    body, chain = polyline(n, 13), line_arc_chain(n, 5)
    kinked = line_arc_chain(n, 5, kink_deg=60.0)
    head = "G17 G90 {} {} F{}\n"
    progs = {}
    for acc in ("BRISK", "SOFT"):
        for mode in ("G64", "G641 ADIS=0.2", "G642 CTOL=0.02", "G645 CTOL=0.02"):
            progs[f"polyline {mode} {acc}"] = (
                f"G90 {mode} {acc} F6000\nG1 X0 Y0\nG1 " + body, None)
        for mode in ("G64", "G645"):
            start = head.format(mode, acc, 6000) + "G1 X0 Y0\n"
            progs[f"line-arc {mode} {acc}"] = (start + chain, None)
            progs[f"corners {mode} {acc}"] = (start + kinked, None)
            progs[f"arcs {mode} {acc}"] = (start.replace(mode, mode + " CTOL=0.02")
                                           + arc_chain(n, 5), None)
            # MD33120 0.05 mm, as in the benchmark: most of them rounded
            progs[f"s-bends {mode} {acc}"] = (head.format(mode, acc, 8000)
                                              + s_bend_chain(n, 5), 0.05)
            progs[f"same-way {mode} {acc}"] = (head.format(mode, acc, 8000)
                                               + same_way_chain(n, 5), 0.05)
    return progs


def _machine(tol_mm):
    """The default machine, with PATH_TRANS_POS_TOL = ``tol_mm`` on every axis if given."""
    if tol_mm is None:
        return load_machine()
    d = tomllib.loads(resources.files("reference.machines").joinpath("default.toml")
                      .read_text())
    for ax in d["axis"].values():
        ax["PATH_TRANS_POS_TOL"] = tol_mm
    return machine_from_dict(d)


PROGRAMS = _programs()


@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_compiled_loops_equal_the_python_loops_in_the_planner(monkeypatch, name):
    """Every call of the passes and of the merges while planning the program: the
    compiled loops give the Python loops' answer; and the plan is the same."""
    passes, merges = lookahead.lookahead_passes, lookahead._merge_flags
    calls = []

    def spy_passes(units, compiled=None):
        py = passes(units, compiled=False)
        _same(py, passes(units, compiled=True))
        calls.append("passes")
        return py

    def spy_merges(*args, compiled=None):
        py = merges(*args, compiled=False)
        assert np.array_equal(py, merges(*args, compiled=True))
        calls.append("merges")
        return py

    text, tol = PROGRAMS[name]
    machine = _machine(tol)
    prog = parse_text(text)
    with monkeypatch.context() as mp:
        mp.setattr(engine, "lookahead_passes", spy_passes)
        mp.setattr(lookahead, "_merge_flags", spy_merges)
        ref = plan(prog, machine, check=False)
    assert "passes" in calls and "merges" in calls
    if "G645" in name and "SOFT" in name and not name.startswith("arcs"):
        # not vacuous: the rounding inserted blocks (the arc-arc corners' roundings
        # under SOFT G645 cost time on this machine: none)
        assert int(ref.path.rounding.inserted.sum()) > 0
    with monkeypatch.context() as mp:
        mp.setattr(lookahead, "PASSES_COMPILED_MIN_UNITS", 0)
        fast = plan(prog, machine, check=False)
    assert fast.time_s == ref.time_s
    for f in ("t", "s", "v", "a", "j"):
        assert np.array_equal(getattr(fast.profile, f), getattr(ref.profile, f)), f

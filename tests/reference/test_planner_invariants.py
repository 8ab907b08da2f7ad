"""Reference planner invariants: it never breaks the limits it declares.

Every profile it produces passes ``check_profile`` under its own bound set (BRISK: v, a,
feed, the G64 jump allowance and stops; SOFT: also jerk) on seeded random programs
(lines, arcs, helices, rapid moves, rotary axes, tiny collinear runs, dwell, exact stops,
BRISK/SOFT changes) for several machines and channel settings, and on the corpus files
in ``../shared/corpus``. The number of random programs per machine is
``FEEDORACLE_RANDOM_CASES`` (default 12; a nightly run can raise it).
"""

from __future__ import annotations

import copy
import os
import tomllib
from importlib import resources
from pathlib import Path as FsPath

import numpy as np
import pytest

from reference.core.constraints import BOUND_SETS
from reference.machine import load_machine, machine_from_dict
from reference.nc import parse_file, parse_text
from reference.planner import plan
from shared_inputs import corpus_listing, needs_corpus

N_RANDOM = int(os.environ.get("FEEDORACLE_RANDOM_CASES", "12"))
DEFAULT_DICT = tomllib.loads(resources.files("reference.machines").joinpath(
    "default.toml").read_text())


def _machine(channel=None, axes_all=None, ipo_ms=None, extra_axes=()):
    d = copy.deepcopy(DEFAULT_DICT)
    d["channel"].update(channel or {})
    for ax in d["axis"]:
        d["axis"][ax].update(axes_all or {})
    for ax in extra_axes:
        d["axis"].setdefault(ax, copy.deepcopy(DEFAULT_DICT["axis"]["X"]))
    if ipo_ms is not None:
        d["machine"]["ipo_cycle_ms"] = ipo_ms
    return machine_from_dict(d, "<test>")


MACHINES = {
    "default": _machine(),
    "ovl1-short-horizon": _machine({"lookahead_blocks": 2},
                                   {"MAX_ACCEL_OVL_FACTOR": 1.0}),
    "factors": _machine({"LOOKAH_SMOOTH_FACTOR": 100.0, "ADAPT_PATH_DYNAMIC": [1.5, 2.0]},
                        {"SOFT_ACCEL_FACTOR": 0.7, "G00_ACCEL_FACTOR": 1.5,
                         "G00_JERK_FACTOR": 0.5, "PATH_TRANS_JERK_LIM": 5.0,
                         "MAX_ACCEL_OVL_FACTOR": 1.5}),
    "brisk-1ms": _machine({"acceleration_mode": "BRISK", "lookahead_blocks": 3,
                           "LOOKAH_SMOOTH_FACTOR": 50.0, "ADAPT_PATH_DYNAMIC": [2.0, 2.0]},
                          ipo_ms=1.0),
}


def random_program(seed: int, n: int = 60) -> str:
    """A SINUMERIK program mixing every motion and mode the planner handles."""
    rng = np.random.default_rng(seed)
    lines = [f"G90 G17 F{rng.integers(300, 12000)}", str(rng.choice(["SOFT", "BRISK", ""])),
             str(rng.choice(["G64", "G60", "G641 ADIS=0.5", "G64"]))]
    x = y = z = a = 0.0
    for _ in range(n):
        r = rng.random()
        words = []
        if rng.random() < 0.08:
            words.append(str(rng.choice(["SOFT", "BRISK"])))
        if rng.random() < 0.08:
            words.append(str(rng.choice(["G64", "G60", "G642", "G9"])))
        if rng.random() < 0.05:
            words.append(str(rng.choice(["G601", "G602", "G603"])))
        if rng.random() < 0.1:
            words.append(f"F{rng.integers(100, 15000)}")
        scale = 10 ** rng.uniform(-2, 2)
        if r < 0.5:                                   # line (3D sometimes, rapid, A axis)
            dx, dy = rng.normal(0, scale, 2)
            dz = rng.normal(0, scale) if rng.random() < 0.3 else 0.0
            x, y, z = x + dx, y + dy, z + dz
            w = f"{'G0' if rng.random() < 0.1 else 'G1'} X{x:.4f} Y{y:.4f} Z{z:.4f}"
            if rng.random() < 0.1:
                a += rng.normal(0, 30)
                w += f" A{a:.3f}"
            words.append(w)
        elif r < 0.75:                                # arc or helix by centre offset
            ang0 = rng.uniform(0, 2 * np.pi)
            cx, cy = x - scale * np.cos(ang0), y - scale * np.sin(ang0)
            sweep = rng.uniform(0.05, 2 * np.pi - 0.05) * (1 if rng.random() < 0.5 else -1)
            x1, y1 = cx + scale * np.cos(ang0 + sweep), cy + scale * np.sin(ang0 + sweep)
            w = f"{'G3' if sweep > 0 else 'G2'} X{x1:.6f} Y{y1:.6f} I{cx - x:.6f} J{cy - y:.6f}"
            if rng.random() < 0.3:
                z += rng.normal(0, scale)
                w += f" Z{z:.4f}"
            x, y = x1, y1
            words.append(w)
        elif r < 0.85:                                # line along X
            x += scale
            words.append(f"G1 X{x:.4f} Y{y:.4f}")
        elif r < 0.9:
            lines.append(f"G4 F{rng.uniform(0.01, 0.3):.3f}")
            continue
        elif r < 0.95:                                # tiny collinear blocks
            for _ in range(int(rng.integers(3, 30))):
                x += 0.02
                lines.append(f"G1 X{x:.4f} Y{y:.4f}")
            continue
        else:
            words.append("M3 S1000" if rng.random() < 0.5 else f"G1 X{x:.4f} Y{y:.4f}")
        lines.append(" ".join(words))
    lines.append("M30")
    return "\n".join(lines) + "\n"


def _assert_keeps_its_bounds(p, what: str) -> None:
    assert p.report is not None
    viol = p.report.violations(BOUND_SETS[p.bound_set])
    assert not viol, (what, p.bound_set, [(v.constraint, v.ratio, v.axis, v.s, v.block)
                                          for v in viol])
    assert np.all(np.isfinite(p.profile.v)) and np.all(p.profile.v >= 0)
    assert sum(b.time_s for b in p.blocks) == pytest.approx(p.time_s, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("name", list(MACHINES))
@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_random_programs_keep_the_declared_bounds(seed: int, name: str):
    prog = parse_text(random_program(seed), f"random{seed}.mpf")
    p = plan(prog, MACHINES[name])
    _assert_keeps_its_bounds(p, f"seed {seed} machine {name}")


#: DRIVE with a knee on every axis (hyperbolic and constant characteristics mixed), with
#: adaptation: the BRISK blocks of the random programs run in DRIVE.
DRIVE_MACHINE = _machine({"ADAPT_PATH_DYNAMIC": [1.5, 1.0]},
                         {"ACCEL_REDUCTION_SPEED_POINT": 0.05, "ACCEL_REDUCTION_FACTOR": 0.6,
                          "ACCEL_TYPE_DRIVE": 1})


@pytest.mark.parametrize("seed", range(N_RANDOM))
def test_random_drive_programs_keep_the_declared_bounds(seed: int):
    text = random_program(seed).replace("BRISK", "DRIVE")
    p = plan(parse_text(text, f"drive{seed}.mpf"), DRIVE_MACHINE)
    _assert_keeps_its_bounds(p, f"seed {seed} DRIVE")


def _corpus_files() -> list[FsPath]:
    return sorted(f for f in corpus_listing() if f.suffix.lower() in (".ngc", ".mpf"))


@needs_corpus
@pytest.mark.parametrize("file", _corpus_files(), ids=lambda f: f.name)
def test_corpus_programs_keep_the_declared_bounds(file: FsPath):
    prog = parse_file(file)
    default = MACHINES["default"]
    missing = [a for a in prog.axes if a not in default.limits.names]
    machines = {"default": _machine(extra_axes=missing) if missing else default}
    if file.name.startswith("lcnc_"):
        machines["linuxcnc_xyz"] = load_machine("linuxcnc_xyz")
    for name, m in machines.items():
        p = plan(prog, m)
        _assert_keeps_its_bounds(p, f"{file.name} on {name}")
        assert p.time_s > 0

"""Check that a speed-up changed no result: dump, then compare, built paths and plans.

``python tests/bench/same_results.py dump OUT.pkl`` (before the change) and again after
it, then ``python tests/bench/same_results.py compare BEFORE.pkl AFTER.pkl``. The
programs: every corpus program (``../shared/corpus``; the LinuxCNC ones converted, each
under G64 and the rounding modes, BRISK and SOFT, :func:`corpus_in_mode`), the
short-segment program under G642, and seeded polylines, line-arc chains (with and
without corners next to the arcs) and arc chains (corners between two arcs) under G64
and the rounding modes, and chains of tangent arcs (S-bends, arcs curving the same way)
under G64 and G645; on both bundled machines; and a seeded S-bend chain under G64 and
G645 on both with PATH_TRANS_POS_TOL = 0.05 mm (most of them rounded). Per case: every
segment array of the built path, its rounding table and block spans, and of the plan
(with its own check) the profile, total time, block rows, corner
rows and trace (less its wall time). ``compare`` prints the largest relative difference
``|a - b| / max(1, |a|)`` of the float columns and every mismatch; a speed-up that only
reorders work must show 0 (bit-identical), and at most round-off otherwise. Where
``../shared`` is absent the corpus cases are left out (saying so on stderr); ``compare``
then reports "different cases" against a dump that has them.
"""

from __future__ import annotations

import dataclasses
import pickle
import sys
import types
from pathlib import Path as FsPath

import numpy as np

HERE = FsPath(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))
sys.path.insert(0, str(HERE.parent / "reference"))
# tests/: shared_inputs, the one place that says where ../shared is
sys.path.insert(0, str(HERE.parent))

from corpus_sinumerik import corpus_in_mode, short_segments_g642  # noqa: E402
from shared_inputs import CORPUS_PRESENT, NO_CORPUS, corpus_listing  # noqa: E402
from reference.machine import load_machine  # noqa: E402
from reference.nc import parse_text  # noqa: E402
from reference.planner import plan  # noqa: E402
from reference.prepare import build_path  # noqa: E402
from bench_rounding import _with_trans_tol  # noqa: E402
from seeded_programs import (arc_chain, line_arc_chain, polyline, s_bend_chain,  # noqa: E402
                             same_way_chain)

MODES = ("G64", "G641 ADIS=0.2", "G642", "G642 CTOL=0.02", "G645", "G645 CTOL=0.05",
         "G643", "G644")
PATH_FIELDS = ("origin", "e1", "e2", "d", "radius", "omega", "theta0", "length", "block",
               "kind", "dradius", "sharpness", "feed", "rapid", "stop", "stop_reason",
               "s_breaks")
#: Largest relative difference ``compare`` accepts as round-off.
ROUNDOFF_REL = 1e-9


def programs(n: int = 1500) -> dict[str, str]:
    """Name -> program text of every case."""
    progs = {}
    if not CORPUS_PRESENT:
        print(f"corpus cases left out: {NO_CORPUS}", file=sys.stderr)
    for f in corpus_listing():
        if f.suffix not in (".ngc", ".mpf"):
            continue
        if f.suffix == ".mpf":
            progs[f.name] = f.read_text()
        for mode in MODES:
            for acc in ("BRISK", "SOFT"):
                progs[f"{f.name}|{mode} {acc}"] = corpus_in_mode(f.name, f"{mode} {acc}")
    if CORPUS_PRESENT:
        progs["short_segments_g642"] = short_segments_g642()
    body = polyline(n, 13)
    for acc in ("BRISK", "SOFT"):
        for mode in MODES + ("G641 ADIS=0.2 ADISPOS=0.1",):
            progs[f"polyline|{mode} {acc}"] = f"G90 {mode} {acc} F6000\nG1 X0 Y0\nG1 " + body
        for kink in (0.0, 60.0):
            chain = line_arc_chain(n, 5, kink_deg=kink)
            for mode in ("G64", "G645", "G642 CTOL=0.02", "G641 ADIS=0.2", "G643", "G644"):
                progs[f"chain{kink:g}|{mode} {acc}"] = \
                    f"G17 G90 {mode} {acc} F6000\nG1 X0 Y0\n" + chain
        arcs = arc_chain(n, 5)
        for mode in ("G64", "G642 CTOL=0.02", "G641 ADIS=0.2", "G645 CTOL=0.02", "G643",
                     "G644", "G642"):
            progs[f"arcs|{mode} {acc}"] = f"G17 G90 {mode} {acc} F6000\nG1 X0 Y0\n" + arcs
        # tangential transitions between arcs (G645): S-bends and arcs curving the same way
        for name, chain in (("sbends", s_bend_chain(n // 5, 5, r_min=5.0)),
                            ("sameway", same_way_chain(n // 5, 5))):
            for mode in ("G64", "G645"):
                progs[f"{name}|{mode} {acc}"] = f"G17 G90 {mode} {acc} F8000\n" + chain
    return progs


def _plain(x):
    """Nested dicts, lists and arrays of ``x`` (picklable, comparable)."""
    if isinstance(x, (dict, types.MappingProxyType)):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray) and x.dtype == object:
        return [_plain(v) for v in x.tolist()]
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return _plain({f.name: getattr(x, f.name) for f in dataclasses.fields(x)})
    if isinstance(x, (np.ndarray, np.generic, str, bytes, int, float, bool, type(None))):
        return x
    if hasattr(x, "__dict__"):                      # other classes (columnar tables)
        return _plain(vars(x))
    if hasattr(x, "__slots__"):
        return _plain({k: getattr(x, k) for k in x.__slots__ if hasattr(x, k)})
    return x


def sbend_programs(n: int = 1500) -> dict[str, str]:
    """Name -> program text of the S-bend cases (a seeded chain of tangent arcs curving
    alternately), run with MD33120 PATH_TRANS_POS_TOL = 0.05 mm so that G645 rounds
    most of them (:func:`dump`)."""
    chain = s_bend_chain(n, 5)
    return {f"sbends|{mode} {acc}": f"G17 G90 {mode} {acc} F8000\n" + chain
            for acc in ("BRISK", "SOFT") for mode in ("G64", "G645", "G645 CTOL=0.02")}


def dump(out: str) -> None:
    """Build and plan every case on both machines (the S-bend cases on both with
    PATH_TRANS_POS_TOL = 0.05 mm); pickle what they produced."""
    res = {}
    runs = [(name, load_machine(name) if name else load_machine(), programs())
            for name in (None, "linuxcnc_xyz")]
    runs += [(f"{name}@0.05", _with_trans_tol(name, 0.05), sbend_programs())
             for name in ("default", "linuxcnc_xyz")]
    for name, machine, progs in runs:
        for key, text in progs.items():
            try:
                prog = parse_text(text, key.split("|")[0])
                path = build_path(prog, machine)
                r = plan(prog, machine, path=path)
            except Exception as exc:  # an error is a result too: it must not change
                res[(name, key)] = ("error", repr(exc))
                continue
            case = {f: getattr(path, f) for f in PATH_FIELDS}
            case["spans"] = path.blocks
            case["table"] = path.rounding
            case["profile"] = r.profile
            case["time"] = r.time_s
            case["rows"] = [dataclasses.astuple(b) for b in r.blocks]
            case["corners"] = [tuple(c) for c in r.corners]
            case["trace"] = [(s, n.split(" in ")[0] if "wall time" in n else n)
                             for s, n in r.trace]
            case["check_ok"] = r.report.ok
            res[(name, key)] = _plain(case)
    with open(out, "wb") as fh:
        pickle.dump(res, fh)
    print(f"{len(res)} cases, {sum(isinstance(v, tuple) for v in res.values())} errors")


def compare(before: str, after: str) -> int:
    """Print the largest relative difference and the mismatches; 1 if any."""
    with open(before, "rb") as fh:
        a = pickle.load(fh)
    with open(after, "rb") as fh:
        b = pickle.load(fh)
    bad, worst = [], [0.0]

    def walk(x, y, where):
        if isinstance(x, dict):
            if x.keys() != y.keys():
                bad.append((where, "keys"))
                return
            for k in x:
                walk(x[k], y[k], f"{where}.{k}")
        elif isinstance(x, (list, tuple)):
            if len(x) != len(y):
                bad.append((where, "length"))
                return
            for i, (p, q) in enumerate(zip(x, y)):
                walk(p, q, f"{where}[{i}]")
        elif isinstance(x, (np.ndarray, float, np.floating)):
            x, y = np.asarray(x), np.asarray(y)
            if x.shape != y.shape or x.dtype.kind != y.dtype.kind:
                bad.append((where, "shape or dtype"))
            elif x.dtype.kind != "f":
                if not np.array_equal(x, y):
                    bad.append((where, "differs"))
            elif not np.array_equal(~np.isfinite(x), ~np.isfinite(y)) or not np.array_equal(
                    x[~np.isfinite(x)], y[~np.isfinite(y)], equal_nan=True):
                bad.append((where, "nan/inf"))
            elif x.size:
                fin = np.isfinite(x)
                rel = float(np.max(np.abs(x[fin] - y[fin]) / np.maximum(1.0, np.abs(x[fin])),
                                   initial=0.0))
                worst[0] = max(worst[0], rel)
                if rel > ROUNDOFF_REL:
                    bad.append((where, rel))
        elif x != y:
            bad.append((where, f"{x!r} != {y!r}"[:200]))

    if a.keys() != b.keys():
        print("different cases")
        return 1
    for k in a:
        walk(a[k], b[k], str(k))
    print(f"{len(a)} cases, largest relative difference {worst[0]:.3g}, "
          f"{len(bad)} mismatches")
    for item in bad[:40]:
        print("  ", item)
    return 1 if bad else 0


if __name__ == "__main__":
    if sys.argv[1:2] == ["dump"] and len(sys.argv) == 3:
        dump(sys.argv[2])
    elif sys.argv[1:2] == ["compare"] and len(sys.argv) == 4:
        sys.exit(compare(sys.argv[2], sys.argv[3]))
    else:
        sys.exit(__doc__)

"""The frequency oracles against their base oracles on the same path, as ratios.

Path: the stadium of ``bench_jerk.py`` (default machine, 2 laps). At about 1,000 and
10,000 NLP grid intervals (``initial_intervals``; one round, ``tol`` wide open so both
stop after their first verified profile): wall time of ``optimal.solve(bounds="jerk")``
and of ``bounds="jerk+freq"`` (which runs that jerk solve inside, plus four acc solves and
the candidates' checks), and ``freq / jerk``; likewise ``acc+freq`` against ``acc`` (the
``acc`` grid starts at the same size). Also both brackets, and the scaling exponent of
the frequency solve's wall time between the two sizes. A last row runs ``jerk+freq`` at
its default gap (2 %) from 1,000 intervals: the jerk solve then refines its grid and the
oracle re-solves the jerk NLP where the rule finds phases short
(:mod:`optimal.freq.jerk_adapted`), against the one-round jerk solve of the first row.
Then the turn run of the frequency bound (:func:`optimal.freq.humps.humps_bound`, where
its bound comes within HUMP_TURN_MARGIN of the bracket) on
``../shared/corpus/lcnc_arc_arc_sawtooth.ngc`` (``acc+freq``, default gap): the oracle's
wall time and the bound's time with the run and without it (the margin set to 0), and
both brackets; left out where ``../shared`` is absent. (Under the cell ceiling of
:data:`optimal.freq.humps.HUMP_MAX_CELLS` = 100,000 the fine run's own cuts meet the
bracket there, so the run does not follow and both sides of the row do the same work:
the row then shows equal brackets and the machine's noise; under 20,000 the run took
the bracket from 2.06 to 1.67 %.) Before it, the rows of the rule in
the jerk relaxation (:mod:`optimal.freq.windows` and :mod:`optimal.freq.chains`) on
examples/demo.mpf and examples/slot.ngc: their time against the jerk solve, and the
bound with them. Last, the NLP with the rule's rows (:mod:`optimal.freq.phase_nlp`) on
``../shared/corpus/lcnc_sam_tolerance_issue.ngc`` (``acc+freq`` and ``jerk+freq``, default
gap, where the bracket stays open): the oracle's wall time and bracket without it and
with it (without it, ``jerk+freq`` still builds the acc+freq motion its second seed
starts from), and the jerk solve's time; left out where ``../shared`` is absent. Before
it, the peak speed levels of the turn programme on ``lcnc_test_12mmflat.ngc``
(``acc+freq``): the oracle and its bound with one level and with the default two. After
it, the search over free phase ends (:mod:`optimal.freq.free_phases`) on the same program
(``acc+freq``): the oracle's wall time and bracket without it and with it; and the jerk
set's reach caps in the turn programme's envelope (:func:`optimal.jerk.lower.
reach_speed_caps`) on the same program (``jerk+freq``): without them and with them.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path as FsPath

HERE = FsPath(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))    # tests/: shared_inputs (where ../shared is)

import optimal  # noqa: E402
from bench_jerk import stadium_gcode  # noqa: E402
from reference.machine import load_machine  # noqa: E402
from reference.nc import parse_text  # noqa: E402
from reference.prepare import build_path  # noqa: E402

SIZES = (1_000, 10_000)


def main() -> int:
    machine = load_machine(None)
    path = build_path(parse_text(stadium_gcode(), "stadium.mpf"), machine)
    print(f"stadium: {path.n_segments} segments, {path.total_length:.1f} mm, default machine")
    print(f"{'set':>9} {'N':>7} {'base s':>9} {'freq s':>9} {'freq/base':>10}  "
          f"brackets (base | freq)")
    for base in ("acc", "jerk"):
        walls = []
        for n in SIZES:
            opts = dict(initial_intervals=n, tol=1.0)
            t0 = time.perf_counter()
            j = optimal.solve(path, machine.limits, bounds=base, **opts)
            t1 = time.perf_counter()
            f = optimal.solve(path, machine.limits, bounds=f"{base}+freq", **opts)
            t2 = time.perf_counter()
            walls.append((j.grid_points, t2 - t1))
            print(f"{base + '+freq':>9} {j.grid_points:>7} {t1 - t0:>9.2f} {t2 - t1:>9.2f} "
                  f"{(t2 - t1) / (t1 - t0):>10.2f}  [{j.lower_bound_s:.4f}, "
                  f"{j.upper_bound_s:.4f}] | [{f.lower_bound_s:.4f}, {f.upper_bound_s:.4f}]",
                  flush=True)
        (n0, w0), (n1, w1) = walls
        print(f"{'':>9} scaling of the {base}+freq wall time: N^"
              f"{math.log(w1 / w0) / math.log(n1 / n0):.2f}", flush=True)
    # at the default gap the stadium's jerk+freq bracket is open after the candidates
    # above, so the oracle also re-solves the jerk NLP where the rule finds phases short
    # (optimal.freq.jerk_adapted): its cost, against the jerk solve at the same size
    n = SIZES[0]
    t0 = time.perf_counter()
    j = optimal.solve(path, machine.limits, bounds="jerk", initial_intervals=n, tol=1.0)
    t1 = time.perf_counter()
    f = optimal.solve(path, machine.limits, bounds="jerk+freq", initial_intervals=n)
    t2 = time.perf_counter()
    print(f"{'jerk+freq':>9} {j.grid_points:>7} {t1 - t0:>9.2f} {t2 - t1:>9.2f} "
          f"{(t2 - t1) / (t1 - t0):>10.2f}  [{j.lower_bound_s:.4f}, {j.upper_bound_s:.4f}] | "
          f"[{f.lower_bound_s:.4f}, {f.upper_bound_s:.4f}] at the default gap "
          f"({f.status}, {f.gap:.2%})", flush=True)
    for name in ("demo.mpf", "slot.ngc"):
        window_row(machine, name)
    turn_run_row(machine)
    peak_levels_row(machine)
    phase_nlp_row(machine)
    free_phases_row(machine)
    reach_row(machine)
    return 0


def window_row(machine, name: str) -> None:
    """The jerk relaxation with the rule's rows (:mod:`optimal.freq.windows`, and the
    chains of :mod:`optimal.freq.chains`) on a bundled example (examples/demo.mpf's
    plunge needs the windows, examples/slot.ngc's zig-zag the chains): the time of those
    rows and that bound against the jerk solve on the same path, and the bracket with and
    without them."""
    from optimal.freq.chains import chain_rows
    from optimal.freq.windows import rule_envelope, window_lower_bound, window_rows
    from reference.nc import parse_file

    path = build_path(parse_file(HERE.parents[1] / "examples" / name), machine)
    t0 = time.perf_counter()
    j = optimal.solve(path, machine.limits, bounds="jerk")
    t1 = time.perf_counter()
    f = optimal.solve(path, machine.limits, bounds="jerk+freq")
    t2 = time.perf_counter()
    acc = optimal.solve(path, machine.limits, bounds="acc")
    moving = path.moving_axes()
    work = path.restricted(moving) if 0 < moving.size < path.n_axes else path
    lim = machine.limits.for_axes(work.axes)
    hold = j.holds.total_s
    t_up = f.upper_bound_s - hold
    args = (work, lim, machine.limits.t_ipo_s, acc.grid, j.segment_lower_bounds_s, t_up,
            j.holds.break_index)
    t3 = time.perf_counter()
    rule = rule_envelope(work, lim, machine.limits.t_ipo_s, acc.grid, t_up,
                         j.holds.break_index)
    windows = window_rows(*args, rule=rule)
    t4 = time.perf_counter()
    chains = chain_rows(*args, rule=rule)
    t5 = time.perf_counter()
    lb = window_lower_bound(work, lim, machine.limits.t_ipo_s, j.grid,
                            j.segment_lower_bounds_s, windows.joined(chains), t_up,
                            j.holds.break_index)
    t6 = time.perf_counter()
    print(f"{'rows':>9} {name}: jerk {t1 - t0:.2f} s, jerk+freq {t2 - t1:.2f} s; "
          f"the rule's bounds and {windows.value.size} window rows {t4 - t3:.2f} s, "
          f"{chains.value.size} chain rows "
          f"{t5 - t4:.3f} s, relaxation with them {t6 - t5:.2f} s (all: "
          f"x{(t6 - t3) / (t1 - t0):.2f} of the jerk solve); lower bound "
          f"{j.lower_bound_s:.4f} -> {lb + hold:.4f} s; jerk+freq [{f.lower_bound_s:.4f}, "
          f"{f.upper_bound_s:.4f}] {f.gap:.2%} ({f.status})", flush=True)


def _without_and_with(module, name: str, off, path, machine, bounds: str):
    """``(wall s, solution)`` of ``optimal.solve(path, ..., bounds)`` with ``module.name``
    set to ``off``, then as it is (restored whatever happens)."""
    res = []
    real = getattr(module, name)
    try:
        for value in (off, real):
            setattr(module, name, value)
            t0 = time.perf_counter()
            sol = optimal.solve(path, machine.limits, bounds=bounds)
            res.append((time.perf_counter() - t0, sol))
    finally:
        setattr(module, name, real)
    return res


def _toggle_row(machine, label: str, program: str, module, name: str, off) -> None:
    """One row: ``acc+freq`` on a corpus program with ``module.name`` set to ``off`` and
    as it is: the oracle's wall time, the bound's time and the bracket of each."""
    from shared_inputs import CORPUS, CORPUS_PRESENT, NO_CORPUS
    from reference.nc import parse_file

    if not CORPUS_PRESENT:
        print(f"{label:>9} skipped: {NO_CORPUS}")
        return
    path = build_path(parse_file(CORPUS / program), machine)
    (w0, a), (w1, b) = _without_and_with(module, name, off, path, machine, "acc+freq")
    print(f"{label:>9} {program} acc+freq: oracle {w0:.1f} -> {w1:.1f} s "
          f"(x{w1 / w0:.2f}), bound {a.bound_time_s:.1f} -> {b.bound_time_s:.1f} s "
          f"(x{b.bound_time_s / a.bound_time_s:.2f}); bracket [{a.lower_bound_s:.4f}, "
          f"{a.upper_bound_s:.4f}] {a.gap:.2%} ({a.status}) -> [{b.lower_bound_s:.4f}, "
          f"{b.upper_bound_s:.4f}] {b.gap:.2%} ({b.status})", flush=True)


def turn_run_row(machine) -> None:
    """The turn run's cost and effect on the 48 sawtooth arcs (see the module docstring)."""
    import optimal.freq.humps as humps
    _toggle_row(machine, "turn run", "lcnc_arc_arc_sawtooth.ngc", humps, "HUMP_TURN_MARGIN",
                0.0)


def peak_levels_row(machine) -> None:
    """The turn programme's peak speed levels (step 4d of :mod:`optimal.freq.humps`) on
    lcnc_test_12mmflat (``acc+freq``, default gap): one level (the rise's and the fall's
    top speeds chosen apart) against the default two."""
    import optimal.freq.humps as humps
    _toggle_row(machine, "peaks", "lcnc_test_12mmflat.ngc", humps, "HUMP_PEAK_LEVELS", 1)


def phase_nlp_row(machine) -> None:
    """The phase NLP's cost and effect on lcnc_sam_tolerance_issue (module docstring)."""
    from shared_inputs import CORPUS, CORPUS_PRESENT, NO_CORPUS
    import optimal.freq.oracle as freq_oracle
    from reference.nc import parse_file

    if not CORPUS_PRESENT:
        print(f"{'phase NLP':>9} skipped: {NO_CORPUS}")
        return
    path = build_path(parse_file(CORPUS / "lcnc_sam_tolerance_issue.ngc"), machine)
    t0 = time.perf_counter()
    optimal.solve(path, machine.limits, bounds="jerk")
    t_j = time.perf_counter() - t0
    for bounds in ("acc+freq", "jerk+freq"):
        (w0, a), (w1, b) = _without_and_with(freq_oracle, "phase_nlp", lambda *a, **k: [],
                                             path, machine, bounds)
        print(f"{'phase NLP':>9} sam {bounds}: oracle {w0:.1f} -> {w1:.1f} s "
              f"(x{w1 / w0:.2f}; the jerk solve {t_j:.1f} s); bracket "
              f"[{a.lower_bound_s:.4f}, {a.upper_bound_s:.4f}] {a.gap:.2%} -> "
              f"[{b.lower_bound_s:.4f}, {b.upper_bound_s:.4f}] {b.gap:.2%} ({b.status})",
              flush=True)


def free_phases_row(machine) -> None:
    """The free phase ends' cost and effect on lcnc_sam_tolerance_issue (``acc+freq``,
    default gap; module docstring): the oracle without the search and with it."""
    from shared_inputs import CORPUS, CORPUS_PRESENT, NO_CORPUS
    import optimal.freq.oracle as freq_oracle
    from reference.nc import parse_file

    if not CORPUS_PRESENT:
        print(f"{'free ends':>9} skipped: {NO_CORPUS}")
        return
    path = build_path(parse_file(CORPUS / "lcnc_sam_tolerance_issue.ngc"), machine)
    (w0, a), (w1, b) = _without_and_with(freq_oracle, "_free_phase_candidate",
                                         lambda *a, **k: None, path, machine, "acc+freq")
    print(f"{'free ends':>9} sam acc+freq: oracle {w0:.1f} -> {w1:.1f} s (x{w1 / w0:.2f}); "
          f"bracket [{a.lower_bound_s:.4f}, {a.upper_bound_s:.4f}] {a.gap:.2%} -> "
          f"[{b.lower_bound_s:.4f}, {b.upper_bound_s:.4f}] {b.gap:.2%} ({b.status})",
          flush=True)


def reach_row(machine) -> None:
    """The reach caps' cost and effect on lcnc_sam_tolerance_issue (``jerk+freq``, default
    gap): the oracle with the turn programme on the ``acc`` grid alone, then as it is."""
    from shared_inputs import CORPUS, CORPUS_PRESENT, NO_CORPUS
    import optimal.freq.oracle as freq_oracle
    from optimal.grid import grid_on
    from reference.nc import parse_file

    if not CORPUS_PRESENT:
        print(f"{'reach':>9} skipped: {NO_CORPUS}")
        return
    path = build_path(parse_file(CORPUS / "lcnc_sam_tolerance_issue.ngc"), machine)
    (w0, a), (w1, b) = _without_and_with(
        freq_oracle, "_reach_grid", lambda work, lim, t_ipo, acc_grid, t: (
            grid_on(work, acc_grid), None), path, machine, "jerk+freq")
    print(f"{'reach':>9} sam jerk+freq: oracle {w0:.1f} -> {w1:.1f} s (x{w1 / w0:.2f}); "
          f"bracket [{a.lower_bound_s:.4f}, {a.upper_bound_s:.4f}] {a.gap:.2%} -> "
          f"[{b.lower_bound_s:.4f}, {b.upper_bound_s:.4f}] {b.gap:.2%} ({b.status})",
          flush=True)


if __name__ == "__main__":
    raise SystemExit(main())

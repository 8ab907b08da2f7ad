"""Backends on the same discrete problem: the exact sweep, the LP and the SOCP agree."""

from __future__ import annotations

import numpy as np
import pytest

import optimal
from optimal.backends import available_backends, get_backend, known_backends, solve_discrete
from optimal.bounds import build_relaxation
from optimal.grid import initial_grid
from optimal.problem import DiscreteProblem, build_grid_problem
from oracle_cases import XYZ, line_arc_line, machine, random_blended_polyline
from reference.core import BackendNotFoundError, path_from_pieces
from reference.core.geometry import arc_segment
from reference.core.tolerances import DISCRETE_AGREEMENT_RTOL

GOOD = (optimal.SolveStatus.OPTIMAL, optimal.SolveStatus.OPTIMAL_INACCURATE)


def helix():
    start = np.array([10.0, 0.0, 0.0])
    arc = arc_segment(start, start + [0, 0, 8.0], np.zeros(3), (0, 1), False, 1,
                      np.array([True] * 3), 0, 1e-6)
    return path_from_pieces(XYZ, [arc], feed=300.0)


CASES = {
    "line_arc_line": (lambda: line_arc_line(5.0, 20.0), 400),
    "polyline": (lambda: random_blended_polyline(30, 7, max_deviation=0.5), 1200),
    "helix": (helix, 300),
}


def problems():
    lim = machine((250.0, 200.0, 100.0), (3000.0, 2000.0, 1000.0))
    out = []
    for name, (make, n) in CASES.items():
        p = make()
        la = lim.for_axes(p.axes)
        g = initial_grid(p, n)
        out.append(pytest.param(build_grid_problem(p, la, g), id=f"{name}-grid"))
        out.append(pytest.param(build_relaxation(p, la, g).problem, id=f"{name}-relaxed"))
    return out


PROBLEMS = problems()


def test_registry_lists_the_three_backends():
    assert known_backends() == ("fast", "highs", "clarabel")
    assert available_backends()[0] == "fast"
    assert set(available_backends()) == {"fast", "highs", "clarabel"}


@pytest.mark.parametrize("problem", PROBLEMS)
@pytest.mark.parametrize("backend", ["highs", "clarabel"])
def test_backends_agree_with_the_exact_sweep(problem, backend):
    ref = solve_discrete(problem, "fast")
    res = solve_discrete(problem, backend)
    assert ref.status == optimal.SolveStatus.OPTIMAL
    assert res.status in GOOD, res.message
    assert res.time_s == pytest.approx(ref.time_s, rel=DISCRETE_AGREEMENT_RTOL)
    scale = float(np.max(ref.b))
    assert np.max(np.abs(res.b - ref.b)) <= 1e-4 * scale
    assert res.build_time_s >= 0 and res.solve_time_s >= 0


@pytest.mark.parametrize("problem", PROBLEMS)
def test_vectorised_and_sequential_sweeps_are_identical(problem):
    a = solve_discrete(problem, "fast", {"method": "vectorised"})
    b = solve_discrete(problem, "fast", {"method": "sequential"})
    assert a.message == "vectorised" and b.message == "sequential"
    np.testing.assert_allclose(a.b, b.b, rtol=1e-10, atol=1e-10 * float(np.max(b.b)))
    assert a.time_s == pytest.approx(b.time_s, rel=1e-10)


@pytest.mark.parametrize("problem", PROBLEMS)
def test_compiled_kernel_matches_the_sequential_sweep(problem):
    """The compiled kernel (optimal.backends.kernel) is the same algorithm as the
    pure-Python sequential sweep: equal to round-off on every case."""
    a = solve_discrete(problem, "fast", {"method": "compiled"})
    b = solve_discrete(problem, "fast", {"method": "sequential"})
    assert a.message == "compiled"
    np.testing.assert_allclose(a.b, b.b, rtol=1e-10, atol=1e-10 * float(np.max(b.b)))


@pytest.mark.parametrize("seed", range(6))
def test_compiled_kernel_on_random_lattice_problems(seed):
    """Random lattice-form problems (mixed forward/backward/vacuous rows, zero caps):
    the kernel equals the sequential sweep, and its result is feasible."""
    rng = np.random.default_rng(seed)
    N, R = 300, 5
    s = np.cumsum(np.r_[0.0, rng.uniform(0.1, 1.0, N)])
    cap = rng.uniform(0.0, 100.0, N + 1)
    cap[rng.random(N + 1) < 0.05] = 0.0
    c1 = rng.normal(size=(N, R))
    c2 = rng.normal(size=(N, R))
    flip = c1 * c2 > 0
    c2 = np.where(flip, -c2, c2)
    c1[rng.random((N, R)) < 0.1] = 0.0
    h = rng.uniform(0.0, 50.0, (N, R))
    prob = DiscreteProblem(s=s, cap=cap, c1=c1, c2=c2, h=h, segment=np.zeros(N, int),
                           row_axis=np.zeros(R, int), cap_code=np.zeros(N + 1, int),
                           cap_axis=np.full(N + 1, -1), axes=("X",), accel_scale=1.0)
    from optimal.backends.fast import sweep
    a, _, how_a = sweep(prob, method="compiled")
    b, _, how_b = sweep(prob, method="sequential")
    assert (how_a, how_b) == ("compiled", "sequential")
    np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-10 * float(np.max(b)))
    lhs = c1 * a[:-1, None] + c2 * a[1:, None]
    assert np.all(lhs <= h + 1e-9 * (np.abs(c1 * a[:-1, None]) + np.abs(c2 * a[1:, None]) + h))
    assert np.all(a <= cap * (1 + 1e-12))


@pytest.mark.parametrize("problem", PROBLEMS[:4])
def test_sweep_result_is_feasible_and_maximal(problem):
    """Feasible, and no single node can be raised by 1e-6 relative without breaking a
    row or a cap (the greatest element is maximal node by node)."""
    b = solve_discrete(problem, "fast").b
    c1, c2, h = problem.c1, problem.c2, problem.h

    def feasible(x):
        lhs = c1 * x[:-1, None] + c2 * x[1:, None]
        tol = 1e-12 * (np.abs(c1 * x[:-1, None]) + np.abs(c2 * x[1:, None]) + h)
        return np.all(x <= problem.cap * (1 + 1e-12)) and np.all(lhs <= h + tol)

    assert feasible(b)
    rng = np.random.default_rng(0)
    for k in rng.choice(b.size, 40, replace=False):
        x = b.copy()
        x[k] = b[k] * (1 + 1e-6) + 1e-9
        assert not feasible(x), k


def test_solve_accepts_every_backend_and_reports_it():
    lim = machine(200.0, 1000.0)
    p = line_arc_line(5.0, 20.0)
    sols = {be: optimal.solve(p, lim, backend=be, tol=5e-3) for be in ("fast", "highs")}
    assert sols["highs"].backend == "highs"
    assert sols["highs"].upper_bound_s == pytest.approx(sols["fast"].upper_bound_s, rel=1e-5)


def test_unknown_backend_and_option_are_rejected():
    p = line_arc_line(5.0, 20.0)
    g = initial_grid(p, 50)
    prob = build_grid_problem(p, machine(200.0, 1000.0).for_axes(p.axes), g)
    with pytest.raises(ValueError, match="unknown backend 'gurobi'"):
        solve_discrete(prob, "gurobi")
    with pytest.raises(ValueError, match="no option 'tolerance'.*known options"):
        solve_discrete(prob, "fast", {"tolerance": 1e-3})
    with pytest.raises(ValueError, match="option 'max_rounds'"):
        solve_discrete(prob, "fast", {"max_rounds": "many"})


def test_missing_backend_names_what_to_install(monkeypatch):
    import optimal.backends.clarabel as mod
    monkeypatch.setattr(mod, "is_available", lambda: False)
    with pytest.raises(BackendNotFoundError, match="pip install cvxpy clarabel"):
        get_backend("clarabel")
    assert "clarabel" not in available_backends()
    with pytest.raises(ImportError):         # BackendNotFoundError is an ImportError
        optimal.solve(line_arc_line(5.0, 20.0), machine(200.0, 1000.0), backend="clarabel")


def test_problem_rejects_rows_outside_the_lattice_form():
    s = np.array([0.0, 1.0, 2.0])
    kw = dict(s=s, cap=np.ones(3), segment=np.zeros(2, int), row_axis=np.zeros(1, int),
              cap_code=np.zeros(3, int), cap_axis=np.zeros(3, int), axes=("X",),
              accel_scale=1.0)
    with pytest.raises(ValueError, match="lattice form"):
        DiscreteProblem(c1=np.ones((2, 1)), c2=np.ones((2, 1)), h=np.ones((2, 1)), **kw)
    with pytest.raises(ValueError, match="increase strictly"):
        DiscreteProblem(**{**kw, "s": np.array([0.0, 1.0, 1.0])}, c1=np.zeros((2, 1)),
                        c2=np.zeros((2, 1)), h=np.ones((2, 1)))


def test_infeasible_discrete_problem_is_a_status():
    s = np.array([0.0, 1.0, 2.0])
    prob = DiscreteProblem(s=s, cap=np.array([0.0, 0.0, 1.0]), c1=np.zeros((2, 0)),
                           c2=np.zeros((2, 0)), h=np.zeros((2, 0)), segment=np.zeros(2, int),
                           row_axis=np.zeros(0, int), cap_code=np.zeros(3, int),
                           cap_axis=np.zeros(3, int), axes=("X",), accel_scale=1.0)
    res = solve_discrete(prob, "fast")
    assert res.status == optimal.SolveStatus.INFEASIBLE
    assert "interval 0" in res.message and res.time_s == float("inf")


@pytest.mark.parametrize("problem", PROBLEMS)
def test_auto_chooses_by_size_alone_not_by_the_process(problem):
    """``method="auto"`` on a small problem gives the numpy sweep's result bit for bit
    even once a large problem (or anything else) has loaded the compiled kernel: the two
    agree to round-off only, and the oracle's NLP stages turned that round-off into a
    1 % different upper bound depending on what ran before in the process."""
    import optimal.backends.kernel  # noqa: F401 - loaded, as after a large solve
    from optimal.backends.fast import sweep
    from optimal.tolerances import COMPILED_MIN_ROWS

    assert problem.c1.size < COMPILED_MIN_ROWS
    b_auto, _, how = sweep(problem, method="auto")
    b_vec, _, how_vec = sweep(problem, method="vectorised")
    assert how == how_vec and "compiled" not in how
    np.testing.assert_array_equal(b_auto, b_vec)

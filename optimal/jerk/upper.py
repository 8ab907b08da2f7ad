"""Upper bound of the jerk oracle: warm start, NLP solve, exact profile, checker, scaling.

1. *Warm start*: the exact optimum of the ``acc`` grid problem on the same grid
   (:func:`optimal.problem.build_grid_problem`, solved by the fast sweep), slowed to
   :data:`~optimal.jerk.tolerances.WARM_START_SPEED_FRACTION` of its speed.
2. *NLP*: :func:`optimal.jerk.backends.solve_nlp` (CasADi + IPOPT).
3. *Exact profile*: node positions, speeds and accelerations and interval durations
   are kept, the jerk of each interval runs its acceleration from one node value to the
   next, so the acceleration is continuous at every knot inside a segment, as the
   rulebook asks (:func:`exact_profile`).
4. *Verification*: ``check_profile`` judges the profile, with the holds inserted
   (:func:`reference.core.holds.with_holds`: the motion the oracle reports), under
   ``BOUND_SETS["jerk"]``;
   what the nodes missed (jerk and acceleration between nodes on arcs, the speed peak
   inside an interval) is repaired by stretching time
   (:func:`reference.core.constraints.time_scale_factor`, the same rule the ``acc``
   oracle applies). The accepted profile's duration is the upper bound.

Units: mm, s. Shapes: ``N`` intervals.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.core.constraints import (BOUND_SETS, ConstraintReport, check_profile,
                                        scale_time, time_scale_factor)
from reference.core.errors import ProfileError
from reference.core.geometry import Path
from reference.core.holds import NO_HOLDS, Holds, with_holds
from reference.core.limits import MachineLimits
from reference.core.profile import Profile

from ..backends import get_backend
from ..grid import Grid
from ..problem import build_grid_problem
from ..status import SolveStatus
from .backends import NlpResult, get_nlp_backend
from .tolerances import WARM_START_SPEED_FRACTION
from .transcription import JerkProblem, build_jerk_problem


@dataclass(frozen=True, slots=True, eq=False)
class UpperResult:
    """One verified round of the jerk NLP.

    Attributes
    ----------
    ok : bool
        IPOPT converged and the checker accepted the (time-scaled) profile.
    profile : Profile or None
        The accepted profile (holds not inserted), ``None`` when not ``ok``.
    time_scale : float
        Stretch factor applied (>= 1).
    objective_s : float
        Duration of the NLP's profile before scaling, s.
    report : ConstraintReport or None
        The checker's report on the unscaled profile with its holds.
    nlp : NlpResult
        IPOPT's answer.
    problem : JerkProblem
        The transcription.
    interval_times_s : numpy.ndarray, shape (N,)
        Time on every grid interval of the accepted profile, s.
    message : str
        Why not ``ok``.
    """

    ok: bool
    profile: Profile | None
    time_scale: float
    objective_s: float
    report: ConstraintReport | None
    nlp: NlpResult
    problem: JerkProblem
    interval_times_s: np.ndarray
    message: str = ""


def warm_start(path: Path, lim, grid: Grid, problem: JerkProblem,
               start: Profile | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Dimensionless ``(c, a, dt)`` to start the NLP from.

    From ``start`` (a verified jerk profile on a coarser grid: its speed and acceleration
    where it passes the new nodes, and the times between them) when given, else from the
    ``acc`` grid optimum on ``grid``, slowed down until the node rows hold.
    """
    u = problem.units
    if start is not None:
        tn = profile_times_at(start, grid.s)
        k = np.clip(np.searchsorted(start.t, tn, side="right") - 1, 0, start.n_intervals - 1)
        tau = tn - start.t[k]
        v = start.v[k] + tau * (start.a[k] + tau * start.j[k] / 2)
        acc_n = start.a[k] + start.j[k] * tau
        dt = np.diff(tn) / u.time_s
        if np.all(dt > 0) and np.all(np.isfinite(dt)):
            c = np.clip(v / u.speed, 0.0, problem.c_max)
            a = acc_n / u.accel
            lam = max(1.0, _row_excess(problem, c, a, dt))
            return c / lam, a / lam ** 2, dt * lam
    acc = get_backend("fast")(build_grid_problem(path, lim, grid), None)
    if acc.b is None or acc.status not in (SolveStatus.OPTIMAL,
                                           SolveStatus.OPTIMAL_INACCURATE):
        raise RuntimeError(f"acc warm start failed: {acc.status} ({acc.message})")
    f = WARM_START_SPEED_FRACTION
    c = f * np.sqrt(np.maximum(acc.b, 0.0)) / u.speed
    ds = problem.ds
    a_int = (c[1:] ** 2 - c[:-1] ** 2) / (2.0 * ds)
    a = np.zeros(c.size)
    a[1:-1] = 0.5 * (a_int[:-1] + a_int[1:])
    vs = c[:-1] + c[1:]
    dt = np.where(vs > 0, 2.0 * ds / np.where(vs > 0, vs, 1.0), 1.0)
    # slow it down until the node rows hold: IPOPT then starts (nearly) feasible, which
    # it needs (from the acc optimum itself it wandered for 900 iterations on a
    # program with long arcs); stretching time by lam divides c by lam, a by lam^2 and
    # every jerk row by lam^3
    lam = max(1.0, _row_excess(problem, c, a, dt))
    return c / lam, a / lam ** 2, dt * lam


def _row_excess(problem: JerkProblem, c: np.ndarray, a: np.ndarray, dt: np.ndarray
                ) -> float:
    """Smallest time stretch after which the acceleration, step and jerk rows hold at
    ``(c, a, dt)`` (accelerations continuous at breaks)."""
    inner = problem.grid.break_node[1:-1]
    a_all = np.concatenate((a, a[inner]))
    lam = 1.0
    for rows, idx, power in ((problem.acc, problem.acc_index, 2),):
        if rows.n:
            val = rows.dq * a_all[idx] + rows.ddq * c[rows.node] ** 2
            lam = max(lam, float(np.max(np.abs(val) / rows.limit)) ** (1.0 / power))
    st = problem.step
    if st.n:
        z = np.concatenate((a_all, [0.0]))
        ai = z[np.where(st.ia_in < 0, z.size - 1, st.ia_in)]
        ao = z[np.where(st.ia_out < 0, z.size - 1, st.ia_out)]
        c2 = c[st.node] ** 2
        val = st.dq_out * ao + st.ddq_out * c2 - st.dq_in * ai - st.ddq_in * c2
        lam = max(lam, float(np.max(np.abs(val) / st.limit)) ** 0.5)
    jr = problem.jerk
    if jr.n:
        k = jr.interval
        cn = c[jr.node]
        an = a[jr.node]
        val = (jr.dq * (a[k + 1] - a[k]) / dt[k] + 3 * jr.ddq * cn * an + jr.dddq * cn ** 3)
        lam = max(lam, float(np.max(np.abs(val) / jr.limit)) ** (1.0 / 3.0))
    return lam


def exact_profile(problem: JerkProblem, c: np.ndarray, a: np.ndarray, a_end: np.ndarray,
                  dt: np.ndarray, block: np.ndarray) -> Profile:
    """The piecewise-constant-jerk profile of an NLP solution.

    On interval ``k`` the acceleration runs linearly from the node value ``a_k`` to the
    interval's end value ``e_k`` (``= a_{k+1}`` except at segment breaks, where the NLP
    has a separate variable for the step), so the jerk is ``(e_k - a_k) / dt_k`` and the
    acceleration is continuous at every knot inside a segment exactly as the rulebook
    asks (:data:`reference.core.rules.STEPS_AT_BREAKS`). Node positions and speeds are
    the NLP's; the constant-jerk motion from each knot reaches the next one up to the
    NLP's residual of the integration equalities (:data:`optimal.jerk.tolerances.IPOPT_TOL`
    in scaled units), far inside :class:`~reference.core.profile.Profile`'s consistency
    tolerance; the checker judges the motion from each knot.

    Parameters
    ----------
    problem : JerkProblem
        For the grid and the units.
    c, a : numpy.ndarray, shape (N + 1,)
        Dimensionless node speeds (clipped to ``[0, c_max]``) and accelerations (on
        leaving the node).
    a_end : numpy.ndarray, shape (N,)
        Dimensionless acceleration at the end of every interval.
    dt : numpy.ndarray, shape (N,)
        Dimensionless durations (> 0).
    block : numpy.ndarray of int, shape (N,)
        NC block of each interval.

    Returns
    -------
    Profile
        In mm and s.
    """
    u = problem.units
    c = np.clip(c, 0.0, problem.c_max)
    h = dt * u.time_s
    v = c * u.speed
    a0 = a[:-1] * u.accel
    j = (a_end * u.accel - a0) / h
    t = np.concatenate(([0.0], np.cumsum(h)))
    return Profile(t=t, s=problem.grid.s, v=v, a=a0, j=j, block=block)


def resolved(path: Path, lim, grid: Grid, problem: JerkProblem, start: Profile,
             attempts: tuple[int, ...] | None = None) -> tuple[Profile | None, int]:
    """``problem`` solved by IPOPT from ``start`` (:func:`warm_start`): the exact profile
    of its answer (:func:`exact_profile`) and the attempt that solved it
    (:func:`optimal.jerk.backends.ipopt.solve_nlp`, which ``attempts`` it tries); the
    profile is ``None`` where IPOPT fails or its answer is no motion. The re-solves of
    :mod:`optimal.freq.jerk_adapted` and :mod:`optimal.freq.phase_nlp` share it."""
    c0, a0, dt0 = warm_start(path, lim, grid, problem, start)
    nlp = get_nlp_backend("ipopt")(problem, c0, a0, dt0, attempts=attempts)
    if not nlp.success:
        return None, nlp.attempt
    try:
        return exact_profile(problem, nlp.c, nlp.a, nlp.a_end, nlp.dt,
                             path.block[grid.segment]), nlp.attempt
    except ProfileError:
        return None, nlp.attempt


def profile_times_at(prof: Profile, s: np.ndarray) -> np.ndarray:
    """Time at which a profile passes path positions ``s`` (non-decreasing), s.

    Within a knot interval the position is a cubic in time, increasing where ``v > 0``:
    a few Newton steps from the linear guess, clipped to the interval.
    """
    s = np.asarray(s, dtype=np.float64)
    k = np.clip(np.searchsorted(prof.s, s, side="right") - 1, 0, prof.n_intervals - 1)
    h = np.diff(prof.t)[k]
    s0, v0, a0, j = prof.s[k], prof.v[k], prof.a[k], prof.j[k]
    ds = prof.s[k + 1] - s0
    tau = np.where(ds > 0, h * np.clip((s - s0) / np.where(ds > 0, ds, 1.0), 0.0, 1.0), 0.0)
    for _ in range(8):
        f = s0 + tau * (v0 + tau * (a0 / 2 + tau * j / 6)) - s
        fp = v0 + tau * (a0 + tau * j / 2)
        step = np.where(fp > 0, f / np.where(fp > 0, fp, 1.0), 0.0)
        tau = np.clip(tau - step, 0.0, h)
    return prof.t[k] + tau


def upper_bound_round(path: Path, limits: MachineLimits, grid: Grid,
                      start: Profile | None = None, nlp_backend: str = "ipopt",
                      holds: Holds = NO_HOLDS) -> UpperResult:
    """Solve the jerk NLP on ``grid`` and verify its profile (see the module docstring).

    Parameters
    ----------
    path : Path
        The path.
    limits : MachineLimits
        Machine limits.
    grid : Grid
        NLP grid.
    start : Profile, optional
        A verified profile from a coarser grid to start from (see :func:`warm_start`).
    nlp_backend : {"ipopt", "scp"}
        NLP solver (:mod:`optimal.jerk.backends`).
    holds : Holds
        The holds the reported motion contains: the NLP arrives at and leaves their
        breaks as at the path ends, and the profile is judged with them inserted.

    Returns
    -------
    UpperResult
    """
    lim = limits.for_axes(path.axes)
    problem = build_jerk_problem(path, lim, grid, limits.t_ipo_s, holds.break_index)
    c0, a0, dt0 = warm_start(path, lim, grid, problem, start)
    nlp = get_nlp_backend(nlp_backend)(problem, c0, a0, dt0)
    empty = np.zeros(grid.n_intervals)
    if not nlp.success:
        return UpperResult(False, None, 1.0, np.inf, None, nlp, problem, empty,
                           f"{nlp_backend}: {nlp.message} after {nlp.iterations} iterations")
    block = path.block[grid.segment]
    prof = exact_profile(problem, nlp.c, nlp.a, nlp.a_end, nlp.dt, block)
    # judged as reported: a hold's zero acceleration between the arriving and the
    # leaving motion is two steps the profile alone does not show
    report = check_profile(path, limits, with_holds(prof, path, holds))
    lam = time_scale_factor(report, BOUND_SETS["jerk"])
    if not np.isfinite(lam):
        bad = [r for r in report.results if not np.isfinite(r.ratio)]
        where = f"{bad[0].constraint} at s = {bad[0].s:.6g} mm" if bad else "a constraint"
        return UpperResult(False, None, lam, prof.duration, report, nlp, problem, empty,
                           f"the NLP profile breaks {where} beyond repair by time scaling")
    accepted = scale_time(prof, lam) if lam > 1.0 else prof
    return UpperResult(True, accepted, lam, prof.duration, report, nlp, problem,
                       np.diff(accepted.t), f"IPOPT: {nlp.message}, {nlp.iterations} "
                       f"iterations, time scale {lam:.6f}")

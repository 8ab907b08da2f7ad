"""IPOPT (through CasADi) on the NLP of the free phase ends
(:class:`optimal.freq.free_phases.FreePhaseNLP`).

Objective and rows, with ``S = s0 + M u``, ``ds = diff(S)``, ``dB = diff(v^2)``
(``2 s'' ds`` per interval) and ``h = 2 ds / (v_k + v_k+1)`` (the interval's time):

* minimise ``sum h``;
* ``sign dB >= 2 creep ds`` (every interval keeps its phase's sign);
* per axis, at both ends ``e`` of every interval,
  ``alpha sign dB + 2 ds beta v_e^2 <= 2 keep ds`` (the axis acceleration, times ``2 ds``
  so that no row divides);
* per phase, with ``T = sum h`` and ``D = S_b - S_a`` over it and ``dv`` its change, a
  rise ``v_b T - D >= dv g/2`` and ``D - v_a T >= dv g/2``, a fall
  ``D - v_b T >= dv g/2`` and ``v_a T - D >= dv g/2``;
* ``u[n + 1] - u[n] >= order_gap`` for the pairs ``order``; the bounds of ``v`` and ``u``.

Units: mm, s, mm/s.
"""

from __future__ import annotations

import numpy as np

#: IPOPT's tolerances: the optimality tolerance, and the constraint violation it must
#: meet (absolute; the rows are in mm and mm/s, and the model's margins,
#: :data:`optimal.freq.free_phases.FREE_RULE_MARGIN` and ``FREE_LIMIT_MARGIN``, are far
#: above it).
FREE_IPOPT_TOL = 1e-9
FREE_IPOPT_CONSTR_VIOL = 1e-11


def solve_free_phases(nlp, *, max_iter: int) -> tuple[bool, np.ndarray, np.ndarray]:
    """Solve ``nlp`` (a :class:`~optimal.freq.free_phases.FreePhaseNLP`) from its initial
    point.

    Returns
    -------
    ok : bool
        Whether IPOPT reported success within ``max_iter`` iterations.
    v : numpy.ndarray, shape (K + 1,)
        Node speeds, mm/s.
    u : numpy.ndarray, shape (U,)
        Shares of the free ends' gaps.
    """
    import casadi as ca

    K = nlp.sign.size
    U = nlp.u0.size
    v = ca.SX.sym("v", K + 1)
    u = ca.SX.sym("u", U)
    S = ca.DM(nlp.s0) + ca.mtimes(ca.DM(nlp.M), u)
    ds = S[1:] - S[:-1]
    h = 2 * ds / (v[:-1] + v[1:])
    dB = v[1:] ** 2 - v[:-1] ** 2
    sign = ca.DM(nlp.sign)
    g, lbg, ubg = [], [], []

    def row(expr, lo=-np.inf, hi=np.inf):
        g.append(expr)
        n = expr.shape[0]
        lbg.append(np.broadcast_to(lo, (n,)))
        ubg.append(np.broadcast_to(hi, (n,)))

    if nlp.order.size:
        row(u[nlp.order + 1] - u[nlp.order], nlp.order_gap)
    row(sign * dB - 2 * nlp.creep * ds, 0.0)
    for j in range(nlp.alpha.shape[1]):
        al, be = nlp.alpha[:, j], nlp.beta[:, j]
        if not (np.any(al > 0) or np.any(be > 0)):
            continue
        for ve in (v[:-1], v[1:]):
            row(ca.DM(al * nlp.sign) * dB + 2 * ds * ca.DM(be) * ve ** 2 - 2 * nlp.keep * ds,
                -np.inf, 0.0)
    for p, (a, b, gp) in enumerate(zip(nlp.phase_start, nlp.phase_stop, nlp.phase_g)):
        a, b = int(a), int(b)
        T = ca.sum1(h[a:b])
        D = S[b] - S[a]
        v0, v1 = v[a], v[b]
        if p % 2 == 0:                         # a rise from v0 to v1
            row(v1 * T - D - (v1 - v0) * gp / 2, 0.0)
            row(D - v0 * T - (v1 - v0) * gp / 2, 0.0)
        else:                                  # a fall
            row(D - v1 * T - (v0 - v1) * gp / 2, 0.0)
            row(v0 * T - D - (v0 - v1) * gp / 2, 0.0)
    problem = {"x": ca.vertcat(v, u), "f": ca.sum1(h), "g": ca.vertcat(*g)}
    opts = {"ipopt.print_level": 0, "print_time": 0, "ipopt.sb": "yes",
            "ipopt.max_iter": int(max_iter), "ipopt.tol": FREE_IPOPT_TOL,
            "ipopt.constr_viol_tol": FREE_IPOPT_CONSTR_VIOL,
            "ipopt.acceptable_constr_viol_tol": 10 * FREE_IPOPT_CONSTR_VIOL}
    solver = ca.nlpsol("free_phases", "ipopt", problem, opts)
    res = solver(x0=np.concatenate((nlp.v0, nlp.u0)),
                 lbx=np.concatenate((nlp.v_lo, nlp.u_lo)),
                 ubx=np.concatenate((nlp.v_hi, nlp.u_hi)),
                 lbg=np.concatenate(lbg), ubg=np.concatenate(ubg))
    x = np.asarray(res["x"]).ravel()
    return bool(solver.stats().get("success", False)), x[:K + 1], x[K + 1:]

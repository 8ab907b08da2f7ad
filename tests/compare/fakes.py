"""Small stand-ins for the heuristic and the oracle (tests of compare/ only).

``toy_profile`` is a forward/backward pass (maximal velocity curve) on a grid with
conservative bounds: tangential acceleration ``scale * min_i A_i / 2`` and centripetal
acceleration at most ``A_i / 2`` per axis, so every profile it makes passes
``check_profile`` under the ``acc`` bound set. ``scale < 1`` makes a slower, still
feasible "heuristic".
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from optimal import SolveStatus
from reference.core.constraints import check_profile
from reference.core.holds import NO_HOLDS, Holds
from reference.core.geometry import Path
from reference.core.limits import MachineLimits
from reference.core.profile import Profile


def toy_profile(path: Path, limits: MachineLimits, scale: float = 1.0,
                nodes_per_mm: float = 2.0) -> Profile:
    """Acceleration-bounded maximal velocity curve along ``path`` (see module doc)."""
    lim = limits.for_axes(path.axes)
    s_nodes = [np.array([0.0])]
    for k in range(path.n_segments):
        a, b = path.s_breaks[k], path.s_breaks[k + 1]
        n = max(8, int(np.ceil((b - a) * nodes_per_mm)))
        s_nodes.append(np.linspace(a, b, n + 1)[1:])
    s = np.concatenate(s_nodes)
    seg = path.segment_index(np.clip(0.5 * (s[:-1] + s[1:]), 0, path.total_length))
    mid = 0.5 * (s[:-1] + s[1:])
    _, dq, ddq, _ = path.evaluate(mid, segment=seg)
    with np.errstate(divide="ignore"):
        v_ax = np.min(np.where(np.abs(dq) > 1e-12, lim.v_max / np.abs(dq), np.inf), axis=1)
        v_c = np.min(np.where(np.abs(ddq) > 1e-15, np.sqrt(0.5 * lim.a_max / np.abs(ddq)),
                              np.inf), axis=1)
    v_int = np.minimum(np.minimum(path.feed[seg], v_ax), v_c) * 0.999
    # node bound: min of adjacent intervals; stops and corner jumps at breaks
    vb = np.full(s.size, np.inf)
    vb[:-1] = np.minimum(vb[:-1], v_int)
    vb[1:] = np.minimum(vb[1:], v_int)
    t_in, t_out = path.junction_tangents()
    for k in range(path.n_segments + 1):
        node = int(np.searchsorted(s, path.s_breaks[k]))
        if path.stop[k]:
            vb[node] = 0.0
        elif 0 < k < path.n_segments:
            d = np.abs(t_out[k - 1] - t_in[k - 1])
            if np.any(d > 1e-9):
                vb[node] = min(vb[node], 0.9 * float(np.min(np.where(
                    d > 1e-9, lim.jump / np.maximum(d, 1e-300), np.inf))))
    a_t = scale * 0.5 * float(np.min(lim.a_max))
    b = vb ** 2
    ds = np.diff(s)
    for i in range(1, s.size):
        b[i] = min(b[i], b[i - 1] + 2 * a_t * ds[i - 1])
    for i in range(s.size - 2, -1, -1):
        b[i] = min(b[i], b[i + 1] + 2 * a_t * ds[i])
    return Profile.from_path_velocity(s, np.sqrt(b), block=path.block[seg])


@dataclass(frozen=True)
class FakeRow:
    block: int
    cause: str


@dataclass(frozen=True)
class FakePlan:
    path: Path
    profile: Profile
    limits: MachineLimits
    bound_set: str = "acc"
    blocks: tuple = ()
    report: object = None
    holds: Holds = NO_HOLDS       # the fake profiles have none


@dataclass(frozen=True)
class FakeSolution:
    status: SolveStatus
    profile: Profile | None
    lower_bound_s: float
    upper_bound_s: float
    total_time_s: float = 0.01
    grid_points: int = 100
    bounds: str = "acc"
    blocks: tuple = ()
    holds: Holds = NO_HOLDS
    segment_lower_bounds_s: object = None


def fake_plan(path: Path, limits: MachineLimits, scale: float = 0.7,
              bound_set: str = "acc") -> FakePlan:
    prof = toy_profile(path, limits, scale)
    rows = tuple(FakeRow(b.block, "axis acceleration") for b in path.blocks)
    return FakePlan(path=path, profile=prof, limits=limits, bound_set=bound_set, blocks=rows,
                    report=check_profile(path, limits, prof))


def fake_solution(path: Path, limits: MachineLimits, rel_gap: float = 0.002) -> FakeSolution:
    prof = toy_profile(path, limits, 1.0)
    ub = prof.duration
    return FakeSolution(SolveStatus.OPTIMAL, prof, ub / (1 + rel_gap), ub)

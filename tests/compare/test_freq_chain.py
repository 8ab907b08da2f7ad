"""The relaxation chain on corpus programs, both bundled machines (issue 12, item 3).

spec/oracle-formulations 1.9: "Relaxations: T*_acc <= T*_jerk <= T*_freq. Dropping
constraints always gives a lower bound." So on the same path LB(acc) <= LB(jerk) <=
LB(jerk+freq) and LB(acc) <= LB(acc+freq) <= LB(jerk+freq), and for the verified motions
UB(acc) <= UB(jerk) <= UB(jerk+freq), each within the brackets: every oracle stops once
its bracket meets the requested gap, so its bounds are its optimum only to within that
(UB(acc) is at most the acc bracket above T*_acc <= T*_jerk <= UB(jerk); LB(acc+freq) <=
T*_acc+freq <= T*_jerk+freq <= LB(jerk+freq) + its bracket), and likewise one step up.
Small programs keep this fast; the frequency check itself is check_profile's.
"""

from __future__ import annotations

import pytest

import optimal
from reference.core.constraints import BOUND_SETS, check_profile
from reference.holds import imposed_holds
from reference.machine import load_machine
from reference.nc import parse_file
from reference.prepare import build_path
from shared_inputs import corpus_file, needs_corpus

# (lcnc_full_xz.ngc and sin_cead_arc.mpf take 30-50 s on the default machine: too slow here)
PROGRAMS = ["lcnc_square.ngc", "lcnc_corner_decel.ngc"]
MACHINES = [None, "linuxcnc_xyz"]
pytestmark = needs_corpus


@pytest.mark.parametrize("machine", MACHINES)
@pytest.mark.parametrize("program", PROGRAMS)
def test_relaxation_chain(program, machine):
    m = load_machine(machine)
    prog = parse_file(corpus_file(program))
    path = build_path(prog, m)
    holds = imposed_holds(prog, path, m)
    lim = m.limits
    sols = {b: optimal.solve(path, lim, bounds=b, holds=holds, initial_intervals=200)
            for b in ("acc", "jerk", "acc+freq", "jerk+freq")}
    # both chains: acc <= jerk <= jerk+freq and acc <= acc+freq <= jerk+freq
    for chain in (("acc", "jerk", "jerk+freq"), ("acc", "acc+freq", "jerk+freq")):
        lb = [sols[b].lower_bound_s for b in chain]
        ub = [sols[b].upper_bound_s for b in chain]
        gap = [sols[b].upper_bound_s - sols[b].lower_bound_s for b in chain]
        # each set's optimum is at least the one before's (fewer constraints); its bounds
        # are that within their own brackets: an oracle stops once its bracket meets the
        # requested gap (lcnc_corner_decel: jerk+freq met 2 % with the jerk oracle's
        # bound alone, 2e-5 s below the acc+freq bound's turn programme)
        assert lb[0] <= lb[1] + gap[1] and lb[1] <= lb[2] + gap[2], chain
        assert ub[0] <= ub[1] + gap[0] and ub[1] <= ub[2] + gap[1], chain
        assert all(lo <= hi for lo, hi in zip(lb, ub))
    for b in ("acc+freq", "jerk+freq"):
        f = sols[b]
        assert f.status in ("optimal", "gap_not_met") and f.bounds == b
        assert check_profile(path, lim, f.profile).ok(BOUND_SETS[b])

"""Programs the fuzz suite found, kept as fixed cases (the shrunk examples of
:mod:`test_fuzz_programs` and the mutants of :mod:`test_fuzz_corpus`, reduced by hand).

A bug fixed on this branch stays here as a plain regression case. A bug that is not fixed
here (it belongs to work done elsewhere, e.g. the resource limits of issue 9 item 3) is an
``xfail(strict=True)`` naming the bug, and its stderr signature is in
:data:`fuzz_harness.KNOWN_BUGS`, so that the generated tests record it as a known bug
(Hypothesis ``event``) and go on looking for others. When the bug is fixed, its case here
passes, the strict xfail fails the run, and both entries are removed.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest

from fuzz_harness import COMPARE_ARGS, KNOWN_BUGS, assert_clean, run_cli

pytestmark = pytest.mark.fuzz

FOUND = [
    # found, then fixed (a block's motion time is bounded, MAX_BLOCK_MOTION_S)
    pytest.param(
        "slow_feed.mpf", "G1 X0 Y0 Z0 F0.001\nG1 X=1000000\n",
        id="profile_precision"),
    # found, then fixed (the size budget): kept as regression cases
    pytest.param(
        "turn.mpf", "G1 F1000 X0 Y0\nG2 X0 Y0 Z10 I5 J0 TURN=999999\nM30\n",
        id="turn_allocation_sin"),
    pytest.param(
        "turn.ngc", "G1 F100 X0 Y0\nG2 X0 Y0 Z10 I5 J0 P1000000\nM2\n",
        id="turn_allocation_ngc"),
]


@pytest.mark.parametrize("name, text", FOUND)
@pytest.mark.parametrize("command", ["plan", "compare"])
def test_found_case(name, text, command):
    with tempfile.TemporaryDirectory() as tmp:
        prog = Path(tmp) / name
        prog.write_text(text)
        argv = [command, str(prog), "--quiet"] + (["--no-report", *COMPARE_ARGS]
                                                  if command == "compare" else [])
        assert_clean(run_cli(argv), [prog])


def test_every_known_bug_has_a_pinned_case():
    pinned = {p.id.rsplit("_", 1)[0] if p.id.endswith(("_sin", "_ngc")) else p.id
              for p in FOUND}
    assert set(KNOWN_BUGS) <= pinned

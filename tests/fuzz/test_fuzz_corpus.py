"""Seeded mutants of the real programs in ``../shared/corpus`` through the CLI.

Each case is one corpus program, cut to at most :data:`MAX_LINES` lines (a random window
of the longer ones, so that ``compare`` stays fast) and damaged by 1-4 mutations drawn
with ``random.Random(seed)``: truncation at a random byte, a flipped, deleted or
duplicated character or line, an inserted hostile word (``X1e308``, ``F0``,
``G2 X1 I0 J0``, ``TURN=999999``, 500 nested brackets, a NUL byte, bytes that are not
UTF-8, ...). The judge is the same as for the generated programs (:mod:`fuzz_harness`):
exit 0/1/2, no traceback, no numpy warning, under the memory budget, exit-2 messages
naming file:line. A case is named ``<corpus file>-<seed>`` and reproduces exactly.

``make test`` runs :data:`CI_SEEDS` seeds per corpus file; ``make fuzz``
(``FEEDORACLE_FUZZ=1``) runs ``FEEDORACLE_FUZZ_SEEDS`` (default 60). A seed that finds a
bug which is not fixed here is listed in :data:`KNOWN_FAILURES` (an xfail, strict: the
case fails loudly once the bug is fixed, and the entry is removed then).
"""

from __future__ import annotations

import os
import random
import tempfile
from pathlib import Path

import pytest

from fuzz_harness import COMPARE_ARGS, assert_clean, run_cli
from shared_inputs import CORPUS, CORPUS_PRESENT, NO_CORPUS, corpus_cases, corpus_listing

pytestmark = pytest.mark.fuzz

#: Longest mutant, lines: a few dozen blocks, like the generated programs.
MAX_LINES = 40
CI_SEEDS = 5
N_SEEDS = int(os.environ.get("FEEDORACLE_FUZZ_SEEDS", 60)) if os.environ.get(
    "FEEDORACLE_FUZZ") else CI_SEEDS

#: Words inserted into a line (both dialects unless noted); issue 9 lists most of them.
HOSTILE = ["X1e308", "F0", "G2 X1 I0 J0", "TURN=999999", "X" + "9" * 400, "G1 X5 F0",
           "X" + "(" * 500 + "1" + ")" * 500, "X=" + "(" * 500 + "1" + ")" * 500,
           "X" + "[" * 500 + "1" + "]" * 500, "\x00", "M98 P1000", "G1 X#99999", "G64 P-1",
           "BSPLINE X10 Y5", "R1=1/0", "#1=[1/0]", "GOTOB NOWHERE", "ENDWHILE", "ENDIF",
           "o100 endwhile", "T=\"DRILL 8.5\"", "POS[A]=90", "ROT Y-90", "CR=0", "G4 F-1",
           "P1000000", "N99999999999999999999", "G17 G18", "X", "=", "[", "(", ";", "#",
           "G91", "G2", "I1e9", "F1e9", "S1e400"]
#: Raw bytes inserted as they are (not UTF-8, UTF-16 BOM, Latin-1 umlauts, CR alone).
HOSTILE_BYTES = [b"\xff\xfe", b"\x80", b"\xe4\xf6\xfc", b"\xc3", b"\r", b"\x00\x00",
                 b"\xef\xbb\xbf"]

#: (corpus file, seed) -> the bug it finds, not fixed on this branch.
KNOWN_FAILURES: dict[tuple[str, int], str] = {}


def _corpus_files() -> list[Path]:
    return sorted(p for p in corpus_listing("*") if p.suffix in (".mpf", ".ngc"))


def mutant(original: bytes, seed: int) -> bytes:
    """A damaged copy of a program (see the module docstring), the same for one seed.

    Parameters
    ----------
    original : bytes
        The program as read from the corpus.
    seed : int

    Returns
    -------
    bytes
    """
    rng = random.Random(seed)
    lines = original.splitlines(keepends=True)
    if len(lines) > MAX_LINES:
        start = rng.choice([0, rng.randrange(len(lines) - MAX_LINES)])
        lines = lines[start:start + MAX_LINES]
    data = b"".join(lines)
    for _ in range(rng.randint(1, 4)):
        op = rng.choice(["truncate", "flip", "flip", "delete", "duplicate", "dup_line",
                         "hostile", "hostile", "hostile", "bytes"])
        at = rng.randrange(len(data) + 1)
        if op == "truncate":
            data = data[:at]
        elif op == "flip" and data:
            at = min(at, len(data) - 1)
            data = data[:at] + bytes([rng.choice(
                b"0123456789.-+XYZIJKFGRP=#[]() \n;" + bytes([rng.randrange(256)]))]) \
                + data[at + 1:]
        elif op == "delete":
            data = data[:at] + data[at + rng.randint(1, 3):]
        elif op == "duplicate":
            data = data[:at] + data[at:at + rng.randint(1, 12)] + data[at:]
        elif op == "dup_line":
            ls = data.splitlines(keepends=True) or [b""]
            k = rng.randrange(len(ls))
            ls.insert(k, ls[k])
            data = b"".join(ls)
        elif op == "hostile":
            # at a line start, as a block of its own, or glued into the text
            word = rng.choice(HOSTILE).encode("utf-8")
            where = rng.choice(["start", "block", "glued"])
            if where != "glued":
                at = data.rfind(b"\n", 0, at) + 1
            sep = b"\n" if where == "block" else b" "
            data = data[:at] + word + sep + data[at:]
        else:
            data = data[:at] + rng.choice(HOSTILE_BYTES) + data[at:]
    return data


def _cases():
    for prog in _corpus_files():
        for seed in range(N_SEEDS):
            reason = KNOWN_FAILURES.get((prog.name, seed))
            marks = [pytest.mark.xfail(strict=True, reason=reason)] if reason else []
            yield pytest.param(prog, seed, marks=marks, id=f"{prog.name}-{seed}")


def test_corpus_is_there():
    if not CORPUS_PRESENT:
        pytest.skip(f"{NO_CORPUS}: no mutants to run")
    assert len(_corpus_files()) >= 10, f"corpus at {CORPUS} has lost its programs"


@pytest.mark.parametrize("original, seed", corpus_cases(list(_cases()), nargs=2))
def test_corpus_mutant(original, seed):
    data = mutant(original.read_bytes(), seed)
    with tempfile.TemporaryDirectory() as tmp:
        prog = Path(tmp) / original.name
        prog.write_bytes(data)
        for command in ("inspect", "plan", "compare"):
            argv = [command, str(prog), "--quiet"] + (
                ["--no-report", *COMPARE_ARGS] if command == "compare" else [])
            if prog.suffix == ".ngc":
                argv += ["--machine", "linuxcnc_xyz"]
            assert_clean(run_cli(argv), [prog])

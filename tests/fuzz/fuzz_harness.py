"""Run the ``feedoracle`` CLI in-process on one fuzz case and judge the outcome.

One case is one call of :func:`compare.cli.main`. The judge (:func:`assert_clean`) holds
the CLI to DESIGN section 7 and issue 9:

- the exit code is 0, 1 or 2: never 3 (an internal error is a bug), never anything else;
- stderr holds no traceback and no warning of Python's ``warnings`` machinery (numpy's
  ``RuntimeWarning`` above all: no numpy warning may reach the user);
- on exit 2 the last line of stderr is the one error line, ``feedoracle: ...``, and it
  names where: the program file and a line (``prog.mpf:12`` or ``prog.mpf:12:5``), or the
  machine-data key (``axis.X.MAX_AX_ACCEL = ...``), or the machine file itself when the file
  as a whole cannot be read (not UTF-8, not TOML); the only whole-program message allowed
  without a line is "the program has no motion";
- the case stays under a memory budget and a time limit (below).

Memory is measured as the growth of the process's peak resident set (Linux ``VmHWM``,
reset per case through ``/proc/self/clear_refs``): it counts every byte the case touches,
numpy's and the native solvers' (clarabel, HiGHS, OSQP allocate outside Python, where
:mod:`tracemalloc` cannot see them), and costs nothing, where :mod:`tracemalloc` slows a
``compare`` 2-5x. Where ``clear_refs`` is not writable (not Linux) :mod:`tracemalloc` is
the fallback. Independently, the address space is capped for the duration of the case
(``RLIMIT_AS``, :data:`ADDRESS_SPACE_GUARD` above what the process already maps), so a
runaway allocation (the 21.5 GiB of ``TURN=1000000`` in issue 9) fails at once with a
``MemoryError`` (exit 3, a test failure naming it) instead of swapping or drawing the
out-of-memory killer onto the test run.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import signal
import threading
import time
import tracemalloc
import warnings
from dataclasses import dataclass
from pathlib import Path

from compare.cli import main

#: Peak-memory budget of one case, bytes. The fuzz programs have at most ~30 blocks (the
#: corpus mutants at most 40 lines); the largest real one, ``lcnc_arc_arc_sawtooth.ngc``
#: (cut to 40 lines as here), grows the peak resident set by 32 MiB in ``compare``;
#: 500 MiB is 15x that: a small case above it means some array is sized by a number in
#: the input (a TURN count, an IPO cycle, a coordinate) rather than by the program's
#: length, the class of bug issue 9 item 3 removes. Two pytest-xdist workers, each at
#: its baseline (~70 MiB resident after a compare has imported numpy, scipy and the
#: solvers) plus this, fit a small 2-core CI machine.
MEMORY_BUDGET_BYTES = 500 * 1024**2
#: Address space a case may map beyond what the process maps before it, bytes: the
#: 2 GB resource budget of issue 9 item 3. Above it an allocation raises MemoryError.
ADDRESS_SPACE_GUARD = 2 * 1024**3
#: Wall-clock limit of one case, s: a hang guard, not a performance target. A small
#: ``compare`` takes 0.05-2 s; a program that loops until the executed-block cap takes
#: ~10 s, so 60 s only trips on a real hang.
TIME_LIMIT_S = 60.0
#: Extra arguments of every fuzzed ``compare``. In the ``ci`` profile (``make test``) the
#: ``acc`` oracle: ``--bounds auto`` solves the jerk NLP for SOFT programs, seconds per
#: case instead of milliseconds, and 50 examples of it would hold up the suite by many
#: minutes; ``make fuzz`` (``FEEDORACLE_FUZZ=1``) runs ``auto``, so the jerk oracle meets
#: the generated programs there. The jerk oracle's bad-input cases (zero and absurd
#: limits, micrometre segments, reversals) are in ``tests/optimal/test_jerk.py``.
COMPARE_ARGS: tuple[str, ...] = () if os.environ.get("FEEDORACLE_FUZZ") else ("--bounds", "acc")

_STATUS = Path("/proc/self/status")
_CLEAR_REFS = Path("/proc/self/clear_refs")
#: The one error line on exit 2 names a line of a file, ``file:12`` or ``file:12:5``.
_AT_LINE = r":\d+(?::\d+)?: "
#: ... or a machine-data key with its value, ``axis.X.MAX_AX_ACCEL = 1e-300: ...``.
_KEY = r"(?:[A-Za-z_][\w\-]*|<file>|--machine)(?:\.\S+)* = "
_NO_MOTION = ": the program has no motion ("


#: Bugs the fuzz suite found that are not fixed on this branch: name -> (what, the regular
#: expression its stderr matches). Each has a strict-xfail case in ``test_fuzz_found.py``;
#: the generated tests record a match as a known bug and look on (:func:`known_bug`).
KNOWN_BUG_SIGNATURES: dict[str, tuple[str, str]] = {
}
KNOWN_BUGS = {name: what for name, (what, _) in KNOWN_BUG_SIGNATURES.items()}


def known_bug(outcome: "Outcome") -> str | None:
    """The name of the known bug an outcome shows, or None."""
    for name, (_, pattern) in KNOWN_BUG_SIGNATURES.items():
        if re.search(pattern, outcome.err):
            return name
    return None


class CaseTimeout(BaseException):
    """A case ran longer than :data:`TIME_LIMIT_S` (a BaseException so that the CLI's
    last-line-of-defence ``except Exception`` does not turn it into exit 3)."""


@dataclass(frozen=True, slots=True)
class Outcome:
    """What one CLI call did.

    Attributes
    ----------
    argv : tuple of str
    code : int
        Exit code returned by ``main``.
    out, err : str
        Captured stdout and stderr.
    peak_bytes : int
        Growth of peak memory during the call, bytes (-1 when not measured).
    seconds : float
        Wall-clock time of the call.
    warned : tuple of str
        Warnings raised through :mod:`warnings` during the call, as ``Category: text
        (file:line)``.
    """

    argv: tuple[str, ...]
    code: int
    out: str
    err: str
    peak_bytes: int
    seconds: float
    warned: tuple[str, ...]

    def describe(self) -> str:
        """The call and its stderr, for an assertion message."""
        err = self.err
        tail = err if len(err) < 3000 else err[:1500] + " ... " + err[-1500:]
        return f"feedoracle {' '.join(self.argv)} -> exit {self.code}\nstderr:\n{tail}"


def _status_kb(key: str) -> int:
    m = re.search(rf"^{key}:\s+(\d+) kB", _STATUS.read_text(), re.M)
    return int(m.group(1)) if m else -1


def _can_reset_peak() -> bool:
    try:
        _CLEAR_REFS.write_text("5")
    except OSError:
        return False
    return _status_kb("VmHWM") > 0


@contextlib.contextmanager
def _address_space_cap():
    """Cap RLIMIT_AS at what the process maps now plus the guard (Linux; else no-op)."""
    try:
        import resource
    except ImportError:               # pragma: no cover - not POSIX
        yield
        return
    size_kb = _status_kb("VmSize") if _STATUS.exists() else -1
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    if size_kb < 0:
        yield
        return
    cap = size_kb * 1024 + ADDRESS_SPACE_GUARD
    if hard != resource.RLIM_INFINITY:
        cap = min(cap, hard)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


@contextlib.contextmanager
def _time_limit(seconds: float):
    """Raise :class:`CaseTimeout` after ``seconds`` (main thread with SIGALRM only)."""
    if threading.current_thread() is not threading.main_thread() or not hasattr(
            signal, "setitimer"):
        yield
        return

    def _expired(signum, frame):
        raise CaseTimeout(f"case ran longer than {seconds:g} s")

    old = signal.signal(signal.SIGALRM, _expired)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)


def run_cli(argv: list[str]) -> Outcome:
    """Call ``compare.cli.main(argv)`` with captured output, warnings recorded, memory
    measured and the address space and time capped.

    Parameters
    ----------
    argv : list of str
        Arguments after ``feedoracle``.

    Returns
    -------
    Outcome
    """
    out, err = io.StringIO(), io.StringIO()
    use_rss = _can_reset_peak()
    if use_rss:
        base_kb = _status_kb("VmRSS")
    else:
        tracemalloc.start(1)
    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        # "always": record every warning, also one a module already raised once (the
        # default filter would hide a repeat from the second case on)
        warnings.simplefilter("always")
        with (_address_space_cap(), _time_limit(TIME_LIMIT_S),
              contextlib.redirect_stdout(out), contextlib.redirect_stderr(err)):
            code = main(list(argv))
    seconds = time.perf_counter() - t0
    if use_rss:
        peak = (_status_kb("VmHWM") - base_kb) * 1024
    else:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    warned = tuple(f"{w.category.__name__}: {w.message} ({w.filename}:{w.lineno})"
                   for w in caught)
    return Outcome(tuple(argv), code, out.getvalue(), err.getvalue(), peak, seconds, warned)


def assert_clean(outcome: Outcome, files: list[Path]) -> None:
    """Assert the CLI behaved (module docstring): exit 0/1/2, no traceback, no warning,
    under the memory budget, and an exit-2 message that names a file line or a key.

    Parameters
    ----------
    outcome : Outcome
    files : list of pathlib.Path
        The input files of the call (program, machine); an exit-2 message must name one
        of them with a line, or a machine-data key.
    """
    why = outcome.describe()
    assert outcome.code in (0, 1, 2), why
    assert "Traceback (most recent call last)" not in outcome.err, why
    assert not outcome.warned, f"{why}\nwarnings that reached the user: {outcome.warned}"
    assert outcome.peak_bytes <= MEMORY_BUDGET_BYTES, (
        f"{why}\npeak memory {outcome.peak_bytes / 2**20:.0f} MiB above the budget "
        f"{MEMORY_BUDGET_BYTES / 2**20:.0f} MiB")
    if outcome.code != 2:
        return
    lines = outcome.err.rstrip("\n").splitlines()
    assert lines, why
    errors = [ln for ln in lines if ln.startswith("feedoracle: ")]
    assert errors == [lines[-1]], f"{why}\nexpected one error line, last"
    msg = lines[-1][len("feedoracle: "):]
    names = [re.escape(str(f)) for f in files]
    at_file_line = any(re.search(n + _AT_LINE, msg) for n in names)
    at_key = bool(re.match(rf"(?:(?:{'|'.join(names)}): )?{_KEY}", msg))
    no_motion = any(msg.startswith(str(f) + _NO_MOTION) for f in files)
    assert at_file_line or at_key or no_motion, (
        f"{why}\nthe error names neither a file line nor a machine-data key")

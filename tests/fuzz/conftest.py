"""Hypothesis profiles of the fuzz suite and the path to its helper modules.

``ci`` (the default, part of ``make test``): few examples, derandomized so that every run
of CI tests the same cases, no example database, no per-example deadline (a ``compare``
runs the oracle; its time varies with the machine, and a hang is caught by the harness's
own time limit). ``fuzz`` (``FEEDORACLE_FUZZ=1``, i.e. ``make fuzz``): many more examples,
random, with the example database in ``.hypothesis/`` so that a failure found once is
replayed first next time. The example counts can be overridden with
``FEEDORACLE_FUZZ_EXAMPLES``.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from hypothesis import HealthCheck, Phase, settings

sys.path.insert(0, str(Path(__file__).parent))

_SLOW_OK = [HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much]

settings.register_profile(
    "ci", max_examples=int(os.environ.get("FEEDORACLE_FUZZ_EXAMPLES", 0)) or 50,
    deadline=None, derandomize=True, database=None, print_blob=True,
    suppress_health_check=_SLOW_OK,
    # no shrinking in CI: a derandomized failure is reproducible as it is, and shrinking
    # a compare-heavy case could take minutes; `make fuzz` shrinks
    phases=[Phase.explicit, Phase.generate])
settings.register_profile(
    "fuzz", max_examples=int(os.environ.get("FEEDORACLE_FUZZ_EXAMPLES", 0)) or 400,
    deadline=None, print_blob=True, suppress_health_check=_SLOW_OK)
settings.load_profile("fuzz" if os.environ.get("FEEDORACLE_FUZZ") else "ci")

"""Makes ``tests/`` importable from every test directory: ``from shared_inputs import ...``.

``tests/shared_inputs.py`` is the one place that says where ``../shared`` (the inputs
written by others) is; the tests in ``tests/compare``, ``tests/reference``, ... import it
by its plain name, as they import their own helpers (``fakes``, ``seeded_programs``).

Why here: pytest loads this conftest before it collects anything below ``tests/``,
whichever subset of the suite runs. The test directories have no ``__init__.py``, so
under pytest's default ``prepend`` import mode a file's own directory is put on
``sys.path`` when it is imported (that is how ``fakes`` and ``seeded_programs`` are
found, and importing this file already adds ``tests/``). The explicit insert below does
not rely on that: it holds under ``--import-mode=importlib`` too, and it tells a reader
where the name comes from. The standalone scripts in ``tests/bench`` put ``tests/`` on
``sys.path`` themselves.

The repository root goes on ``sys.path`` as well: with ``tests/`` there, the folders
``tests/reference``, ``tests/optimal`` and ``tests/compare`` (no ``__init__.py``) are
namespace-package candidates for ``import reference`` etc., and the editable install's
finder is asked only after them; a regular package on ``sys.path`` beats a namespace
one, so the real packages are imported. ``python -m pytest`` from the root has the root
there already; the ``pytest`` script, or a run from another directory, does not.
"""

from __future__ import annotations

import sys
from pathlib import Path

_TESTS = Path(__file__).resolve().parent
for _entry in (str(_TESTS), str(_TESTS.parent)):     # no module name is in both
    if _entry not in sys.path:
        sys.path.insert(0, _entry)

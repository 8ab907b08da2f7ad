"""``python -m compare`` is the ``feedoracle`` command."""

from .cli import main

raise SystemExit(main())

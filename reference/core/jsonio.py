"""The one JSON encoding of results: how non-finite numbers are written.

JSON has no infinity and no NaN. Every part of the result contract (the planner's, the
oracle's and the comparison's, DESIGN section 7) is written by :func:`write_json`, so
there is one rule:

* ``+inf`` (a velocity jump at a corner where the machine allows none has ratio
  ``inf``; an upper bound that does not exist; a gap upper end with a zero lower bound)
  is written as ``1.7976931348623157e+308``, the largest double, together with a sibling
  flag ``"<name>_infinite": true``. It parses back to a float larger than any real
  value, so ``ratio > 1`` tests stay right;
* ``-inf`` as ``-1.7976931348623157e+308`` (same flag);
* ``NaN`` (a quantity that does not exist, e.g. the oracle's speed without an oracle
  profile) by leaving the key out, or ``null`` inside lists.

Producers leave ``inf`` and ``NaN`` in their dicts as they are; they never encode.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path as FsPath
from typing import Any

import numpy as np

#: How +inf is written (see the module docstring).
JSON_INF = sys.float_info.max


def _nonfinite(v: Any) -> bool:
    return isinstance(v, (float, np.floating)) and not math.isfinite(float(v))


def json_ready(obj: Any) -> Any:
    """``obj`` with non-finite floats encoded and numpy scalars made plain, recursively.

    Parameters
    ----------
    obj : dict, list, tuple or scalar

    Returns
    -------
    The same structure, ``json.dumps(..., allow_nan=False)`` ready.
    """
    if isinstance(obj, dict):
        out = {}
        for k, v in obj.items():
            if _nonfinite(v):
                if math.isnan(float(v)):
                    continue
                out[k] = JSON_INF if v > 0 else -JSON_INF
                out[f"{k}_infinite"] = True
            else:
                out[k] = json_ready(v)
        return out
    if isinstance(obj, (list, tuple)):
        return [(None if math.isnan(float(v)) else JSON_INF if v > 0 else -JSON_INF)
                if _nonfinite(v) else json_ready(v) for v in obj]
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating):
        return float(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


def dumps(obj: dict | list) -> str:
    """Strict JSON text of a result (non-finite floats encoded as above)."""
    return json.dumps(json_ready(obj), indent=1, allow_nan=False, ensure_ascii=False) + "\n"


def write_json(obj: dict | list, file: str | FsPath) -> None:
    """Write a result as JSON (``-`` writes to standard output)."""
    text = dumps(obj)
    if str(file) == "-":
        sys.stdout.write(text)
        return
    FsPath(file).parent.mkdir(parents=True, exist_ok=True)
    FsPath(file).write_text(text, encoding="utf-8")

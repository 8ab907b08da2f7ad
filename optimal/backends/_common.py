"""Helpers shared by the backend adapters (numpy only)."""

from __future__ import annotations

from typing import Mapping

import numpy as np


def check_options(backend: str, options: Mapping[str, object] | None,
                  known: Mapping[str, type]) -> dict[str, object]:
    """Validate backend options against the adapter's known keys (G14).

    Parameters
    ----------
    backend : str
        Backend name for the message.
    options : Mapping or None
        User options.
    known : Mapping[str, type]
        Accepted keys and their types.

    Returns
    -------
    dict
        A copy of the options.

    Raises
    ------
    ValueError
        An unknown key or a value of the wrong type.
    """
    opts = dict(options or {})
    for key, val in opts.items():
        if key not in known:
            raise ValueError(f"backend {backend!r} has no option {key!r}; known options: "
                             f"{', '.join(sorted(known)) or 'none'}")
        typ = known[key]
        if not isinstance(val, typ) or (typ is int and isinstance(val, bool)):
            raise ValueError(f"backend {backend!r} option {key!r} = {val!r}: must be "
                             f"{getattr(typ, '__name__', typ)}")
    return opts


def sparse_rows(problem):
    """Non-empty rows of a problem as COO triplets over the ``N + 1`` node variables.

    Returns
    -------
    rows, cols : numpy.ndarray of int
        Row and column index of each non-zero.
    vals : numpy.ndarray
        Coefficients, each row normalised by its largest coefficient.
    rhs : numpy.ndarray
        Normalised right-hand sides, one per row.
    """
    c1, c2, h = problem.c1, problem.c2, problem.h
    k, r = np.nonzero((c1 != 0) | (c2 != 0))
    a1, a2, hh = c1[k, r], c2[k, r], h[k, r]
    norm = np.maximum(np.abs(a1), np.abs(a2))
    a1, a2, hh = a1 / norm, a2 / norm, hh / norm
    n_rows = k.size
    row_id = np.arange(n_rows)
    rows = np.concatenate((row_id, row_id))
    cols = np.concatenate((k, k + 1))
    vals = np.concatenate((a1, a2))
    keep = vals != 0
    return rows[keep], cols[keep], vals[keep], hh

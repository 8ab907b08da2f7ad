"""Read-only array storage for the frozen result records of every package.

A frozen dataclass freezes its attributes, not the numpy arrays they hold: each record
stores its arrays through :func:`readonly`, so a result cannot be changed in place after
it was checked.
"""

from __future__ import annotations

import numpy as np


def readonly(a, dtype=None) -> np.ndarray:
    """A contiguous, write-protected array of ``a`` (converted to ``dtype`` if given).

    Parameters
    ----------
    a : array_like
    dtype : numpy dtype, optional
        Default: keep ``a``'s own (float64 for Python floats).

    Returns
    -------
    numpy.ndarray
        Not writeable; a copy only where ``a`` was not contiguous or of another dtype.
    """
    out = np.ascontiguousarray(a, dtype=dtype)
    out.setflags(write=False)
    return out

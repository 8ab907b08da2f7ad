"""Inserted blocks on their own comparison rows.

The corner-rounding stage (:mod:`reference.rounding`) attributes each rounding to the
program block whose end is its corner, so every program
block keeps exactly one :class:`~reference.core.geometry.BlockSpan` and both planners'
per-block numbers stay keyed by program block. For people, the comparison shows an
inserted segment on a row of its own, named by its corner: :func:`inserted_pieces` finds
those segments and :func:`stretch_motion` measures a profile on any stretch of the path
exactly (the same knots and stationary points :func:`reference.core.rows.block_motion`
uses), so the corner block's row and its inserted rows split the block's time without
loss. Both live in :mod:`reference.core.rows`: ``feedoracle plan`` splits its rows the
same way.
"""

from __future__ import annotations

from reference.core.rows import inserted_pieces, inserted_splits, stretch_motion

__all__ = ["inserted_pieces", "inserted_splits", "stretch_motion"]

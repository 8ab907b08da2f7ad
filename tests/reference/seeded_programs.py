"""Seeded NC program bodies shared by the planner tests and the rounding benchmark."""

from __future__ import annotations

import numpy as np


def polyline(n: int, seed: int) -> str:
    """``n`` seeded lines of 0.5..5 mm with turns of 5..120 degrees (body only: ``X.. Y..``
    words, one line each, then ``M30``)."""
    rng = np.random.default_rng(seed)
    heading, x, y, out = 0.0, 0.0, 0.0, []
    for _ in range(n):
        heading += np.radians(rng.uniform(5.0, 120.0)) * rng.choice((-1.0, 1.0))
        step = rng.uniform(0.5, 5.0)
        x += step * np.cos(heading)
        y += step * np.sin(heading)
        out.append(f"X{x:.4f} Y{y:.4f}")
    return "\n".join(out) + "\nM30\n"

"""Unit conversions at the boundary. Inside, everything is mm, s, degrees (rotary axes).

Machine data come in SINUMERIK units (mm/min, m/s^2, m/s^3; rev/min, rev/s^2, rev/s^3
for rotary axes); programs in mm or inch and mm/min or in/min.
"""

from __future__ import annotations

MM_PER_INCH = 25.4
MM_PER_M = 1000.0
S_PER_MIN = 60.0
DEG_PER_REV = 360.0


def mm_min_to_mm_s(value: float) -> float:
    """Convert mm/min to mm/s."""
    return value / S_PER_MIN


def mm_s_to_mm_min(value: float) -> float:
    """Convert mm/s to mm/min."""
    return value * S_PER_MIN


def m_to_mm(value: float) -> float:
    """Convert m (or m/s^k) to mm (or mm/s^k)."""
    return value * MM_PER_M


def rev_to_deg(value: float) -> float:
    """Convert revolutions (or rev/s^k) to degrees (or deg/s^k)."""
    return value * DEG_PER_REV


def inch_to_mm(value: float) -> float:
    """Convert inch to mm."""
    return value * MM_PER_INCH

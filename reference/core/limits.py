"""Axis and machine limits in internal units (mm, s, degrees), immutable.

Machine data files use SINUMERIK units; ``reference.machine`` converts them once into
these records. Everything downstream (oracle, heuristic, checker) reads only these.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import MachineDataError


@dataclass(frozen=True, slots=True)
class AxisLimits:
    """Dynamic limits of one machine axis.

    Attributes
    ----------
    name : str
        Axis name (``"X"``, ``"A"``, ...).
    v_max : float
        Velocity limit (MD32000), mm/s (deg/s for rotary axes).
    a_max : float
        Acceleration limit (MD32300), mm/s^2 (deg/s^2).
    j_max : float
        Jerk limit used by path planning (MD32431), mm/s^3 (deg/s^3).
    overload_factor : float
        MD32310 MAX_ACCEL_OVL_FACTOR (>= 1): velocity jumps at non-tangential block
        transitions may reach ``a_max * (overload_factor - 1) * t_ipo``.
    frequency_hz : float
        MD32440 LOOKAH_FREQUENCY, Hz: no velocity-change process involving this axis may
        be shorter than ``1 / frequency_hz``.
    path_trans_jerk : float
        MD32432 PATH_TRANS_JERK_LIM, mm/s^3: jerk allowed at block transitions with a
        curvature jump (SOFT).
    rotary : bool
        True for rotary axes (units are degrees).
    """

    name: str
    v_max: float
    a_max: float
    j_max: float
    overload_factor: float = 1.2
    frequency_hz: float = 10.0
    path_trans_jerk: float = float("nan")
    rotary: bool = False

    def __post_init__(self) -> None:
        for key, unit in (("v_max", "mm/s"), ("a_max", "mm/s^2"), ("j_max", "mm/s^3"),
                          ("frequency_hz", "Hz")):
            val = getattr(self, key)
            if not (isinstance(val, (int, float)) and np.isfinite(val) and val > 0):
                raise MachineDataError(f"axis.{self.name}.{key}", val,
                                       f"must be a finite number > 0 {unit}")
        if not (np.isfinite(self.overload_factor) and self.overload_factor >= 1.0):
            raise MachineDataError(f"axis.{self.name}.overload_factor", self.overload_factor,
                                   "must be >= 1.0 (1.0 = stop at every corner)")
        if np.isnan(self.path_trans_jerk):
            object.__setattr__(self, "path_trans_jerk", float(self.j_max))
        elif not self.path_trans_jerk > 0:
            raise MachineDataError(f"axis.{self.name}.path_trans_jerk", self.path_trans_jerk,
                                   "must be > 0 mm/s^3")


@dataclass(frozen=True, slots=True)
class AxisArrays:
    """Limits of a path's axes as arrays in the path's axis order, each shape ``(n,)``.

    Attributes
    ----------
    v_max, a_max, j_max : numpy.ndarray
        mm/s, mm/s^2, mm/s^3 (degrees for rotary axes).
    jump : numpy.ndarray
        Allowed velocity jump at a non-tangential transition,
        ``a_max * (overload_factor - 1) * t_ipo``, mm/s.
    frequency_hz : numpy.ndarray
        LOOKAH_FREQUENCY per axis, Hz.
    path_trans_jerk : numpy.ndarray
        PATH_TRANS_JERK_LIM per axis, mm/s^3.
    """

    v_max: np.ndarray
    a_max: np.ndarray
    j_max: np.ndarray
    jump: np.ndarray
    frequency_hz: np.ndarray
    path_trans_jerk: np.ndarray


@dataclass(frozen=True, slots=True)
class MachineLimits:
    """All axes' limits plus the interpolation cycle.

    Attributes
    ----------
    axes : tuple[AxisLimits, ...]
        One entry per machine axis.
    t_ipo_s : float
        Interpolation (IPO) cycle, s.
    name : str
        Machine name (for reports).
    """

    axes: tuple[AxisLimits, ...]
    t_ipo_s: float
    name: str = "machine"

    def __post_init__(self) -> None:
        if not (np.isfinite(self.t_ipo_s) and self.t_ipo_s > 0):
            raise MachineDataError("machine.ipo_cycle_ms", self.t_ipo_s * 1e3,
                                   "must be a finite number > 0 ms")
        names = [a.name for a in self.axes]
        if len(set(names)) != len(names):
            raise MachineDataError("axis", names, "axis names must be unique")

    @property
    def names(self) -> tuple[str, ...]:
        """Axis names in machine order."""
        return tuple(a.name for a in self.axes)

    def axis(self, name: str) -> AxisLimits:
        """Limits of one axis by name.

        Raises
        ------
        MachineDataError
            The machine defines no such axis.
        """
        for a in self.axes:
            if a.name == name:
                return a
        raise MachineDataError(f"axis.{name}", None,
                               f"machine '{self.name}' defines no axis {name} "
                               f"(it has {', '.join(self.names)})")

    def for_axes(self, names: tuple[str, ...]) -> AxisArrays:
        """Limits as arrays ordered like ``names`` (a path's axes).

        Parameters
        ----------
        names : tuple[str, ...]
            Axis names of the path, length ``n``.

        Returns
        -------
        AxisArrays
            Arrays of shape ``(n,)``.

        Raises
        ------
        MachineDataError
            An axis of the path has no limits in this machine.
        """
        ax = [self.axis(n) for n in names]
        arr = lambda f: np.array([f(a) for a in ax], dtype=np.float64)  # noqa: E731
        return AxisArrays(
            v_max=arr(lambda a: a.v_max), a_max=arr(lambda a: a.a_max),
            j_max=arr(lambda a: a.j_max),
            jump=arr(lambda a: a.a_max * (a.overload_factor - 1.0) * self.t_ipo_s),
            frequency_hz=arr(lambda a: a.frequency_hz),
            path_trans_jerk=arr(lambda a: a.path_trans_jerk))

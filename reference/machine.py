"""Machine data (``machine.toml``): load, validate and convert once to mm and s.

Names follow SINUMERIK machine data so values can be copied from a control; units are
the control's at the boundary (see the tables below) and mm, s, degrees inside.
Unknown keys, wrong types, non-positive limits and implausible magnitudes (the usual
sign of a unit mix-up, e.g. MAX_AX_ACCEL given in mm/s^2) raise
:class:`~reference.core.errors.MachineDataError` naming the key, the value and the rule.
"""

from __future__ import annotations

import difflib
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path as FsPath
from typing import Any

from .core.errors import MachineDataError
from .core.limits import AxisLimits, MachineLimits
from .core.units import m_to_mm, mm_min_to_mm_s, rev_to_deg
from .tools import EMPTY_TOOLS, ToolTable, tools_from_toml

DEFAULT_MACHINE = "default"
BUNDLED_MACHINES = ("default", "linuxcnc_xyz")


@dataclass(frozen=True, slots=True)
class _Key:
    """One machine-data key: expected type, unit, plausible range (in file units)."""

    kind: type | tuple[type, ...]
    unit: str
    lo: float | None = None       # exclusive lower bound (None: no check)
    hi: float | None = None       # inclusive upper bound: above it the unit is likely wrong
    doc: str = ""
    low: float | None = None      # plausible minimum: below it the unit is likely wrong


# Plausible ranges cover real machines from small routers to large gantries; a value
# outside is almost always a unit error (m/min for mm/min, mm/s^2 for m/s^2), so it is
# rejected with the unit named instead of silently giving a 1000x wrong answer. Every
# number key has both ends: a plausible maximum ``hi`` and, for the keys a planner divides
# by or multiplies a limit with, a plausible minimum ``low`` (a value such as 1e-300 is a
# unit or typing error, and would otherwise divide by zero or stretch a profile to
# astronomical times). The minima sit one to three decades below the smallest value of
# real machine data (a hobby router accelerates with about 0.1 m/s^2, jerks with about
# 1 m/s^3, samples at 10 Hz; tolerances are at least 1 um).
_MACHINE_KEYS: dict[str, _Key] = {
    "name": _Key(str, ""),
    "ipo_cycle_ms": _Key((int, float), "ms", 0.0, 100.0, "IPO cycle (MD10050 x MD10070)",
                         0.01),
}

_CHANNEL_KEYS: dict[str, _Key] = {
    "SMOOTHING_MODE": _Key(int, "", -1, 99999, "MD20480 decimal digit map"),
    "IGNORE_OVL_FACTOR_FOR_ADIS": _Key(bool, "", doc="MD20490"),
    "LOOKAH_SMOOTH_FACTOR": _Key((int, float), "%", -1e-12, 100.0,
                                  "MD20460 (0 selects the internal 100 %)"),
    "ADAPT_PATH_DYNAMIC": _Key(list, "", doc="MD20465 [BRISK, SOFT], each >= 1"),
    "lookahead_blocks": _Key(int, "blocks", 0, 100000, "LookAhead horizon"),
    "SMOOTH_CONTUR_TOL": _Key((int, float), "mm", 0.0, 100.0, "SD42465", 1e-6),
    "SMOOTH_ORI_TOL": _Key((int, float), "deg", 0.0, 90.0, "SD42466", 1e-6),
    "CUTCOM_CORNER_LIMIT": _Key((int, float), "deg", 0.0, 180.0, "MD20210", 1e-3),
    "CUTCOM_CURVE_INSERT_LIMIT": _Key((int, float), "deg", -1e-12, 180.0, "MD20230"),
    "CUTCOM_MAX_DISC": _Key((int, float), "", -1e-12, 100.0, "MD20220 (0..100)"),
    "CUTCOM_840C_MD6": _Key((int, float), "mm", -1e-12, 100.0,
                            "840C MD6 TRC switch-over threshold, 0 = off"),
    "acceleration_mode": _Key(str, "", doc="BRISK | SOFT"),
    "MAX_PATH_JERK": _Key((int, float), "m/s^3", 0.0, 1e6, "MD20600", 1e-3),
    "G0_TOLERANCE_FACTOR": _Key((int, float), "", 0.0, 1000.0, "MD20560", 1e-3),
    "rounding_length_clamp": _Key((int, float), "", 0.0, 0.5, "block-length clamp c", 1e-3),
}

#: Largest MD35230 ACCEL_REDUCTION_FACTOR: a_red = (1 - factor) MAX_AX_ACCEL must stay a
#: real acceleration (1 would stop the axis from accelerating above the knee at all);
#: a reduction to less than 1 % is a typing error, not a drive.
_DRIVE_FACTOR_MAX = 0.99

_AXIS_KEYS: dict[str, _Key] = {
    "type": _Key(str, "", doc="linear | rotary"),
    "MAX_AX_VELO": _Key((int, float), "mm/min", 1.0, 1e7, "MD32000 (rotary: rev/min)"),
    "MAX_AX_ACCEL": _Key((int, float), "m/s^2", 0.0, 200.0, "MD32300 (rotary: rev/s^2)",
                         1e-4),
    "MAX_AX_JERK": _Key((int, float), "m/s^3", 0.0, 1e5, "MD32431 (rotary: rev/s^3)",
                        1e-3),
    "MAX_ACCEL_OVL_FACTOR": _Key((int, float), "", None, 10.0, "MD32310, >= 1"),
    "LOOKAH_FREQUENCY": _Key((int, float), "Hz", 0.0, 1000.0, "MD32440", 1e-2),
    "PATH_TRANS_JERK_LIM": _Key((int, float), "m/s^3", 0.0, 1e5, "MD32432", 1e-3),
    "COMPRESS_POS_TOL": _Key((int, float), "mm", 0.0, 100.0, "MD33100", 1e-6),
    "PATH_TRANS_POS_TOL": _Key((int, float), "mm", 0.0, 100.0, "MD33120", 1e-6),
    "EPS_TLIFT_TANG_STEP": _Key((int, float), "deg", 0.0, 180.0, "MD37400", 1e-3),
    "POSCTRL_GAIN": _Key((int, float), "(m/min)/mm", 0.0, 100.0, "MD32200", 1e-3),
    "STOP_LIMIT_FINE": _Key((int, float), "mm", 0.0, 10.0, "MD36010", 1e-6),
    "STOP_LIMIT_COARSE": _Key((int, float), "mm", 0.0, 10.0, "MD36000", 1e-6),
    "VELO_FFW_WEIGHT": _Key((int, float), "", -1e-12, 1.0, "MD32610 (0..1)"),
    "SOFT_ACCEL_FACTOR": _Key((int, float), "", 0.0, 10.0, "MD32433", 1e-3),
    "G00_ACCEL_FACTOR": _Key((int, float), "", 0.0, 10.0, "MD32434", 1e-3),
    "G00_JERK_FACTOR": _Key((int, float), "", 0.0, 10.0, "MD32435", 1e-3),
    "ACCEL_REDUCTION_SPEED_POINT": _Key((int, float), "", 0.0, 1.0,
                                        "MD35220: share of MAX_AX_VELO, 0..1", 1e-3),
    "ACCEL_REDUCTION_FACTOR": _Key((int, float), "", -1e-12, _DRIVE_FACTOR_MAX,
                                   "MD35230: a_red = (1 - factor) MAX_AX_ACCEL, 0..0.99"),
    "ACCEL_TYPE_DRIVE": _Key(int, "", None, None, "MD35240: 0 constant, 1 hyperbolic, 2 linear"),
}


#: Plausible maximum of each ADAPT_PATH_DYNAMIC factor: the control divides the path
#: acceleration and jerk by it; real data use 1..4, and 10 (like the other factor keys)
#: still leaves room while rejecting inf or a value typed in the wrong field.
_ADAPT_MAX = 10.0
#: Longest machine name: it heads tables and report titles.
_NAME_MAX = 200


@dataclass(frozen=True, slots=True)
class AxisSettings:
    """Per-axis machine data the heuristic uses beyond the dynamic limits (mm, s, deg).

    Attributes
    ----------
    compress_pos_tol_mm : float
        MD33100 COMPRESS_POS_TOL, mm (degrees for rotary axes).
    path_trans_pos_tol_mm : float
        MD33120 PATH_TRANS_POS_TOL, mm (degrees for rotary axes): the deviation G645 may
        use to round a tangential transition with a curvature jump (spec 5.7: "used
        only at tangential transitions"). Default 0.005 [M].
    eps_tlift_deg : float
        MD37400 EPS_TLIFT_TANG_STEP, degrees.
    kv_per_s : float
        Position-controller gain MD32200 converted to 1/s (1 (m/min)/mm = 16.667 1/s).
    stop_fine_mm, stop_coarse_mm : float
        MD36010 / MD36000 exact-stop windows, mm.
    velo_ffw_weight : float
        MD32610 VELO_FFW_WEIGHT in effect during the program, 0..1 (0 = no velocity
        feed-forward: following error ``v/Kv``; 1 = ideal feed-forward). Used by the
        exact-stop settle model (:mod:`reference.holds`). Default 0.
    soft_accel_factor, g00_accel_factor, g00_jerk_factor : float
        MD32433 / MD32434 / MD32435.
    accel_reduction_speed_point : float
        MD35220 ACCEL_REDUCTION_SPEED_POINT: DRIVE reduces the acceleration above this
        share of MAX_AX_VELO (1 = never). Default 1.
    accel_reduction_factor : float
        MD35230 ACCEL_REDUCTION_FACTOR: ``a_red = (1 - factor) MAX_AX_ACCEL``
        (0 = no reduction). Default 0.
    accel_type_drive : int
        MD35240 ACCEL_TYPE_DRIVE, the characteristic above the knee: 0 constant,
        1 hyperbolic, 2 linear (:mod:`reference.planner.drive`). Default 0.
    """

    compress_pos_tol_mm: float = 0.01
    path_trans_pos_tol_mm: float = 0.005
    eps_tlift_deg: float = 5.0
    kv_per_s: float = 1.0 * 1000.0 / 60.0
    stop_fine_mm: float = 0.01
    stop_coarse_mm: float = 0.04
    velo_ffw_weight: float = 0.0
    soft_accel_factor: float = 1.0
    g00_accel_factor: float = 1.0
    g00_jerk_factor: float = 1.0
    accel_reduction_speed_point: float = 1.0
    accel_reduction_factor: float = 0.0
    accel_type_drive: int = 0


@dataclass(frozen=True, slots=True)
class ChannelSettings:
    """Channel machine data that drive the heuristic (mm, s).

    Attributes
    ----------
    smoothing_mode : int
        MD20480 SMOOTHING_MODE (decimal digits, see sinumerik-model 5.9).
    ignore_ovl_factor_for_adis : bool
        MD20490.
    lookahead_smooth_factor_pct : float
        MD20460 LOOKAH_SMOOTH_FACTOR, % allowed time loss, as given. 0 (also the value
        when the key is missing) selects the control's internal 100 %: "a smoothing
        factor other than 0% prevents the default value of 100% from being used" (B1
        excerpt; :func:`reference.planner.smoothing.effective_factor`). A small value
        such as 1 % switches the smoothing practically off.
    adapt_path_dynamic : tuple[float, float]
        MD20465 ADAPT_PATH_DYNAMIC for [BRISK, SOFT]; 1.0 = off.
    lookahead_blocks : int
        Prepared blocks the LookAhead sees; v = 0 is assumed at the horizon end.
    smooth_contour_tol_mm : float
        SD42465 SMOOTH_CONTUR_TOL, mm.
    smooth_ori_tol_deg : float
        SD42466 SMOOTH_ORI_TOL, degrees.
    cutcom_corner_limit_deg : float
        MD20210 CUTCOM_CORNER_LIMIT, degrees: at outside corners whose deflection (the
        change of direction) exceeds it, G451 switches to G450 (sinumerik-model 9).
    cutcom_curve_insert_limit_deg : float
        MD20230 CUTCOM_CURVE_INSERT_LIMIT, degrees: outside corners whose deflection is
        below it get the intersection instead of a transition circle (default 10 [M]).
    cutcom_max_disc : float
        MD20220 CUTCOM_MAX_DISC: the largest DISC value accepted (default 50 [M]).
    cutcom_840c_md6_mm : float
        Emulate the 840C's MD6 rule at outside corners with arcs (sinumerik-model 9 and
        the 840C excerpt), threshold in mm; 0 = off (840D behaviour).
    acceleration_mode : {"BRISK", "SOFT"}
        Default group-21 mode.
    max_path_jerk : float
        MD20600 MAX_PATH_JERK, mm/s^3.
    g0_tolerance_factor : float
        MD20560 G0_TOLERANCE_FACTOR.
    rounding_length_clamp : float
        Model knob c: a rounding distance is at most c times each neighbouring block.
    """

    smoothing_mode: int = 0
    ignore_ovl_factor_for_adis: bool = False
    lookahead_smooth_factor_pct: float = 0.0
    adapt_path_dynamic: tuple[float, float] = (1.0, 1.0)
    lookahead_blocks: int = 200
    smooth_contour_tol_mm: float = 0.05
    smooth_ori_tol_deg: float = 1.0
    cutcom_corner_limit_deg: float = 100.0
    cutcom_curve_insert_limit_deg: float = 10.0
    cutcom_max_disc: float = 50.0
    cutcom_840c_md6_mm: float = 0.0
    acceleration_mode: str = "SOFT"
    max_path_jerk: float = 1e8
    g0_tolerance_factor: float = 3.0
    rounding_length_clamp: float = 0.5


@dataclass(frozen=True, slots=True)
class Machine:
    """A whole machine: dynamic limits (shared with the oracle) plus control settings.

    Attributes
    ----------
    name : str
        Machine name.
    source : str
        File it was loaded from (``"<bundled:default>"`` for bundled data).
    limits : MachineLimits
        Per-axis v, a, j, overload factor, frequency and the IPO cycle.
    channel : ChannelSettings
        Channel machine data.
    axis_settings : tuple[tuple[str, AxisSettings], ...]
        Per-axis settings by axis name.
    tools : ToolTable
        Tool radii per tool and cutting edge (``[tools]``, and a LinuxCNC tool table
        given with ``--tool-table``), for tool radius compensation.
    """

    name: str
    source: str
    limits: MachineLimits
    channel: ChannelSettings
    axis_settings: tuple[tuple[str, AxisSettings], ...]
    tools: ToolTable = EMPTY_TOOLS

    def settings_of(self, axis: str) -> AxisSettings:
        """Per-axis settings by axis name (defaults for an unknown axis)."""
        for name, st in self.axis_settings:
            if name == axis:
                return st
        return AxisSettings()


def _check(section: str, key: str, value: Any, spec: _Key, source: str) -> None:
    dotted = f"{section}.{key}" if section else key
    kinds = spec.kind if isinstance(spec.kind, tuple) else (spec.kind,)
    # bool is an int in Python; a number key must not accept true/false
    if isinstance(value, bool) and bool not in kinds:
        ok = False
    else:
        ok = isinstance(value, kinds)
    if not ok:
        want = " or ".join(k.__name__ for k in kinds).replace("int or float", "number")
        want = {"int": "n integer", "str": " string", "bool": " boolean"}.get(want, f" {want}")
        raise MachineDataError(dotted, value, f"must be a{want}"
                               + (f" in {spec.unit}" if spec.unit else ""), source)
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        if value != value or value in (float("inf"), float("-inf")):
            raise MachineDataError(dotted, value, "must be finite", source)
        if spec.lo is not None and not value > spec.lo:
            # lo just below 0 stands for ">= 0" (0 itself allowed)
            rule = ("must be >= 0" if -1e-9 < spec.lo < 0 else f"must be > {spec.lo:g}")
            raise MachineDataError(dotted, value, f"{rule} {spec.unit}".rstrip(), source)
        if spec.low is not None and value < spec.low and not spec.unit:
            raise MachineDataError(dotted, value, f"is below the plausible minimum "
                                   f"{spec.low:g} ({spec.doc})", source)
        if spec.low is not None and value < spec.low:
            raise MachineDataError(
                dotted, value, f"is below the plausible minimum {spec.low:g} {spec.unit}; "
                f"check the unit ({spec.doc} is given in {spec.unit})".replace(" ;", ";")
                .replace("( is given in )", "(a factor)"), source)
        if spec.hi is not None and value > spec.hi and not spec.unit:
            # a share, a factor or a code: no unit to mix up
            raise MachineDataError(dotted, value, f"must be <= {spec.hi:g} ({spec.doc})",
                                   source)
        if spec.hi is not None and value > spec.hi:
            raise MachineDataError(
                dotted, value, f"is above the plausible maximum {spec.hi:g} {spec.unit}; "
                f"check the unit ({spec.doc} is given in {spec.unit})", source)


def _unknown(section: str, key: str, value: Any, known: dict[str, _Key], source: str):
    close = difflib.get_close_matches(key.upper(), list(known), n=1, cutoff=0.6) or [
        k for k in known if k.lower() == key.lower()]
    hint = f" (did you mean {close[0]}?)" if close else ""
    raise MachineDataError(f"{section}.{key}" if section else key, value,
                           f"unknown key{hint}; known keys: {', '.join(sorted(known))}", source)


def machine_from_dict(data: dict[str, Any], source: str = "<dict>") -> Machine:
    """Validate a parsed ``machine.toml`` and convert it to internal units.

    Parameters
    ----------
    data : dict
        The TOML document as a dict (sections ``machine``, ``channel``, ``axis.<NAME>``,
        ``tools``: see :mod:`reference.tools`).
    source : str
        Where it came from, for messages.

    Returns
    -------
    Machine

    Raises
    ------
    MachineDataError
        Unknown section or key, wrong type, non-positive or implausible value.
    """
    for sec in data:
        if sec not in ("machine", "channel", "axis", "tools"):
            raise MachineDataError(sec, data[sec], "unknown section; expected [machine], "
                                   "[channel], [axis.<NAME>] and [tools]", source)
    for sec in ("machine", "channel"):
        if sec in data and not isinstance(data[sec], dict):
            raise MachineDataError(sec, data[sec], f"must be a table: a [{sec}] section with "
                                   "keys, not a value", source)
    mach = data.get("machine", {})
    for k, v in mach.items():
        if k not in _MACHINE_KEYS:
            _unknown("machine", k, v, _MACHINE_KEYS, source)
        _check("machine", k, v, _MACHINE_KEYS[k], source)
    if "ipo_cycle_ms" not in mach:
        raise MachineDataError("machine.ipo_cycle_ms", None, "is required (IPO cycle in ms)",
                               source)
    t_ipo = mach["ipo_cycle_ms"] / 1000.0
    name = mach.get("name", FsPath(source).stem)
    if not name.strip() or not name.isprintable() or len(name) > _NAME_MAX:
        # the name goes into one-line messages, tables and report titles (escaped there)
        raise MachineDataError("machine.name", name, f"must be one line of printable text, "
                               f"1 to {_NAME_MAX} characters", source)

    ch = data.get("channel", {})
    for k, v in ch.items():
        if k not in _CHANNEL_KEYS:
            _unknown("channel", k, v, _CHANNEL_KEYS, source)
        _check("channel", k, v, _CHANNEL_KEYS[k], source)
    adapt = ch.get("ADAPT_PATH_DYNAMIC", [1.0, 1.0])
    if (len(adapt) != 2 or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                   and 1.0 <= x <= _ADAPT_MAX for x in adapt)):
        raise MachineDataError("channel.ADAPT_PATH_DYNAMIC", adapt,
                               f"must be two numbers >= 1.0 and <= {_ADAPT_MAX:g} "
                               "([BRISK, SOFT]; 1.0 = off; it divides the path dynamics, "
                               "so a larger factor is a typing error)", source)
    mode = ch.get("acceleration_mode", "SOFT")
    if mode not in ("BRISK", "SOFT"):
        raise MachineDataError("channel.acceleration_mode", mode, "must be BRISK or SOFT",
                               source)
    channel = ChannelSettings(
        smoothing_mode=ch.get("SMOOTHING_MODE", 0),
        ignore_ovl_factor_for_adis=ch.get("IGNORE_OVL_FACTOR_FOR_ADIS", False),
        lookahead_smooth_factor_pct=float(ch.get("LOOKAH_SMOOTH_FACTOR", 0.0)),
        adapt_path_dynamic=(float(adapt[0]), float(adapt[1])),
        lookahead_blocks=ch.get("lookahead_blocks", 200),
        smooth_contour_tol_mm=float(ch.get("SMOOTH_CONTUR_TOL", 0.05)),
        smooth_ori_tol_deg=float(ch.get("SMOOTH_ORI_TOL", 1.0)),
        cutcom_corner_limit_deg=float(ch.get("CUTCOM_CORNER_LIMIT", 100.0)),
        cutcom_curve_insert_limit_deg=float(ch.get("CUTCOM_CURVE_INSERT_LIMIT", 10.0)),
        cutcom_max_disc=float(ch.get("CUTCOM_MAX_DISC", 50.0)),
        cutcom_840c_md6_mm=float(ch.get("CUTCOM_840C_MD6", 0.0)),
        acceleration_mode=mode,
        max_path_jerk=m_to_mm(float(ch.get("MAX_PATH_JERK", 1e5))),
        g0_tolerance_factor=float(ch.get("G0_TOLERANCE_FACTOR", 3.0)),
        rounding_length_clamp=float(ch.get("rounding_length_clamp", 0.5)))

    axes_raw = data.get("axis", {})
    if not isinstance(axes_raw, dict) or not axes_raw:
        raise MachineDataError("axis", axes_raw, "at least one [axis.<NAME>] section is "
                               "required", source)
    axes: list[AxisLimits] = []
    settings: list[tuple[str, AxisSettings]] = []
    for ax, tbl in axes_raw.items():
        if not isinstance(tbl, dict):
            raise MachineDataError(f"axis.{ax}", tbl, "must be a table [axis.NAME]", source)
        sec = f"axis.{ax}"
        for k, v in tbl.items():
            if k not in _AXIS_KEYS:
                _unknown(sec, k, v, _AXIS_KEYS, source)
            _check(sec, k, v, _AXIS_KEYS[k], source)
        if tbl.get("ACCEL_TYPE_DRIVE", 0) not in (0, 1, 2):
            raise MachineDataError(f"{sec}.ACCEL_TYPE_DRIVE", tbl["ACCEL_TYPE_DRIVE"],
                                   "must be 0 (constant), 1 (hyperbolic) or 2 (linear)", source)
        for req in ("MAX_AX_VELO", "MAX_AX_ACCEL", "MAX_AX_JERK"):
            if req not in tbl:
                raise MachineDataError(f"{sec}.{req}", None,
                                       f"is required ({_AXIS_KEYS[req].unit})", source)
        kind = tbl.get("type", "rotary" if ax in ("A", "B", "C") else "linear")
        if kind not in ("linear", "rotary"):
            raise MachineDataError(f"{sec}.type", kind, "must be linear or rotary", source)
        rotary = kind == "rotary"
        conv = rev_to_deg if rotary else m_to_mm
        ovl = tbl.get("MAX_ACCEL_OVL_FACTOR", 1.2)
        if ovl < 1.0:
            raise MachineDataError(f"{sec}.MAX_ACCEL_OVL_FACTOR", ovl,
                                   "must be >= 1.0 (1.0 = stop at every corner)", source)
        v_mm_min = tbl["MAX_AX_VELO"] * (360.0 if rotary else 1.0)
        j = conv(tbl["MAX_AX_JERK"])
        axes.append(AxisLimits(
            name=ax, v_max=mm_min_to_mm_s(v_mm_min), a_max=conv(tbl["MAX_AX_ACCEL"]),
            j_max=j, overload_factor=float(ovl),
            frequency_hz=float(tbl.get("LOOKAH_FREQUENCY", 10.0)),
            path_trans_jerk=conv(tbl.get("PATH_TRANS_JERK_LIM", tbl["MAX_AX_JERK"])),
            rotary=rotary))
        settings.append((ax, AxisSettings(
            compress_pos_tol_mm=float(tbl.get("COMPRESS_POS_TOL", 0.01)),
            path_trans_pos_tol_mm=float(tbl.get("PATH_TRANS_POS_TOL", 0.005)),
            eps_tlift_deg=float(tbl.get("EPS_TLIFT_TANG_STEP", 5.0)),
            kv_per_s=float(tbl.get("POSCTRL_GAIN", 1.0)) * 1000.0 / 60.0,
            stop_fine_mm=float(tbl.get("STOP_LIMIT_FINE", 0.01)),
            stop_coarse_mm=float(tbl.get("STOP_LIMIT_COARSE", 0.04)),
            velo_ffw_weight=float(tbl.get("VELO_FFW_WEIGHT", 0.0)),
            soft_accel_factor=float(tbl.get("SOFT_ACCEL_FACTOR", 1.0)),
            g00_accel_factor=float(tbl.get("G00_ACCEL_FACTOR", 1.0)),
            g00_jerk_factor=float(tbl.get("G00_JERK_FACTOR", 1.0)),
            accel_reduction_speed_point=float(tbl.get("ACCEL_REDUCTION_SPEED_POINT", 1.0)),
            accel_reduction_factor=float(tbl.get("ACCEL_REDUCTION_FACTOR", 0.0)),
            accel_type_drive=int(tbl.get("ACCEL_TYPE_DRIVE", 0)))))
    for geo in ("X", "Y", "Z"):
        if geo not in axes_raw:
            raise MachineDataError(f"axis.{geo}", None, "geometry axes X, Y and Z are "
                                   "required", source)
    limits = MachineLimits(axes=tuple(axes), t_ipo_s=t_ipo, name=name)
    tools = tools_from_toml(data["tools"], source) if "tools" in data else EMPTY_TOOLS
    return Machine(name=name, source=source, limits=limits, channel=channel,
                   axis_settings=tuple(settings), tools=tools)


def _decode(data: bytes, source: str) -> str:
    """Machine-data bytes as text: UTF-8 (TOML's encoding, with or without a BOM), or
    UTF-16 with a byte-order mark (what some Windows editors write). Anything else, e.g.
    Latin-1 umlauts in a comment, is rejected naming the file, never guessed."""
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError as exc:
            raise MachineDataError("<file>", source, f"is not valid UTF-16 text despite its "
                                   f"byte-order mark (byte {exc.start})", source) from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise MachineDataError("<file>", source, f"is not UTF-8 text (byte {exc.start}, line "
                               f"{line}): TOML files must be UTF-8; save the file as UTF-8",
                               source) from None


def load_machine(path: str | FsPath | None = None) -> Machine:
    """Load machine data from a TOML file, or a bundled machine by name.

    Parameters
    ----------
    path : str or pathlib.Path or None
        A ``.toml`` file, or the name of a bundled machine (``"default"``,
        ``"linuxcnc_xyz"``); ``None`` gives the default SINUMERIK-like 3-axis mill.

    Returns
    -------
    Machine

    Raises
    ------
    MachineDataError
        The file is missing, is not valid TOML, or breaks a rule.
    """
    if path is None or str(path) in BUNDLED_MACHINES:
        name = DEFAULT_MACHINE if path is None else str(path)
        text = resources.files("reference.machines").joinpath(f"{name}.toml").read_text()
        source = f"<bundled:{name}>"
    else:
        p = FsPath(path)
        if not p.is_file():
            raise MachineDataError("--machine", str(path), "file not found (bundled machines: "
                                   + ", ".join(BUNDLED_MACHINES) + ")")
        source = str(path)
        text = _decode(p.read_bytes(), source)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise MachineDataError("<file>", source, f"is not valid TOML: {exc}", source) from None
    return machine_from_dict(data, source)

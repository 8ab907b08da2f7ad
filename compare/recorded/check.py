"""The check of a recorded trajectory (``feedoracle check``): the last stage.

:func:`recorded_profile` runs the stages before it (read positions aligned to the
path, projection, smoothing when the samples are noisy, reconstruction) and rejects a
recording that does not cover the whole program. :func:`check_recorded` builds the
path, puts back the holds a recording cannot show (those before the first and after
the last motion, as :func:`reference.holds.imposed_holds` gives them, as the oracle
has them), runs the oracle, and judges the profile with
:func:`~reference.core.constraints.check_profile` at the measurement tolerance, the
deviation against ``--max-deviation``, and the comparison with the oracle block by
block. :class:`CheckResult` holds the outcome and writes it as text and JSON.

Inputs
    a CSV file (see :mod:`compare.recorded.reading`), the program and the machine; the
    bound set, the path kind, the noise level and the accepted deviation.
Outputs
    :class:`CheckResult`: the recording, its projection, the noise level, the
    reconstruction details and the :class:`~compare.comparison.Comparison` of the
    recorded profile (``reference_name == "recorded"``) against the oracle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path as FsPath
from typing import Callable, TextIO

import numpy as np

from reference.core.constraints import BOUND_SETS
from reference.core.rules import STEPS_SPREAD
from reference.core.errors import TrajectoryError
from reference.core.geometry import Path
from reference.core.holds import with_holds
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.holds import imposed_holds
from reference.machine import Machine
from reference.nc.program import Program
from reference.prepare import build_path, prepare, restrict_to_machine

from .. import engines
from ..comparison import (Comparison, Side, block_span, compare_profiles, oracle_result,
                          programmed_contour)
from ..export import comparison_dict
from ..text import print_comparison
from .projection import Projection, project
from .reading import Recording, align_axes, read_trajectory
from .reconstruction import measurement_tolerance, reconstruct
from .smoothing import estimate_noise, smooth

#: Default largest accepted deviation from the path, mm (also >= 5x the noise level).
DEFAULT_MAX_DEVIATION_MM = 0.1

#: Smooth only when the noise would move second-difference accelerations by more than
#: this fraction of the smallest axis acceleration limit (below it, smoothing changes
#: nothing that matters and exact data stay exact).
ACCEL_NOISE_REL = 0.005


@dataclass(frozen=True, slots=True)
class CheckResult:
    """Outcome of ``feedoracle check``.

    Attributes
    ----------
    recording : Recording
        The samples as read.
    projection : Projection
        Their projection onto the path.
    noise_mm : float
        Noise level used for smoothing, mm (0: none).
    max_deviation_mm : float
        The deviation accepted (the gate of the deviation check), mm.
    info : dict
        Reconstruction details (see :func:`reconstruct`).
    comparison : Comparison
        The recorded profile against the oracle (``reference_name == "recorded"``).
    path_kind : str
        ``"reference"`` (the heuristic's path with its rounding) or ``"programmed"``.
    """

    recording: Recording
    projection: Projection
    noise_mm: float
    max_deviation_mm: float
    info: dict
    comparison: Comparison
    path_kind: str = "reference"

    @property
    def deviation_ok(self) -> bool:
        """True when no sample is farther from the path than the accepted deviation."""
        return float(np.max(self.projection.deviation)) <= self.max_deviation_mm

    @property
    def ok(self) -> bool:
        """True when the deviation and every declared limit hold and bounds exist."""
        return self.deviation_ok and self.comparison.verdict(None).ok

    def _where(self, i: int) -> str:
        rec, c = self.recording, self.comparison
        s = float(self.projection.s[i])
        blk = int(c.path.block_of(min(s, c.path.total_length))[0]) if c.path.n_segments else -1
        span = block_span(c.path, blk)
        line = f", line {span.line}{(' ' + span.label) if span and span.label else ''}" \
            if span else ""
        return f"row {rec.rows[i]} (t = {rec.t[i]:.4f} s, s = {s:.3f} mm{line})"

    def deviation_text(self) -> str:
        """Largest deviation and where."""
        i = self.projection.worst
        return f"{float(self.projection.deviation[i]):.4g} mm at {self._where(i)}"

    def print(self, out: TextIO) -> None:
        """Text summary (deviation, limits, gap, stops, worst blocks)."""
        rec = self.recording
        out.write(f"{rec.file}: {rec.t.size} samples over {rec.t[-1] - rec.t[0]:.4f} s, "
                  f"projected onto the {self.path_kind} path of {self.comparison.program}\n")
        dev_state = "ok" if self.deviation_ok else "FAIL"
        out.write(f"  deviation  {dev_state}: largest {self.deviation_text()} "
                  f"(accepted {self.max_deviation_mm:.4g} mm)\n")
        smooth_txt = f"smoothed for noise {self.noise_mm:.3g} mm" if self.noise_mm > 0 \
            else "no smoothing (noise below the accuracy that matters)"
        out.write(f"  samples    {smooth_txt}; motion from t = {self.info['t_offset_s']:.4f} s "
                  f"in the recording\n")
        for k, sb, v in self.info["unsnapped_stops"]:
            reason = self.comparison.path.stop_reason[k]
            out.write(f"  stop       the recording does not stop at s = {sb:.3f} mm "
                      f"({reason}): it passes at about {v:.3g} mm/s\n")
        print_comparison(self.comparison, None, out)

    def to_dict(self) -> dict:
        """JSON result: the comparison contract plus a ``recorded`` part."""
        d = comparison_dict(self.comparison)
        i = self.projection.worst
        d["recorded"] = {
            "file": self.recording.file, "samples": int(self.recording.t.size),
            "path": self.path_kind, "noise_mm": self.noise_mm,
            "max_deviation_mm": float(self.projection.deviation[i]),
            "max_deviation_at": {"row": int(self.recording.rows[i]),
                                 "t": float(self.recording.t[i]),
                                 "s": float(self.projection.s[i])},
            "accepted_deviation_mm": self.max_deviation_mm,
            "deviation_ok": self.deviation_ok,
            "t_offset_s": self.info["t_offset_s"],
            "unsnapped_stops": [{"s": sb, "reason": self.comparison.path.stop_reason[k],
                                 "speed": v} for k, sb, v in self.info["unsnapped_stops"]]}
        d["verdict"]["ok"] = self.ok
        if not self.deviation_ok and d["verdict"]["status"] == "ok":
            d["verdict"]["status"] = "leaves the path"
            d["verdict"]["text"] = f"the trajectory leaves the path: {self.deviation_text()}"
        return d


def recorded_profile(path: Path, limits: MachineLimits, rec: Recording,
                     smoothing: float | str = "auto"
                     ) -> tuple[Profile, Projection, float, dict]:
    """Project, smooth and reconstruct a recording on ``path``.

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    rec : Recording
    smoothing : float or "auto"
        Noise level in mm (0 = none) or ``"auto"`` (estimated).

    Returns
    -------
    profile, projection, noise_mm, info
        See :func:`reconstruct` for ``info``.

    Raises
    ------
    TrajectoryError
        The recording does not start at the path start or does not reach its end.
    """
    q = align_axes(rec, path)
    proj = project(path, q, rec.t)
    L = path.total_length
    h = float(np.median(np.diff(rec.t)))
    if smoothing == "auto":
        sigma = estimate_noise(proj.s, rec.t)
        a_min = float(np.min(limits.for_axes(path.axes).a_max))
        if math.sqrt(6.0) * sigma / h ** 2 <= ACCEL_NOISE_REL * a_min:
            sigma = 0.0
    else:
        sigma = float(smoothing)
    s = smooth(rec.t, proj.s, sigma) if sigma > 0 else proj.s
    s = np.clip(np.maximum.accumulate(s), 0.0, L)
    tol = max(DEFAULT_MAX_DEVIATION_MM, 5 * sigma)
    start_gap = float(np.linalg.norm(q[0] - path.evaluate(0.0)[0][0])) if path.n_segments else 0.0
    if s[0] > tol or start_gap > 10 * tol + 1.0:
        raise TrajectoryError(f"{rec.file}:{rec.rows[0]}: the recording starts "
                              f"{max(s[0], start_gap):.4g} mm from the start of the path "
                              f"(it must cover the whole program)")
    if L - s[-1] > tol:
        i = int(np.argmax(s))
        raise TrajectoryError(f"{rec.file}:{rec.rows[-1]}: the recording ends {L - s[-1]:.4g} mm "
                              f"before the end of the path (s = {s[i]:.3f} of {L:.3f} mm)")
    s = s.copy()
    s[0] = 0.0 if s[0] <= tol else s[0]
    s[-1] = L
    s = np.clip(np.maximum.accumulate(s), 0.0, L)
    prof, info = reconstruct(path, limits, rec.t, s)
    return prof, proj, sigma, info


def check_recorded(file: str | FsPath, program: Program, machine: Machine, *,
                   bounds: str | None = None, path_kind: str = "reference",
                   smoothing: float | str = "auto",
                   max_deviation: float | None = None,
                   progress: Callable[[str, float], None] | None = None) -> CheckResult:
    """Read, project, check and compare a recorded trajectory (``feedoracle check``).

    Parameters
    ----------
    file : path
        CSV file (see :mod:`compare.recorded.reading`).
    program : reference.nc.Program
        The program the recording ran.
    machine : reference.machine.Machine
        Machine data (limits).
    bounds : str, optional
        Bound set the recording is judged against (default ``"acc"``).
    path_kind : {"reference", "programmed"}
        Project onto the heuristic's path (with its rounding) or the programmed contour.
    smoothing : float or "auto"
        Noise level in mm, 0 for none, ``"auto"`` to estimate.
    max_deviation : float, optional
        Largest accepted distance from the path, mm (default ``max(0.1, 5 * noise)``).
    progress : callable, optional
        ``progress(message, fraction)``.

    Returns
    -------
    CheckResult
    """
    limits = machine.limits
    if path_kind == "reference":
        path = build_path(program, machine)
    else:
        path = restrict_to_machine(prepare(program), limits)
    holds = imposed_holds(program, path, machine)
    rec = read_trajectory(file, path.axes, tuple(bool(r) for r in path.rotary))
    if progress is not None:
        progress("projecting the recording", -1.0)
    prof, proj, sigma, info = recorded_profile(path, limits, rec, smoothing)
    # rest before the first and after the last motion is trimmed from the recording, so
    # the holds the program imposes there (a dwell before any motion, the settle of the
    # last block, dwells at the end) cannot be measured: they are put back as imposed
    at_ends = (holds.break_index == 0) | (holds.break_index == path.n_segments)
    prof = with_holds(prof, path, holds.subset(at_ends))
    bound_set = bounds or "acc"
    sol = engines.run_oracle(path, limits, "acc",
                             progress=engines.prefixed(progress, "oracle: "),
                             holds=holds)
    i = proj.worst
    tol = measurement_tolerance(path, limits, rec.t, sigma, info["scale"])
    notes = [f"Recorded trajectory {rec.file} ({rec.t.size} samples): judged on the "
             f"{bound_set!r} bound set ({', '.join(BOUND_SETS[bound_set])}) with a "
             f"measurement tolerance of {100 * tol:.3g} %; largest distance "
             f"from the {path_kind} path {float(proj.deviation[i]):.4g} mm at row "
             f"{rec.rows[i]} (t = {rec.t[i]:.4f} s)."]
    if sigma > 0:
        notes.append(f"Positions were smoothed for a noise level of {sigma:.3g} mm.")
    if info["scale"] > 5e-3:
        notes.append(f"Positions between stops and corners were rescaled by up to "
                     f"{100 * info['scale']:.2f} % to put each of them in place; the "
                     f"recording may not follow this path closely.")
    c = compare_profiles(path, limits, Side("recorded", prof, bound_set,
                                            ratio_tol=tol, steps=STEPS_SPREAD),
                         oracle_result(sol), program=program.file, machine=machine.name,
                         program_lines=tuple(program.lines), notes=notes,
                         programmed=programmed_contour(program, limits))
    max_dev = max_deviation if max_deviation is not None else max(
        DEFAULT_MAX_DEVIATION_MM, 5 * sigma)
    return CheckResult(recording=rec, projection=proj, noise_mm=sigma,
                       max_deviation_mm=max_dev, info=info, comparison=c,
                       path_kind=path_kind)

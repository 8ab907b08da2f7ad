"""Corpus programs converted to SINUMERIK syntax at test time.

``../shared/corpus/SOURCES.md`` asks that its programs are used from there and not copied
into this repository (the ``lcnc_*`` files are GPL-2.0 data). Tests and benchmarks that
need a LinuxCNC program in the other dialect convert it here, from the corpus file, on
every run; where the corpus is absent the calling test skips, naming the file
(:func:`shared_inputs.corpus_file`).
"""

from __future__ import annotations

import re

from shared_inputs import corpus_file


def short_segments_g642() -> str:
    """``lcnc_short_segments_0.001.ngc`` (3000 collinear 0.001 in blocks along X, Y, Z at
    F999 in/min) as a SINUMERIK program under G642.

    Changes: ``G20`` -> ``G700`` (inch lengths and inch/min feeds, as G20), ``G64`` ->
    ``G642`` (rounding with tolerances), ``( )`` comments -> ``;`` comments, tabs ->
    spaces, axis words upper case, ``M2`` kept. The motion is unchanged.

    Raises
    ------
    pytest.skip.Exception
        The corpus file is not beside the project (the calling test skips, saying so;
        a benchmark checks :data:`shared_inputs.CORPUS_PRESENT` first).
    """
    src = corpus_file("lcnc_short_segments_0.001.ngc").read_text()
    out = []
    for line in src.splitlines():
        line = line.replace("\t", " ").strip()
        m = re.fullmatch(r"\((.*)\)", line)
        if m:
            out.append(f"; {m.group(1)}")
            continue
        line = re.sub(r"\bG20\b", "G700", line)
        line = re.sub(r"\bG64\b", "G642", line)
        line = re.sub(r"([xyz])(?=[-\d.])", lambda k: k.group(1).upper(), line)
        line = re.sub(r"([A-Z]) +(?=[-\d.])", r"\1", line)
        out.append(line)
    return "\n".join(out) + "\n"


def corpus_in_mode(name: str, mode: str) -> str:
    """Corpus program ``name`` as a SINUMERIK program whose continuous-path mode is
    ``mode`` (e.g. ``"G642"``, ``"G641 ADIS=0.2"``, ``"G64"``).

    LinuxCNC programs (``.ngc``): ``G20``/``G21`` -> ``G700``/``G710``, every ``G64``
    (with its ``P``/``Q`` blending tolerances) and ``G61`` -> ``mode``, arc radius ``R``
    -> ``CR=``, ``( )`` comments -> ``;`` comments, tabs -> spaces, axis words upper
    case; the motion is unchanged. SINUMERIK programs (``.mpf``): ``mode`` in a first
    line of its own, before the program's own words (a ``G64`` in the program is
    replaced as well).

    Raises
    ------
    pytest.skip.Exception
        The corpus file is not beside the project (the calling test skips, saying so;
        a benchmark checks :data:`shared_inputs.CORPUS_PRESENT` first).
    """
    src = corpus_file(name).read_text()
    if name.endswith(".mpf"):
        return f"{mode}\n" + re.sub(r"\bG64\b", mode, src)
    out = []
    for line in src.splitlines():
        line = line.replace("\t", " ").strip()
        line = re.sub(r"\(([^)]*)\)", lambda k: f"; {k.group(1)}" if k.start() else
                      f"; {k.group(1)}", line)
        code, sep, comment = line.partition(";")
        code = re.sub(r"\bG20\b", "G700", code)
        code = re.sub(r"\bG21\b", "G710", code)
        code = re.sub(r"\bG6[14]\b\s*(P\s*[-\d.]+)?\s*(Q\s*[-\d.]+)?", f" {mode} ", code)
        code = re.sub(r"([xyzijkrf])(?=\s*[-\d.])", lambda k: k.group(1).upper(), code)
        code = re.sub(r"([A-Z]) +(?=[-\d.])", r"\1", code)
        code = re.sub(r"\bR(?=[-\d.])", "CR=", code)
        out.append((code.strip() + (" " if code.strip() and sep else "") + sep + comment)
                   .strip())
    return "\n".join(out) + "\n"

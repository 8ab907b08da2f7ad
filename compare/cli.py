"""The ``feedoracle`` command line (DESIGN section 7).

Exit codes: 0 all good; 1 a gap above ``--max-gap`` or a limit violation; 2 bad input
(one message on stderr naming file and line, never a traceback).
"""

from __future__ import annotations

import argparse
import sys
import traceback
from typing import Sequence

import numpy as np

from reference.core.budget import DEFAULT_MAX_GRID_POINTS
from reference.core.errors import FeedOracleError
from reference.core.geometry import KIND_CODES
from reference.prepare import path_stages, prepare

from .commands import number_at_least
from .pipeline import load_inputs
from .progress import Progress

EXIT_OK, EXIT_FAIL, EXIT_BAD_INPUT, EXIT_INTERNAL = 0, 1, 2, 3


class _Parser(argparse.ArgumentParser):
    """argparse that exits with code 2 and a one-line message on usage errors."""

    def error(self, message: str) -> None:  # noqa: D102 - argparse API
        self.print_usage(sys.stderr)
        print(f"feedoracle: error: {message}", file=sys.stderr)
        raise SystemExit(EXIT_BAD_INPUT)


def _fmt(x: float, nd: int = 3) -> str:
    return "inf" if x == float("inf") else f"{x:.{nd}f}"


def cmd_inspect(args: argparse.Namespace) -> int:
    """``feedoracle inspect``: print blocks, their segments and any warnings."""
    inputs = load_inputs(args.program, args.machine, dialect=args.dialect,
                         tool_table=args.tool_table, tool_table_units=args.tool_table_units)
    program, machine = inputs.program, inputs.machine
    path = prepare(program)       # the programmed contour, whatever axes the machine has
    out = sys.stdout
    out.write(f"program {program.file} ({program.dialect}, {len(program.blocks)} blocks, "
              f"{path.n_segments} segments, {path.total_length:.3f} mm); machine "
              f"{machine.name}\n")
    out.write(f"{'line':>6} {'label':<8} {'kind':<5} {'segs':>4} {'length_mm':>11} "
              f"{'feed_mm_min':>11} {'mode':<5} {'stop':<30} source\n")
    for span in path.blocks:
        blk = program.blocks[span.block]
        feed = span.feed_mm_s * 60.0 if span.n_segments else float("nan")
        feed_s = "rapid" if blk.motion == "G0" else ("-" if feed != feed else _fmt(feed, 1))
        stop = span.stop_reason or ""
        src = blk.source.strip()
        if len(src) > 60:
            src = src[:57] + "..."
        out.write(f"{blk.line:>6} {span.label[:8]:<8} {span.kind:<5} {span.n_segments:>4} "
                  f"{span.length:>11.4f} {feed_s:>11} {blk.continuous_mode:<5} "
                  f"{stop[:30]:<30} {src}\n")
    try:
        stages = path_stages(program, machine)
    except FeedOracleError as exc:    # e.g. an axis without machine data: listed above
        out.write(f"path stages: not evaluated ({exc})\n")
        stages = None
    if stages is not None:
        final = stages.path
        if stages.trc.blocks or stages.tangential.corners:
            out.write(f"path both planners run on: {final.n_segments} segments, "
                      f"{final.total_length:.3f} mm (after tool radius compensation, "
                      "tangential control and rounding)\n")
        _write_trc(out, program, stages)
        _write_tangential(out, program, stages)
        _write_rounding(out, program, stages.path.rounding)
        _write_changed_segments(out, program, stages)
    for w in inputs.warnings:
        print(str(w), file=sys.stderr)
    if path.n_segments == 0:
        # a listing of nothing is a valid answer here; plan, optimize and compare reject it
        print(f"{program.file}: note: the program has no motion (no block moves an axis)",
              file=sys.stderr)
    return EXIT_OK


def _write_trc(out, program, stages) -> None:
    """Tool radius compensation: the role, side and radius of each compensated block, and
    what was done at each corner (transition circle, intersection, DISC, ...)."""
    trc = stages.trc
    if not trc.blocks:
        return
    lines = {b.index: b.line for b in program.blocks}
    out.write(f"tool radius compensation: {len(trc.blocks)} blocks, {len(trc.corners)} "
              "corners\n")
    out.write(f"{'line':>6} {'role':<9} {'side':<4} {'radius_mm':>9}\n")
    for b in trc.blocks:
        out.write(f"{lines[b.block]:>6} {b.role:<9} {b.side:<4} {b.radius_mm:>9.4f}\n")
    if trc.corners:
        out.write(f"{'corner':>13} {'side':<10} {'angle_deg':>9} {'inserted_mm':>11} "
                  "action\n")
        for c in trc.corners:
            corner = f"{lines[c.block]}/{lines[c.next_block]}"
            out.write(f"{corner:>13} {c.side:<10} {c.deflection_deg:>9.3f} "
                      f"{c.inserted_mm:>11.4f} {c.action}\n")


def _write_tangential(out, program, stages) -> None:
    """Tangential control: where the following axis turns, by how much and how."""
    corners = stages.tangential.corners
    if not corners:
        return
    lines = {b.index: b.line for b in program.blocks}
    n = len(corners)
    out.write(f"tangential control: {n} tangent step{'' if n == 1 else 's'}\n")
    out.write(f"{'line':>6} {'axis':<4} {'step_deg':>9} action\n")
    for c in corners:
        out.write(f"{lines[c.block]:>6} {c.axis:<4} {c.step_deg:>9.3f} {c.action}\n")


def _write_changed_segments(out, program, stages) -> None:
    """The segments of the blocks that compensation or tangential control changed, as
    both planners run on them: kind (``trc``/``tlift`` for inserted ones), ends, radius."""
    path = stages.path
    touched = {b.block for b in stages.trc.blocks} | {
        b.index for b in program.blocks if b.tangential is not None}
    if not touched:
        return
    rows = [i for i in range(path.n_segments) if int(path.block[i]) in touched]
    if not rows:
        return
    out.write(f"path segments of those blocks ({len(rows)}; axes {' '.join(path.axes)}):\n")
    out.write(f"{'line':>6} {'kind':<8} {'length_mm':>10} {'radius':>9}  start -> end\n")
    q0 = path.evaluate(path.s_breaks[rows], segment=rows)[0]
    q1 = path.evaluate(path.s_breaks[[i + 1 for i in rows]], segment=rows)[0]
    for k, i in enumerate(rows):
        blk = program.blocks[int(path.block[i])]
        a = " ".join(f"{x:.4f}" for x in q0[k])
        b = " ".join(f"{x:.4f}" for x in q1[k])
        out.write(f"{blk.line:>6} {KIND_CODES[int(path.kind[i])]:<8} {path.length[i]:>10.4f} "
                  f"{path.radius[i]:>9.4f}  {a} -> {b}\n")


def _write_rounding(out, program, table) -> None:
    """The rounding stage's decision per corner in G641..G645: the rounding's tangent
    distance, length, contour deviation and radius, or why no rounding was inserted."""
    if table is None or table.n == 0:
        return
    lines = {b.index: b.line for b in program.blocks}
    out.write(f"rounding: {int(table.inserted.sum())} of {table.n} corners in G641..G645 "
              "rounded (shape: arc = tangent arc, G2 = clothoid pair, curvature continuous; "
              "G2 transition = G645 at a tangential line-arc transition or between two "
              "tangent arcs, d = length of the line replaced (two arcs: the longer of "
              "the arcs' parts); "
              "radius_mm = smallest radius); d = distance of the rounding's ends from the corner, "
              "dev = largest distance of the rounded path from the corner, F_G64 / F_round "
              "= speed through the corner under G64 / through the rounding (model "
              "estimate, mm/min) that decided it\n")
    out.write(f"{'corner':>13} {'mode':<5} {'d_mm':>9} {'length_mm':>10} {'dev_mm':>9} "
              f"{'radius_mm':>10} {'F_G64':>9} {'F_round':>9} result\n")
    for i in range(table.n):
        corner = f"{lines[int(table.block[i])]}/{lines[int(table.next_block[i])]}"
        if table.inserted[i]:
            what = "rounded (" + ("G2 transition" if table.tangential[i] else
                                  "G2" if table.g2[i] else "arc") + ")"
            if table.internal[i]:
                what += " inside the blocks (G643: no block of its own)"
            if table.blocks_spanned[i] > 2:
                what += (f" across lines {lines[int(table.first_block[i])]}.."
                         f"{lines[int(table.last_block[i])]} (short blocks)")
            if table.clamped[i]:
                what += " (clamped to half the block" + (
                    "s" if table.blocks_spanned[i] > 2 else "") + ")"
        else:
            what = "none: " + table.reason_text(i)
        f64, frd = (60.0 * table.v_g64[i], 60.0 * table.v_round[i])
        out.write(f"{corner:>13} {table.mode[i]:<5} {table.distance_mm[i]:>9.4f} "
                  f"{table.length_mm[i]:>10.4f} {table.deviation_mm[i]:>9.5f} "
                  f"{table.radius_mm[i]:>10.4f} {_num(f64):>9} {_num(frd):>9} {what}\n")


def _num(x: float) -> str:
    """A speed for the rounding table: ``-`` where it was not evaluated."""
    return "-" if not np.isfinite(x) else f"{x:.1f}"


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of all sub-commands."""
    p = _Parser(prog="feedoracle", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    def common(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("--machine", metavar="M.toml", default=None,
                        help="machine data (default: the bundled 3-axis mill; "
                             "'linuxcnc_xyz' names the bundled LinuxCNC test machine)")
        sp.add_argument("--dialect", choices=("sinumerik", "ngc"), default=None,
                        help="NC dialect (default: from the file extension)")
        sp.add_argument("--quiet", action="store_true", help="no progress output")
        sp.add_argument("--debug", action="store_true",
                        help="on an internal error (exit 3), print the traceback")
        sp.add_argument("--tool-table", metavar="FILE", default=None,
                        help="LinuxCNC tool table (T<n> P<n> D<diameter> lines) for cutter "
                             "compensation; overrides [tools] of the machine data")
        sp.add_argument("--tool-table-units", choices=("mm", "inch"), default="mm",
                        help="units of the tool table (LinuxCNC keeps it in machine units; "
                             "default mm)")
        sp.add_argument("--max-grid-points", metavar="N",
                        type=number_at_least(1.0, "a number of points >= 1"),
                        default=DEFAULT_MAX_GRID_POINTS,
                        help="size budget: most points sampled along the path (arc and "
                             "helix samples, IPO rows of a CSV); a program needing more "
                             f"is rejected up front (default {DEFAULT_MAX_GRID_POINTS:.0e})")

    sp = sub.add_parser("inspect", help="blocks -> path segments table")
    sp.add_argument("program")
    common(sp)
    sp.set_defaults(func=cmd_inspect)

    from . import commands  # plan, optimize, compare, check live beside the report code
    commands.register(sub, common)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    progress = Progress(quiet=args.quiet)
    args.progress = progress
    try:
        return int(args.func(args))
    except FeedOracleError as exc:
        progress.done()
        print(f"feedoracle: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except BrokenPipeError:
        # output piped into a pager or head that closed early: not an error of ours
        sys.stderr.close()
        return EXIT_OK
    except OSError as exc:
        progress.done()
        name = exc.filename if exc.filename is not None else ""
        print(f"feedoracle: {name}: {exc.strerror or exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        progress.done()
        print("feedoracle: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:          # noqa: BLE001 - the last line of defence, exit 3
        # anything else is a bug of feedoracle, never bad input and never a gap: one
        # line saying so (the traceback with --debug), and an exit code of its own
        progress.done()
        print(f"feedoracle: internal error (a bug in feedoracle, please report it): "
              f"{type(exc).__name__}: {exc}"
              + ("" if args.debug else "; run with --debug for the "
                 "traceback"), file=sys.stderr)
        if args.debug:
            traceback.print_exc(file=sys.stderr)
        return EXIT_INTERNAL
    finally:
        progress.done()


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())

"""Sub-commands plan, optimize, compare and check (registered by :mod:`compare.cli`).

Exit codes (DESIGN section 7): 0 all good; 1 a gap above ``--max-gap``, a limit
violation, or an oracle without certified bounds (nothing certifies the program then);
2 bad input (one message on stderr naming file and line, never a traceback).

``--max-gap`` takes percent: ``15%`` and ``15`` both mean 15 %; ``0.5`` means 0.5 %
(not 50 %). The gate compares the *upper* end of the gap interval,
``(t_ref - H)/(LB - H) - 1`` (``H``: the imposed holds, dwell and exact-stop settle, in
both totals and in no gap), with it, so a program passes only when its gap is certified
to be within the gate.
"""

from __future__ import annotations

import argparse
import gc
import math
import sys
from pathlib import Path as FsPath
from typing import Callable, Sequence

from reference.core.constraints import BOUND_SETS
from reference.core.errors import FeedOracleError

from . import engines, pipeline
from .comparison import Comparison
from .export import (comparison_dict, blocks_csv, profile_samples, write_json,
                     write_samples_csv)
from .text import num, print_comparison, print_summary, rows_table

EXIT_OK, EXIT_FAIL, EXIT_BAD_INPUT = 0, 1, 2


class UsageError(FeedOracleError, ValueError):
    """A command-line value that does not parse (exit 2)."""


def parse_max_gap(text: str) -> float:
    """``--max-gap`` as a fraction: ``"15%"`` and ``"15"`` -> 0.15, ``"0.5"`` -> 0.005.

    Raises
    ------
    argparse.ArgumentTypeError
        Not a finite number >= 0.
    """
    raw = text.strip()
    body = raw[:-1].strip() if raw.endswith("%") else raw
    try:
        pct = float(body)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"--max-gap {text!r}: expected percent, e.g. 15% or 15") from None
    if not (math.isfinite(pct) and pct >= 0):
        raise argparse.ArgumentTypeError(f"--max-gap {text!r}: must be a percentage >= 0")
    return pct / 100.0


def number_at_least(minimum: float, what: str) -> Callable[[str], float]:
    """An argparse ``type``: a finite number ``>= minimum`` (``1e9`` allowed), else an
    error naming ``what`` was expected."""
    def parse(text: str) -> float:
        try:
            x = float(text)
        except ValueError:
            x = math.nan
        if not (math.isfinite(x) and x >= minimum):
            raise argparse.ArgumentTypeError(f"{text!r}: expected {what}")
        return x
    return parse


#: ``--max-deviation``.
_mm = number_at_least(0.0, "a length >= 0 in mm")


# --------------------------------------------------------------------- registration
def register(sub: argparse._SubParsersAction, common: Callable) -> None:
    """Add plan, optimize, compare and check to the CLI parser."""
    sp = sub.add_parser("plan", help="heuristic only: per-block times, speeds and causes")
    sp.add_argument("program")
    sp.add_argument("--json", metavar="F", help="write the 'reference' part as JSON ('-' = stdout)")
    sp.add_argument("--csv", metavar="F",
                    help="write the motion sampled at the IPO cycle: t, s, v and every axis")
    common(sp)
    sp.set_defaults(func=cmd_plan)

    sp = sub.add_parser("optimize", help="oracle only: certified bounds on the optimal time")
    sp.add_argument("program")
    sp.add_argument("--bounds", choices=engines.BOUND_CHOICES[1:], default="acc",
                    help="constraint set of the oracle (default acc)")
    sp.add_argument("--json", metavar="F", help="write the 'oracle' part and block rows as JSON")
    sp.add_argument("--csv", metavar="F",
                    help="write the verified optimal motion sampled at the IPO cycle")
    common(sp)
    sp.set_defaults(func=cmd_optimize)

    sp = sub.add_parser(
        "compare", help="heuristic vs oracle, block by block; reports and a CI gate",
        description="Compare the heuristic with the time-optimal motion, block by block. "
                    "Exit 0 good, 1 gap above --max-gap or a limit violation, 2 bad input.")
    sp.add_argument("programs", nargs="+", metavar="PROGRAM")
    sp.add_argument("--bounds", choices=engines.BOUND_CHOICES, default="auto",
                    help="oracle constraint set; auto = the heuristic's own where the "
                         "oracle can solve it, else acc (with a note)")
    sp.add_argument("--report", metavar="DIR", default="reports",
                    help="write HTML, JSON and CSV per program here (default: reports)")
    sp.add_argument("--no-report", action="store_true", help="write no report files")
    sp.add_argument("--json", metavar="F",
                    help="write the result as JSON (several programs: a JSON array)")
    sp.add_argument("--max-gap", metavar="PCT", type=parse_max_gap, default=None,
                    help="fail (exit 1) when the gap may exceed PCT percent: '15%%' or "
                         "'15' mean 15 %%, '0.5' means 0.5 %%; compared with the upper "
                         "end (t_ref-H)/(LB-H) - 1 of the certified gap interval (H: "
                         "dwell and exact-stop settle, not counted)")
    common(sp)
    sp.set_defaults(func=cmd_compare)

    sp = sub.add_parser(
        "check", help="a recorded trajectory (CSV t,X,Y,Z...) against limits and oracle",
        description="Read a trajectory recorded from any controller or simulator (CSV "
                    "with header t,X,Y,Z[,A,...] in s and mm/degrees), project it onto "
                    "the program's path, check it against the machine limits and compare "
                    "it block by block with the oracle.")
    sp.add_argument("trajectory", metavar="TRAJECTORY.csv")
    sp.add_argument("--program", required=True, metavar="P", help="the NC program it ran")
    sp.add_argument("--bounds", choices=tuple(BOUND_SETS), default=None,
                    help="constraints the trajectory must keep (default acc: velocity, "
                         "acceleration, feed, corner jumps, stops; jerk from samples is "
                         "shown for information unless --bounds jerk)")
    sp.add_argument("--path", choices=("reference", "programmed"), default="reference",
                    dest="path_kind",
                    help="project onto the heuristic's path (with its corner rounding, "
                         "default) or onto the programmed contour")
    sp.add_argument("--max-deviation", metavar="MM", type=_mm, default=None,
                    help="fail (exit 1) when the trajectory is farther than MM from the "
                         "path (default: 0.1 mm, or 5 x the noise level)")
    sp.add_argument("--smoothing", metavar="MM", default="auto",
                    help="position noise to smooth away, mm: 'auto' (estimated from the "
                         "samples), 0 (interpolate exactly) or a value")
    sp.add_argument("--report", metavar="DIR", default=None,
                    help="also write an HTML/JSON/CSV report into DIR")
    sp.add_argument("--json", metavar="F", help="write the result as JSON")
    common(sp)
    sp.set_defaults(func=cmd_check)


# --------------------------------------------------------------------- helpers
def _load(program_file: str, args: argparse.Namespace) -> pipeline.Inputs:
    """Program and machine of the command line; their warnings go to stderr."""
    inputs = pipeline.load_inputs(program_file, args.machine, dialect=args.dialect,
                                  tool_table=args.tool_table,
                                  tool_table_units=args.tool_table_units)
    for w in inputs.warnings:
        print(str(w), file=sys.stderr)
    return inputs


# --------------------------------------------------------------------- plan
def cmd_plan(args: argparse.Namespace) -> int:
    """``feedoracle plan``: run the heuristic, print its block table."""
    # Parsing, the path and the plan build some objects per block and no reference
    # cycles; with 10^6 blocks the cyclic collector re-scans them again and again (the
    # planner alone: 44 s -> 24 s without it, measured on a busy machine). Paused for
    # the command, restored after.
    collecting = gc.isenabled()
    gc.disable()
    try:
        return _plan(args)
    finally:
        if collecting:
            gc.enable()


def _plan(args: argparse.Namespace) -> int:
    from reference.planner import ipo_samples, to_json_dict
    from reference.planner.export import iter_json_rows
    inputs = _load(args.program, args)
    program, machine = inputs.program, inputs.machine
    plan = pipeline.plan_program(program, machine, progress=args.progress,
                                 max_grid_points=args.max_grid_points)
    args.progress.done()
    if args.csv:
        pipeline.require_ipo_budget(plan.profile.duration, plan.limits.t_ipo_s, "--csv",
                                    args.max_grid_points)
    if args.json:
        doc = to_json_dict(plan)
        write_json(doc, args.json)
        rows = doc["blocks"]
    else:
        rows = iter_json_rows(plan)
    if args.csv:
        header, data = ipo_samples(plan)
        write_samples_csv(header, data, args.csv)
    out = sys.stdout if args.json != "-" and args.csv != "-" else sys.stderr
    viol = plan.report.violations(BOUND_SETS[plan.bound_set]) if plan.report else ()
    out.write(f"{program.file}: machine {machine.name!r}, heuristic bounds {plan.bound_set}, "
              f"time {plan.profile.duration:.4f} s, "
              f"{'no violations' if not viol else str(len(viol)) + ' violation(s)'}\n")
    for v in viol:
        out.write(f"  VIOLATION {v.constraint} {v.axis or ''} ratio {v.ratio:.4g} at "
                  f"s = {v.s:.3f} mm, t = {v.t:.4f} s\n")
    rows_table(rows, out, "t_reference_s", "v_exit_reference", "limit_reference")
    return EXIT_FAIL if viol else EXIT_OK


# --------------------------------------------------------------------- optimize
def cmd_optimize(args: argparse.Namespace) -> int:
    """``feedoracle optimize``: the oracle on the program's path."""
    bounds, _ = engines.resolve_bounds(args.bounds, None)    # an unavailable set: exit 2 now
    inputs = _load(args.program, args)
    res = pipeline.optimize_program(inputs.program, inputs.machine, bounds=bounds,
                                    progress=args.progress,
                                    max_grid_points=args.max_grid_points)
    args.progress.done()
    o = res.oracle_dict()
    rows = res.rows()
    if args.json:
        write_json(res.to_dict(), args.json)
    if args.csv and res.solution.profile is not None:
        pipeline.require_ipo_budget(res.solution.profile.duration, res.limits.t_ipo_s,
                                    "--csv", args.max_grid_points)
        header, data = profile_samples(res.path, res.solution.profile, res.limits.t_ipo_s)
        write_samples_csv(header, data, args.csv)
    out = sys.stdout if args.json != "-" and args.csv != "-" else sys.stderr
    out.write(f"{res.program}: machine {res.machine!r}, bounds {res.bounds}: status "
              f"{o.get('status')}, LB {num(o.get('lower_bound_s') or math.nan, 4)} s, UB "
              f"{num(o.get('upper_bound_s') or math.nan, 4)} s ({o.get('grid_points', 0)} "
              f"grid points, {o.get('solve_time_s', 0.0):.2f} s)\n")
    rows_table(rows, out, "t_oracle_s", "v_exit_oracle", "limit_oracle")
    return EXIT_OK if res.certified else EXIT_FAIL


# --------------------------------------------------------------------- compare
def _report_stems(files: Sequence[str]) -> list[str]:
    """Unique file stems for report names (``dir_name`` when two stems collide)."""
    stems = [FsPath(f).stem for f in files]
    out = []
    for f, st in zip(files, stems):
        if stems.count(st) > 1:
            parent = FsPath(f).resolve().parent.name or "root"
            st = f"{parent}_{st}"
        base, k = st, 2
        while st in out:
            st, k = f"{base}_{k}", k + 1
        out.append(st)
    return out


def cmd_compare(args: argparse.Namespace) -> int:
    """``feedoracle compare``: heuristic vs oracle per program; reports; the CI gate."""
    files = list(args.programs)
    for f in files:
        if not FsPath(f).is_file():
            raise UsageError(f"{f}: no such program file")
    if args.bounds != "auto":
        engines.resolve_bounds(args.bounds, None)       # an unavailable set: exit 2 now
    stems = _report_stems(files)
    out = sys.stdout if args.json != "-" else sys.stderr
    results: list[tuple[str, Comparison]] = []
    docs = []
    report_dir = None if args.no_report else FsPath(args.report)
    n = len(files)
    for i, (f, stem) in enumerate(zip(files, stems)):
        prefix = f"[{i + 1}/{n}] {f}: " if n > 1 else f"{f}: "
        inputs = _load(f, args)
        c = pipeline.compare_program(inputs.program, inputs.machine, bounds=args.bounds,
                                     progress=engines.prefixed(args.progress, prefix),
                                     max_grid_points=args.max_grid_points)
        args.progress.done()
        doc = comparison_dict(c, args.max_gap)
        docs.append(doc)
        results.append((stem, c))
        if report_dir is not None:
            args.progress(f"{prefix}writing report", -1.0)
            _write_program_report(report_dir, stem, c, doc, args.max_gap)
            args.progress.done()
        if n == 1:
            print_comparison(c, args.max_gap, out)
    if n > 1:
        print_summary(results, args.max_gap, out)
    if report_dir is not None:
        if n > 1:
            from .report_html import write_index
            index = write_index(report_dir, results, args.max_gap)
            out.write(f"report: {index}; open {index.resolve().as_uri()}\n")
        else:
            page = report_dir / (stems[0] + ".html")
            out.write(f"report: {page} (also {stems[0]}.json, {stems[0]}.csv); open "
                      f"{page.resolve().as_uri()}\n")
    if args.json:
        write_json(docs[0] if n == 1 else docs, args.json)
    failed = [(s, c) for s, c in results if not c.verdict(args.max_gap).ok]
    if failed:
        err = sys.stderr
        for _, c in failed:
            v = c.verdict(args.max_gap)
            err.write(f"FAIL {c.program}: {v.status}: {v.text}\n")
            if v.status == "gap above gate":
                for r in c.worst_blocks(5):
                    lab = f" {r.label}" if r.label else ""
                    err.write(f"  line {r.line}{lab} ({r.kind}): {1e3 * r.gap_s:+.1f} ms, "
                              f"heuristic limited by {r.limit_reference}, oracle by "
                              f"{r.limit_oracle}\n")
        return EXIT_FAIL
    return EXIT_OK


def _write_program_report(folder: FsPath, stem: str, c: Comparison, doc: dict,
                          max_gap: float | None, title: str | None = None) -> None:
    from .report_html import write_report
    folder.mkdir(parents=True, exist_ok=True)
    write_json(doc, folder / f"{stem}.json")
    (folder / f"{stem}.csv").write_text(blocks_csv(c), encoding="utf-8")
    write_report(folder / f"{stem}.html", c, max_gap=max_gap, title=title,
                 links={"JSON": f"{stem}.json", "CSV": f"{stem}.csv"})


# --------------------------------------------------------------------- check
def cmd_check(args: argparse.Namespace) -> int:
    """``feedoracle check``: a recorded trajectory against limits and the oracle."""
    inputs = _load(args.program, args)
    smoothing = args.smoothing
    if smoothing != "auto":
        try:
            smoothing = float(smoothing)
        except ValueError:
            raise UsageError(f"--smoothing {args.smoothing!r}: 'auto' or a noise level "
                             f"in mm") from None
        if not (math.isfinite(smoothing) and smoothing >= 0):
            raise UsageError(f"--smoothing {args.smoothing!r}: must be >= 0 mm")
    result = pipeline.check_trajectory(args.trajectory, inputs.program, inputs.machine,
                                       bounds=args.bounds, path_kind=args.path_kind,
                                       smoothing=smoothing,
                                       max_deviation=args.max_deviation,
                                       progress=args.progress,
                                       max_grid_points=args.max_grid_points)
    args.progress.done()
    out = sys.stdout if args.json != "-" else sys.stderr
    result.print(out)
    doc = result.to_dict()
    if args.report:
        folder = FsPath(args.report)
        stem = FsPath(args.trajectory).stem
        _write_program_report(folder, stem, result.comparison, doc, None,
                              title=f"{args.trajectory} on {inputs.program.file}")
        out.write(f"report: {folder / (stem + '.html')}\n")
    if args.json:
        write_json(doc, args.json)
    return EXIT_OK if result.ok else EXIT_FAIL

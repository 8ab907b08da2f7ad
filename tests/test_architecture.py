"""Import rules of DESIGN section 1, checked on the source with ``ast``.

- reference/core/ imports only the standard library, numpy and scipy;
- reference/ never imports optimal or compare;
- optimal/ imports reference.core only (never the NC parser or the heuristic), and
  solver packages only inside optimal/backends/;
- nothing imports compare (except compare itself and the tests).
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SOLVERS = {"cvxpy", "clarabel", "osqp", "highspy", "casadi", "toppra", "ruckig"}
STDLIB = set(sys.stdlib_module_names)


def _imports(py: Path) -> list[tuple[int, str]]:
    """Absolute module names imported by a file (relative imports resolved)."""
    tree = ast.parse(py.read_text(encoding="utf-8"))
    pkg = py.relative_to(ROOT).with_suffix("").parts[:-1]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg[: len(pkg) - node.level + 1]
                mod = ".".join(base + ((node.module,) if node.module else ()))
            else:
                mod = node.module or ""
            out.append((node.lineno, mod))
    return out


def _files(folder: str) -> list[Path]:
    return sorted((ROOT / folder).rglob("*.py"))


def _top(mod: str) -> str:
    return mod.split(".")[0]


@pytest.mark.parametrize("py", _files("reference/core"), ids=lambda p: p.name)
def test_core_imports_only_stdlib_numpy_scipy(py: Path) -> None:
    for line, mod in _imports(py):
        top = _top(mod)
        ok = top in STDLIB or top in ("numpy", "scipy") or mod.startswith("reference.core")
        assert ok, f"{py.relative_to(ROOT)}:{line} imports {mod}"


@pytest.mark.parametrize("py", _files("reference"), ids=lambda p: str(p.relative_to(ROOT)))
def test_reference_never_imports_optimal_or_compare(py: Path) -> None:
    for line, mod in _imports(py):
        assert _top(mod) not in ("optimal", "compare"), (
            f"{py.relative_to(ROOT)}:{line} imports {mod}")


def test_optimal_imports_reference_core_only() -> None:
    for py in _files("optimal"):
        _check_optimal_file(py)


def _check_optimal_file(py: Path) -> None:
    in_backends = "backends" in py.relative_to(ROOT).parts
    for line, mod in _imports(py):
        top = _top(mod)
        if top == "reference":
            assert mod.startswith("reference.core"), (
                f"{py.relative_to(ROOT)}:{line} imports {mod} (only reference.core allowed)")
        assert top != "compare", f"{py.relative_to(ROOT)}:{line} imports {mod}"
        if top in SOLVERS:
            assert in_backends, (f"{py.relative_to(ROOT)}:{line} imports solver {mod} "
                                 "outside optimal/backends/")


@pytest.mark.parametrize("folder", ["reference", "optimal"])
def test_nothing_imports_compare(folder: str) -> None:
    for py in _files(folder):
        for line, mod in _imports(py):
            assert _top(mod) != "compare", f"{py.relative_to(ROOT)}:{line} imports {mod}"


def test_rules_catch_a_violation(tmp_path: Path) -> None:
    """The checker itself must see a forbidden import (guards against a vacuous test)."""
    bad = ROOT / "reference" / "core" / "_probe_tmp.py"
    try:
        bad.write_text("import cvxpy\nfrom ..planner import plan\n")
        mods = [m for _, m in _imports(bad)]
        assert "cvxpy" in mods and "reference.planner" in mods
    finally:
        bad.unlink()


# ------------------------------------------------------------------ one rulebook
#: The modules that hold the shared rules (DESIGN section 2, "One rulebook").
RULEBOOK = ("reference/core/rules.py", "reference/core/causes.py",
            "reference/core/tolerances.py", "reference/core/rows.py",
            "reference/core/jsonio.py", "reference/core/arrays.py")
#: Where the heuristic, the oracle (grid problem and relaxation), the checker and
#: compare live: none of them may define its own copy of a rulebook name.
CONSUMERS = ("reference", "optimal", "compare")


def _defined_names(py: Path) -> dict[str, int]:
    """Module-level assignments and function/class definitions of a file -> line."""
    tree = ast.parse(py.read_text(encoding="utf-8"))
    out: dict[str, int] = {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            out[node.name] = node.lineno
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for tg in targets:
                for n in ast.walk(tg):
                    if isinstance(n, ast.Name):
                        out[n.id] = node.lineno
    return out


def _rulebook_names() -> set[str]:
    names: set[str] = set()
    for rel in RULEBOOK:
        names |= {n for n in _defined_names(ROOT / rel) if not n.startswith("_")}
    return names


def _cause_words() -> tuple[str, ...]:
    """Cause words that are not also checker constraint names ("feed", "jerk", ...)."""
    from reference.core.causes import CAUSES
    from reference.core.constraints import CONSTRAINTS
    return tuple(c for c in CAUSES if c not in CONSTRAINTS)


def _copies(py: Path, names: set[str], words: tuple[str, ...]) -> list[str]:
    """Rulebook names a file redefines, and literal collections of cause words."""
    rel = py.relative_to(ROOT)
    found = [f"{rel}:{line} defines {name}, a rulebook name"
             for name, line in _defined_names(py).items() if name in names]
    for node in ast.walk(ast.parse(py.read_text(encoding="utf-8"))):
        if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            elts = node.elts
        elif isinstance(node, ast.Dict):
            elts = [v for v in node.values if v is not None]
        else:
            continue
        hits = {e.value for e in elts if isinstance(e, ast.Constant) and e.value in words}
        if len(hits) >= 2 or isinstance(node, ast.Dict) and "corner rule" in hits:
            found.append(f"{rel}:{node.lineno} spells out the cause vocabulary {sorted(hits)}")
    return found


@pytest.mark.parametrize("folder", CONSUMERS)
def test_no_module_keeps_its_own_copy_of_a_shared_rule(folder: str) -> None:
    names, words = _rulebook_names(), _cause_words()
    rulebook = {ROOT / r for r in RULEBOOK}
    problems = []
    for py in _files(folder):
        if py not in rulebook:
            problems += _copies(py, names, words)
    assert not problems, "\n".join(problems)


def test_rulebook_check_sees_a_copy() -> None:
    """The copy detector must see a redefined tolerance and a private cause list."""
    bad = ROOT / "compare" / "_probe_rules_tmp.py"
    try:
        bad.write_text("TANGENT_TOL_RAD = 1e-7\n"
                       "X = ('feed', 'axis velocity', 'corner rule')\n"
                       "def junction_speed_cap():\n    pass\n")
        found = _copies(bad, _rulebook_names(), _cause_words())
        assert len(found) == 3, found
    finally:
        bad.unlink()


# ------------------------------------------------------------------ import cycles
def _module_name(py: Path) -> str:
    parts = py.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _import_graph(folder: str) -> dict[str, set[str]]:
    """Module -> modules of the same package it imports (function-level imports too;
    ``from . import x`` resolved to the submodule ``x`` where there is one). Imports under
    ``if TYPE_CHECKING:`` are left out: they never run, so they make no cycle."""
    mods = {_module_name(py): py for py in _files(folder)}
    graph: dict[str, set[str]] = {}
    for name, py in mods.items():
        pkg = name.split(".") if py.name == "__init__.py" else name.split(".")[:-1]
        out: set[str] = set()
        tree = ast.parse(py.read_text(encoding="utf-8"))
        typing_only = {id(n) for node in ast.walk(tree) if isinstance(node, ast.If)
                       and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING"
                       for n in ast.walk(node)}
        for node in ast.walk(tree):
            if id(node) in typing_only:
                continue
            if isinstance(node, ast.Import):
                out |= {a.name for a in node.names if a.name in mods}
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = pkg[: len(pkg) - node.level + 1]
                    mod = ".".join(base + ([node.module] if node.module else []))
                else:
                    mod = node.module or ""
                for a in node.names:
                    sub = f"{mod}.{a.name}"
                    out |= {sub} if sub in mods else ({mod} if mod in mods else set())
        graph[name] = out - {name}
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, edges = work[-1]
            w = next((w for w in edges if w in graph), None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                elif w in on_stack:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    found.append(sorted(comp))
    return found


@pytest.mark.parametrize("folder", ["compare", "reference", "optimal"])
def test_no_import_cycle_within_a_package(folder: str) -> None:
    graph = _import_graph(folder)
    assert len(graph) > 5                              # the walk found the modules
    assert _cycles(graph) == [], f"import cycles in {folder}/ (lazy imports count too)"


def test_cycle_finder_sees_a_cycle() -> None:
    """Guards against a vacuous cycle test: a known cycle and a known chain."""
    g = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set(), "e": {"d"}}
    assert _cycles(g) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []
    graph = _import_graph("compare")
    assert {"compare.engines", "compare.pipeline"} <= graph["compare.commands"]


def test_pipeline_is_free_of_the_cli() -> None:
    """compare/pipeline.py takes plain arguments: no argparse, no printing, no CLI module."""
    py = ROOT / "compare" / "pipeline.py"
    mods = {m for _, m in _imports(py)}
    cli_side = {"argparse", "sys", "compare.cli", "compare.commands", "compare.progress",
                "compare.text"}
    assert not mods & cli_side, f"compare/pipeline.py imports {sorted(mods & cli_side)}"
    calls = {n.func.id for n in ast.walk(ast.parse(py.read_text(encoding="utf-8")))
             if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
    assert "print" not in calls


#: Thresholds that only the rulebook's functions may read: everyone else asks
#: ``is_tangential``, ``curvature_jumps``, ``junction_speed_cap`` (a module that reads the
#: number itself is a module about to write the rule a second time).
RULE_THRESHOLDS = ("TANGENT_TOL_RAD", "CURVATURE_JUMP_TOL_PER_MM")


@pytest.mark.parametrize("folder", CONSUMERS)
def test_rule_thresholds_are_read_only_by_the_rulebook(folder: str) -> None:
    allowed = {ROOT / "reference/core/rules.py", ROOT / "reference/core/tolerances.py"}
    problems = []
    for py in _files(folder):
        if py in allowed:
            continue
        for node in ast.walk(ast.parse(py.read_text(encoding="utf-8"))):
            names = ([a.name for a in node.names] if isinstance(node, ast.ImportFrom)
                     else [node.id] if isinstance(node, ast.Name)
                     else [node.attr] if isinstance(node, ast.Attribute) else [])
            hit = sorted(set(names) & set(RULE_THRESHOLDS))
            if hit:
                problems.append(f"{py.relative_to(ROOT)}:{node.lineno} uses {hit[0]}")
    assert not problems, "\n".join(problems)

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
            "reference/core/tolerances.py")
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

"""The package-level API: every exported name resolves, ``import reference`` stays light,
and the README's Python example runs exactly as printed there (so it cannot drift).
"""

from __future__ import annotations

import contextlib
import io
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _readme_example() -> str:
    """The one ``python`` code block of README.md's "Python API" section."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("\n## Python API\n", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"^```python\n(.*?)^```$", section, flags=re.S | re.M)
    assert len(blocks) == 1, "README's Python API section must hold one python block"
    return blocks[0]


def test_readme_example_runs_and_prints_the_gap_interval():
    code = _readme_example()
    assert len(code.strip().splitlines()) <= 12           # a short example, as promised
    out = io.StringIO()
    namespace: dict = {}
    with contextlib.redirect_stdout(out):
        exec(compile(code, "README.md", "exec"), namespace)
    printed = out.getvalue()
    result, solution, path, plan = (namespace[k] for k in ("result", "solution", "path",
                                                           "plan"))
    assert plan.path is path and result.path is path       # one path object, both sides
    assert str(solution.status) == "optimal"
    # the heuristic is never faster than the certified lower bound
    assert result.t_reference_s >= solution.lower_bound_s
    assert 0.0 <= result.gap_lower <= result.gap_upper
    assert re.search(r"heuristic \d+\.\d{3} s, optimum in \[\d+\.\d{3}, \d+\.\d{3}\] s, "
                     r"gap \d+\.\d+ – \d+\.\d+ %", printed), printed


@pytest.mark.parametrize("package", ["reference", "optimal", "compare"])
def test_every_exported_name_resolves(package):
    mod = __import__(package)
    assert mod.__all__ and len(set(mod.__all__)) == len(mod.__all__)
    for name in mod.__all__:
        assert getattr(mod, name) is not None, f"{package}.{name}"
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        getattr(mod, "no_such_name")


def test_named_entry_points_are_exported():
    import compare
    import optimal
    import reference
    from compare import pipeline
    for name in ("parse_text", "parse_file", "load_machine", "build_path", "plan",
                 "Program", "Machine", "Path", "ReferencePlan"):
        assert name in reference.__all__
    assert "solve" in optimal.__all__ and "OptimalSolution" in optimal.__all__
    for name in ("compare", "Comparison", "format_interval", "comparison_dict", "Inputs",
                 "OptimizeResult", "CheckResult", "load_inputs", "plan_program",
                 "optimize_program", "compare_program", "check_trajectory"):
        assert name in compare.__all__, name
        if name in pipeline.__all__:
            assert getattr(compare, name) is getattr(pipeline, name)
    from reference.prepare import build_path
    assert reference.build_path is build_path


def test_import_reference_is_light_and_never_loads_optimal_or_compare():
    probe = ("import sys, reference, reference.core\n"
             "heavy = sorted(m for m in sys.modules if m.split('.')[0] in "
             "('optimal', 'compare') or m.startswith(('reference.planner', 'reference.nc', "
             "'scipy')))\n"
             "print(heavy)\n"
             "reference.build_path\n"
             "print(sorted(m for m in sys.modules if m.split('.')[0] in "
             "('optimal', 'compare')))\n")
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                       cwd=ROOT, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == ["[]", "[]"]

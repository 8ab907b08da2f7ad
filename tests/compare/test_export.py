"""JSON/CSV writers: the schema copy, non-finite numbers, column sets."""

from __future__ import annotations

import csv
import io
import json
import math
import sys
from dataclasses import replace
from pathlib import Path

import jsonschema
import pytest

from conftest import SMALL, path_of
from fakes import fake_plan, fake_solution

from compare.comparison import OracleResult, Side, compare, compare_profiles
from compare.export import (CSV_COLUMNS, JSON_INF, blocks_csv, comparison_dict, dumps,
                            profile_samples, schema)
from reference.core.limits import MachineLimits
from shared_inputs import SCHEMA, absent


@pytest.mark.skipif(not SCHEMA.is_file(),
                    reason=absent(SCHEMA, "DESIGN's result schema, which the packaged one "
                                          "copies (it lives beside the repository)"))
def test_packaged_schema_is_the_shared_one():
    """The packaged schema is DESIGN's, with one difference issue 12 (newer than DESIGN)
    makes: the bound set ``acc+freq`` (BRISK with the dynamic response adaptation)."""
    shared = json.loads(SCHEMA.read_text())
    ours = schema()
    enum = ours["properties"]["bounds"]["enum"]
    assert "acc+freq" in enum and "acc+freq" not in shared["properties"]["bounds"]["enum"]
    ours["properties"]["bounds"]["enum"] = [b for b in enum if b != "acc+freq"]
    assert ours == shared


def test_infinite_ratio_is_written_as_the_largest_double(machine):
    program, path = path_of(SMALL, machine)
    plan = fake_plan(path, machine.limits)
    # judge the plan on a machine that allows no velocity jump at corners: ratio inf
    stiff = MachineLimits(tuple(replace(a, overload_factor=1.0) for a in machine.limits.axes),
                          machine.limits.t_ipo_s, "stiff")
    sol = fake_solution(path, machine.limits)
    c = compare_profiles(path, stiff, Side("reference", plan.profile, "acc"),
                         OracleResult("optimal", sol.profile, sol.lower_bound_s,
                                      sol.upper_bound_s), program="t.mpf")
    jumps = [v for v in c.reference_violations if v.constraint == "velocity_jump"]
    assert jumps and math.isinf(jumps[0].ratio)
    text = dumps(comparison_dict(c))
    doc = json.loads(text)                           # strict JSON: no Infinity, no NaN
    assert "Infinity" not in text and "NaN" not in text
    jsonschema.validate(doc, schema())
    v = next(v for v in doc["reference"]["violations"] if v["constraint"] == "velocity_jump")
    assert v["ratio"] == JSON_INF == sys.float_info.max and v["ratio_infinite"] is True
    assert v["ratio"] > 1


def test_missing_oracle_profile_keeps_the_schema_valid(machine):
    program, path = path_of(SMALL, machine)
    plan = fake_plan(path, machine.limits)
    c = compare_profiles(path, machine.limits, Side("reference", plan.profile, "acc"),
                         OracleResult("solver_error", None, math.nan, math.nan))
    doc = json.loads(dumps(comparison_dict(c)))
    jsonschema.validate(doc, schema())
    assert doc["verdict"]["ok"] is False
    assert "t_oracle_s" not in doc["blocks"][1]                     # NaN: left out
    assert doc["gap"]["upper_infinite"] is True


def test_blocks_csv_has_one_row_per_block(machine):
    program, path = path_of(SMALL, machine)
    c = compare(fake_plan(path, machine.limits), fake_solution(path, machine.limits),
                program=program)
    rows = list(csv.DictReader(io.StringIO(blocks_csv(c))))
    assert tuple(rows[0].keys()) == CSV_COLUMNS
    assert len(rows) == len(c.rows)
    assert sum(float(r["t_reference_s"]) for r in rows) == pytest.approx(c.t_reference_s)
    assert rows[0]["source"] == "N10 G90 G64 F6000"


def test_profile_samples_end_exactly_and_follow_the_path(machine):
    program, path = path_of(SMALL, machine)
    prof = fake_plan(path, machine.limits).profile
    header, data = profile_samples(path, prof, machine.limits.t_ipo_s)
    assert header == ("t", "s", "v", "X", "Y", "Z")
    assert data[-1, 0] == pytest.approx(prof.duration)
    assert data[0, 3:].tolist() == [0.0, 0.0, 0.0]
    assert data[-1, 3:].tolist() == pytest.approx([120.0, 0.0, 0.0])

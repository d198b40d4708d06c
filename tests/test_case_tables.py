"""Tables that depend on a check's fixed case only (reference runs, what the usual slips give)
are built once per kernel (``check.tolerance.case_table``): a second wrong attempt is judged
at once, with the same verdict and the same hints as on a fresh kernel.

The kind is "a table recomputed at every attempt although only the case determines it"; the
two checks that had the costliest ones are tested here (notebook 02's three-grid order, 1 s
of slips per wrong answer, and notebook 08's hair loop, a whole run per slip)."""

from __future__ import annotations

import numpy as np
import pytest
from planted import define
from test_hints_escalate_01_03 import CASES
from test_nb08_hair import PLANTS

from course_lib.check import FAILURES, evaluate, nb02, nb08, tolerance


def _judge(module, exercise, source, attempt=0) -> dict:
    check = getattr(module, exercise)
    FAILURES.pop(check.key, None)
    if attempt:
        FAILURES[check.key] = attempt
    try:
        return evaluate(check, define(source, exercise))
    finally:
        FAILURES.pop(check.key, None)


def _counting(monkeypatch, module, name) -> list:
    """Count the calls of ``module.name`` (as the check looks it up)."""
    calls, inner = [], getattr(module, name)

    def counted(*args):
        calls.append(1)
        return inner(*args)

    monkeypatch.setattr(module, name, counted)
    return calls


def _order_source(label):
    return next(c[2] for c in CASES if c[1] == "observed_order" and c[3] == label)


def _hair_source(label):
    return next(p.source for p in PLANTS if p.exercise == "hair_frames" and p.label == label)


@pytest.fixture
def fresh_tables(monkeypatch):
    monkeypatch.setattr(tolerance, "_TABLES", {})


@pytest.mark.parametrize(("module", "exercise", "builder", "first", "second"), [
    (nb02, "observed_order", "order_mistakes", _order_source("not log10"),
     _order_source("the ratio is upside down")),
    (nb08, "hair_frames", "loop_mistakes", _hair_source("no damping"),
     _hair_source("bounces off the head")),
])
def test_slips_are_built_once_per_case(monkeypatch, fresh_tables, module, exercise, builder,
                                       first, second):
    """Two answers with different mistakes, the second judged as a second wrong attempt:
    the slips of each failing case are built once in all, and each answer still gets its own
    hint (the hint tests of notebooks 02 and 08 judge every planted mistake with the tables
    shared, so a table that pinned one answer's hint would fail them)."""
    calls = _counting(monkeypatch, module, builder)
    refs = _counting(monkeypatch, nb08, "reference")
    one = _judge(module, exercise, first)
    two = _judge(module, exercise, second, attempt=1)
    assert one["status"] == two["status"] == "incorrect"
    failing = {case.split(":")[0] for v in (one, two) for case in v["failed_cases"]}
    assert 1 <= len(calls) <= len(failing), (len(calls), failing)
    assert one["failed_cases"] != two["failed_cases"]
    if module is nb08:   # and the reference run of each case, once
        assert len(refs) == len(list(nb08.loop_cases()))


def test_a_table_cannot_be_changed_by_its_user(fresh_tables):
    """Arrays come back read-only, at the top or as a dict's values, so no caller can change
    what the next attempt is judged against."""
    table = tolerance.case_table("demo", "a case", lambda: {"slip": np.zeros(3), "other": 1.0})
    with pytest.raises(ValueError, match="read-only"):
        table["slip"][0] = 1.0
    run = tolerance.case_table("demo", "a run", np.ones, 4)
    with pytest.raises(ValueError, match="read-only"):
        run += 1.0
    assert tolerance.case_table("demo", "a run", np.zeros, 4) is run   # built once, by label

"""Hints escalate: a nudge on the first wrong attempt, the fuller explanation only after
another failure in the same kernel; the grader (a fresh process) only ever shows the nudge."""

from __future__ import annotations

import contextlib
import io

from course_lib.check import FAILURES, Checker, evaluate, exercise


@exercise
def double(ck: Checker, fn) -> None:
    ck.close(fn(3.0), 6.0, "double(3)", mistakes={
        ("you added instead of multiplying: look at the operator",
         "return 2 * x, not x + 2"): 5.0})


def _say(fn) -> str:
    with contextlib.redirect_stdout(io.StringIO()) as out:
        double(fn)
    return out.getvalue()


def test_a_nudge_first_then_more_and_the_grader_sees_the_nudge():
    FAILURES.pop(double.key, None)
    first = _say(lambda x: x + 2)
    assert "look at the operator" in first and "return 2 * x" not in first
    second = _say(lambda x: x + 2)
    assert "return 2 * x, not x + 2" in second
    assert FAILURES[double.key] == 2
    FAILURES.pop(double.key)
    verdict = evaluate(double, lambda x: x + 2)  # what the grader runs, in a fresh process
    assert "look at the operator" in verdict["failed_cases"][0]
    assert "correct" in _say(lambda x: 2 * x) and double.key not in FAILURES


def test_the_line_budget_counts_only_the_students_own_lines():
    """A budget of lines is the student's: the standard library's and installed packages'
    frames (the grader's replay decodes a recorded answer with base64 and numpy inside the
    answer's call) do not count, while a loop in the answer's own code does."""
    import statistics

    from course_lib.check._answers import call_analysis

    data = list(range(3000))

    def formula_through_the_stdlib():
        return statistics.mean(data) * 2 + 1          # a pure-Python loop inside the stdlib

    def own_loop():
        total = 0
        for i in range(3000):
            total += i
        return total

    ck = Checker("budget")
    ok, got = call_analysis(ck, "stdlib", 50, None, formula_through_the_stdlib)
    assert ok and got == 3000 and not ck.failed
    ok, _ = call_analysis(ck, "loop", 50, None, own_loop, why="it loops")
    assert not ok and "more than 50 lines" in ck.failed[-1] and "it loops" in ck.failed[-1]

"""Time limits judge the submission's computing, not how busy the grading machine is.

A cell's and an exercise's budget are CPU seconds of the sandboxed process; the wall clock
may run ``sandbox.WAIT_FACTOR`` times longer before the grader kills it. A process that
gets no CPU for a while (a loaded machine, here imitated by a sleep) is not a slow answer;
a loop that computes for ever is stopped at the CPU budget; code that only waits is stopped
by the wall watch. Before this rule a wall-clock alarm of 6 s timed out a correct answer
under a load of 11.

One hand-in of notebook 02 (its imports and exercise cells, as tests/grading/corpus.py
writes them) carries the three behaviours, one per exercise, and is graded once with a
budget of 0.5 s of CPU per exercise: the rule is the same at 0.5 s as at the real 20 s.
"""

from __future__ import annotations

import time

import pytest
from grading.corpus import A02, Sub

from course_lib.check import nb02
from course_lib.instructor.grade import grade_class
from course_lib.instructor.recorder import Recorder, Timeout
from course_lib.instructor.sandbox import WAIT_FACTOR, Limits
from course_lib.instructor.verdicts import Replay, ReplayStop

BUDGET = 0.5  # CPU seconds per exercise
PAUSE = 0.3  # s off the CPU per call of the starved answer
LIMITS = Limits(deadline=120, cell_s=30, exercise_s=BUDGET, memory_mb=1024)


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    """``({exercise: row}, wall seconds)`` of the one hand-in: ``forward_euler_step`` right but
    off the CPU for PAUSE s per call, ``radius_after`` a loop that computes for ever,
    ``drift_dt`` a loop that only sleeps; ``observed_order`` left blank."""
    root = tmp_path_factory.mktemp("limits")
    (Sub(A02)
     .answer("forward_euler_step", f"import time as _time\n_time.sleep({PAUSE})\nreturn y + dt * f(t, y)")
     .answer("radius_after", "while True:\n    pass")
     .answer("drift_dt", "import time as _time\nwhile True:\n    _time.sleep(0.05)")
     .write(root / "class" / "ann" / f"{A02}.ipynb"))
    start = time.monotonic()
    rows = grade_class([root / "class"], root / "grades.csv", assignments=[A02], limits=LIMITS, jobs=1,
                       progress=False)
    return {r.exercise: r for r in rows}, time.monotonic() - start


def test_an_answer_starved_of_cpu_is_not_timed_out(graded):
    # One call per step case, each off the CPU for PAUSE s: past the budget on the wall
    # clock, far below it in CPU time (and below the wall watch).
    calls = len(nb02._STEP_CASES)
    assert BUDGET < calls * PAUSE < WAIT_FACTOR * BUDGET
    row = graded[0]["forward_euler_step"]
    assert row.status == "correct", row.message


def test_a_computing_loop_stops_at_the_cpu_budget(graded):
    row = graded[0]["radius_after"]
    assert row.status == "timeout", {k: r.message for k, r in graded[0].items()}
    assert f"did not finish within {BUDGET:g} s of CPU time" in row.message


def test_an_answer_that_only_waits_is_stopped_by_the_wall_watch(graded):
    rows, seconds = graded
    row = rows["drift_dt"]
    assert row.status == "timeout", row.message
    # killed by the wall watch (WAIT_FACTOR x budget + grace), not by the CPU budget or the
    # notebook's deadline; the notebook is then re-run for the exercise after it
    assert f"killed after {WAIT_FACTOR * BUDGET:g} s (time limit)" in row.message
    assert rows["observed_order"].status == "pending", rows["observed_order"].message
    assert seconds < LIMITS.deadline


# The limit can strike at any instruction. Wherever it lands, the grader's replay must stop
# with a timeout, never call the half-recorded call tampering (it did, 1 run in 3, when
# the alarm landed inside the check's own function during a callback).

STRIKE = {"at": None}


def _square(k):
    """The check's function handed to the answer; the alarm strikes in it at call STRIKE."""
    if k == STRIKE["at"]:
        raise Timeout()
    return k * k


def _answer(step, n):
    return sum(step(k) for k in range(n))


def test_a_limit_striking_inside_a_callback_replays_as_a_timeout(monkeypatch):
    recorder = Recorder(_answer, 1 << 20)
    monkeypatch.setitem(STRIKE, "at", 3)
    with pytest.raises(Timeout):
        recorder(_square, 10)
    monkeypatch.setitem(STRIKE, "at", None)
    assert recorder.calls[0]["timeout"]
    with pytest.raises(ReplayStop, match="timeout"):
        Replay(recorder.calls)(_square, 10)


def test_a_limit_striking_in_the_bookkeeping_replays_as_a_timeout(monkeypatch):
    from course_lib.instructor import codec

    real = codec.encode

    def slow_encode(value, *args, **kwargs):
        if value == 285:  # the answer's result: the alarm lands while it is encoded
            raise Timeout()
        return real(value, *args, **kwargs)

    recorder = Recorder(_answer, 1 << 20)
    monkeypatch.setattr(codec, "encode", slow_encode)
    with pytest.raises(Timeout):
        recorder(_square, 10)
    monkeypatch.setattr(codec, "encode", real)
    assert recorder.calls[0]["timeout"] and "result" not in recorder.calls[0]
    with pytest.raises(ReplayStop, match="timeout"):
        Replay(recorder.calls)(_square, 10)

"""Time limits judge the submission's computing, not how busy the grading machine is.

A cell's and an exercise's budget are CPU seconds of the sandboxed process; the wall clock
may run ``sandbox.WAIT_FACTOR`` times longer before the grader kills it. A process that
gets no CPU for a while (a loaded machine, here imitated by a sleep) is not a slow answer;
a loop that computes for ever is stopped at the CPU budget; code that only waits is stopped
by the wall watch, which does not count the time the process waited for a CPU. Before
this rule a wall-clock alarm of 6 s timed out a correct answer under a load of 11.

One hand-in of notebook 02 (its imports and exercise cells, as tests/grading/corpus.py
writes them) carries the three behaviours, one per exercise, and is graded once with a
budget of 0.5 s of CPU per exercise: the rule is the same at 0.5 s as at the real 20 s.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest
from grading.corpus import A02, Sub
from notebook_helpers import ROOT

from course_lib.check import nb02
from course_lib.instructor.grade import grade_class
from course_lib.instructor.recorder import Recorder, Timeout
from course_lib.instructor.sandbox import COUNTS_QUEUEING, WAIT_FACTOR, Limits, queued_seconds
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


# --- a grading machine whose CPUs are busy ------------------------------------------------

PINNED = hasattr(os, "sched_setaffinity")


def _spin(seconds: float, held: bool = False) -> str:
    """Source of a busy loop pinned to CPU 0 for ``seconds`` (after a byte on stdin if
    ``held``)."""
    return ("import os, sys, time\nos.sched_setaffinity(0, {0})\n"
            + ("sys.stdin.read(1)\n" if held else "")
            + f"t = time.monotonic()\nwhile time.monotonic() - t < {seconds}: pass")


CROWDED = f"""
import os, subprocess, sys
from pathlib import Path
sys.path.insert(0, {str(ROOT / "tests")!r})
os.sched_setaffinity(0, {{0}})     # this process, the grader's fork server and its workers
# four busy loops on the same CPU, each in its own session (the scheduler shares a CPU
# between sessions first), held until the looping exercise starts
hogs = [subprocess.Popen([sys.executable, "-c", {_spin(30, held=True)!r}], stdin=subprocess.PIPE,
                         start_new_session=True)
        for _ in range(4)]
try:
    from grading.corpus import A02, Sub
    from course_lib.instructor import sandbox
    from course_lib.instructor.grade import grade_class
    real_apply = sandbox._apply

    def apply(msg, state, run):
        real_apply(msg, state, run)
        if msg.get("event") == "exercise_start" and msg.get("name") == "radius_after":
            for h in hogs:
                h.stdin.write(b"go")
                h.stdin.close()

    sandbox._apply = apply
    root = Path(sys.argv[1])
    (Sub(A02).answer("radius_after", "while True:\\n    pass")
     .write(root / "class" / "ann" / f"{{A02}}.ipynb"))
    limits = sandbox.Limits(deadline=120, cell_s=30, exercise_s={BUDGET}, memory_mb=1024, grace=0.2)
    rows = grade_class([root / "class"], root / "grades.csv", assignments=[A02], limits=limits,
                       jobs=1, progress=False)
    print(next(r.message for r in rows if r.exercise == "radius_after"))
finally:
    for h in hogs:
        h.kill()
"""


@pytest.mark.skipif(not (COUNTS_QUEUEING and PINNED),
                    reason="the kernel's scheduler statistics and CPU affinity (Linux) are needed")
def test_a_computing_loop_on_a_crowded_cpu_still_stops_at_the_cpu_budget(tmp_path):
    """The grader, its workers and (from the looping exercise's start) four busy loops share
    one CPU: the looping answer gets a fifth of it, so its 0.5 s of CPU take about 2.5 s,
    past the wall watch (3 x 0.5 s + a grace of 0.2 s). The time it spent waiting for the
    CPU is not charged to it: it is stopped by its CPU budget, with the message a quiet
    machine gives, not killed by the wall watch (as a fresh-clone run on a busy machine once
    saw: the cluster's gradebook then differed from the local one by that message)."""
    out = subprocess.run([sys.executable, "-c", CROWDED, str(tmp_path)], capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-3000:]
    assert f"did not finish within {BUDGET:g} s of CPU time" in out.stdout, out.stdout


def test_queued_seconds_counts_waiting_for_a_cpu_not_sleeping():
    if not (COUNTS_QUEUEING and PINNED):
        assert queued_seconds(os.getpid()) == 0.0
        return
    busy = [subprocess.Popen([sys.executable, "-c", _spin(5)]) for _ in range(2)]
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(5)"])
    try:
        time.sleep(1.0)
        queued = [queued_seconds(p.pid) for p in busy]
        assert sum(queued) > 0.5, queued  # two loops on one CPU: each waits about half the time
        assert queued_seconds(sleeper.pid) < 0.1
    finally:
        for p in (*busy, sleeper):
            p.kill()
            p.wait()
    assert queued_seconds(busy[0].pid) == 0.0 and queued_seconds(None) == 0.0  # gone, or none

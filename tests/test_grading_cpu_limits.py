"""Time limits judge the submission's computing, not how busy the grading machine is.

A cell's and an exercise's budget are CPU seconds of the sandboxed process; the wall clock
may run ``sandbox.WAIT_FACTOR`` times longer before the grader kills it. A process that
gets no CPU for a while (a loaded machine, here imitated by a sleep) is not a slow answer;
a loop that computes for ever is stopped at the CPU budget; code that only waits is stopped
by the wall watch. Before this rule a wall-clock alarm of 6 s timed out a correct answer
under a load of 11.
"""

from __future__ import annotations

import textwrap
import time

import nbformat
import pytest
from notebook_helpers import ROOT

from course_lib.instructor import grade_notebook
from course_lib.instructor.recorder import Recorder, Timeout
from course_lib.instructor.sandbox import WAIT_FACTOR, Limits
from course_lib.instructor.verdicts import Replay, ReplayStop

BUDGET = 1.0  # CPU seconds per exercise


def _grade(tmp_path, who: str, redefinition: str) -> dict:
    """The 02 solution with ``forward_euler_step`` wrapped by ``redefinition``, graded."""
    nb = nbformat.read(ROOT / "solutions" / "02_forward_euler.ipynb", as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell(textwrap.dedent(redefinition)))
    path = tmp_path / who / "02_forward_euler.ipynb"
    path.parent.mkdir()
    nbformat.write(nb, path)
    limits = Limits(deadline=170, cell_s=30, exercise_s=BUDGET, memory_mb=1024)
    rows = grade_notebook(path, "02_forward_euler", limits=limits, jobs=1)
    return {r["exercise"]: r for r in rows}


@pytest.mark.parametrize("pause", [0.3, 0.6])
def test_an_answer_starved_of_cpu_is_not_timed_out(tmp_path, pause):
    # Four or more calls, each off the CPU for `pause` s: well past the 1 s budget on the
    # wall clock, far below it in CPU time.
    rows = _grade(tmp_path, f"starved{pause}", f"""\
        import time as _time
        _right = forward_euler_step
        def forward_euler_step(f, t, y, dt):
            _time.sleep({pause})
            return _right(f, t, y, dt)
        """)
    row = rows["forward_euler_step"]
    assert row["status"] == "correct", row["message"]


def test_a_computing_loop_stops_at_the_cpu_budget(tmp_path):
    rows = _grade(tmp_path, "looping", """\
        def forward_euler_step(f, t, y, dt):
            while True:
                pass
        """)
    row = rows["forward_euler_step"]
    assert row["status"] == "timeout", {k: r["message"] for k, r in rows.items()}
    assert f"did not finish within {BUDGET:g} s of CPU time" in row["message"]


def test_an_answer_that_only_waits_is_stopped_by_the_wall_watch(tmp_path):
    start = time.monotonic()
    rows = _grade(tmp_path, "waiting", """\
        import time as _time
        def forward_euler_step(f, t, y, dt):
            while True:
                _time.sleep(0.05)
        """)
    row = rows["forward_euler_step"]
    assert row["status"] == "timeout", row["message"]
    # stopped by the wall watch (WAIT_FACTOR x budget + grace), then the notebook is re-run
    # for the other exercises: bounded well below the notebook's deadline
    assert time.monotonic() - start < 160
    assert WAIT_FACTOR * BUDGET < 170


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

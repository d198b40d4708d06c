"""Notebook 04, the sixth read's defects: the stiff follower's timings (cells 17 to 19) and
the escalation of Exercise 2's hint for a solve with I + dt A."""

from __future__ import annotations

import contextlib
import io

import numpy as np
import pytest
from notebook_helpers import ROOT, cpu_only_clock, markdown, read

import course_lib as cl
from course_lib.lessons import nb04_beyond_euler as lesson
from course_lib.plotting import METHOD_LABELS

NB = "04_beyond_euler.ipynb"
STIFF = ["forward_euler", "midpoint", "rk4", "backward_euler", "trapezoidal"]
#: the fewest steps for 1e-4 m that cell 17 prints (tests/test_nb04_beyond_euler.py asserts them)
FEWEST = {"forward_euler": 3147, "midpoint": 3157, "rk4": 2266, "backward_euler": 32,
          "trapezoidal": 121}


def _flat(text: str) -> str:
    return " ".join(text.split())


def _cells(marker: str, folder: str = "solutions") -> list:
    return [c for c in read(ROOT / folder / NB).cells
            if c.cell_type == "code" and marker in c.source]


# --- 1. timings: CPU time, best of three, printed as ratios in an uncompared cell ---------


@pytest.fixture(scope="module")
def timing_run():
    """Run the notebook's own timing cell with a clock whose wall clocks raise; return its
    namespace (``per_step``: each method's least CPU time per step over three runs of the
    cell), the first run's printout and its number of process_time reads. The cell's runs
    last milliseconds, and on a machine busy with other processes one of them measured
    forward Euler's step four times too slow (the cell's own best of three, within one
    run): the least of three runs of the cell is the same estimate, with more samples."""
    cells = _cells("cpu_per_step(")
    assert len(cells) == 1
    fewest = {(m, 1e-4): lesson.cost_study([m], [n])[0] for m, n in FEWEST.items()}
    runs = []
    for _ in range(3):
        clock, calls = cpu_only_clock("the timing")
        ns = {"np": np, "cl": cl, "lesson": lesson, "METHOD_LABELS": METHOD_LABELS,
              "stiff_methods": list(STIFF), "fewest": fewest}
        saved = lesson.time
        lesson.time = clock
        try:
            with contextlib.redirect_stdout(io.StringIO()) as out:
                exec(compile(cells[0].source, "<timing cell>", "exec"), ns)
        finally:
            lesson.time = saved
        runs.append((ns, out.getvalue(), len(calls)))
    ns, printed, calls = runs[0]
    ns["per_step"] = {m: min(r[0]["per_step"][m] for r in runs) for m in ns["per_step"]}
    return ns, printed, calls


def test_timing_cell_reads_cpu_time_best_of_three(timing_run):
    ns, _, calls = timing_run
    assert calls == 2 * 3 * len(STIFF)          # two reads a run, three runs, five methods
    assert set(ns["per_step"]) == set(STIFF)


def test_step_costs_follow_the_evaluations_and_an_implicit_step_costs_tens(timing_run):
    """What cell 19 says holds on any machine, in ratios of CPU times (best of three):
    explicit steps cost roughly their f-evaluations (1, 2, 4; measured 1.7 and 4.3 to 4.9,
    and 3.2 and 8.0 with eight other processes on the two cores: a cheap f leaves room for
    the stages' own array work; asserted within a factor three of the evaluation ratio, and
    in order), an
    implicit step costs tens of forward Euler steps (measured 37 to 66; asserted 10 to 200),
    so the trapezoid's run is not much cheaper than forward Euler's (measured 1.6 to 2.6
    times as long; asserted at least half) and backward Euler's is cheaper (0.4 to 0.67)."""
    per_step = timing_run[0]["per_step"]
    r = {m: per_step[m] / per_step["forward_euler"] for m in STIFF}
    for m in ("midpoint", "rk4"):
        evals = cl.EVALS_PER_STEP[m] / cl.EVALS_PER_STEP["forward_euler"]     # 2 and 4
        assert evals / 3 <= r[m] <= 3 * evals, (m, r)
    assert 1 < r["midpoint"] < r["rk4"], r
    for m in ("backward_euler", "trapezoidal"):
        assert 10 <= r[m] <= 200, (m, r)
    run = {m: r[m] * FEWEST[m] / FEWEST["forward_euler"] for m in STIFF}
    assert run["trapezoidal"] >= 0.5, run
    assert run["backward_euler"] < 1 and run["backward_euler"] < run["trapezoidal"], run
    assert min(run["midpoint"], run["rk4"]) > 1, run


def test_timing_printout_gives_ratios_not_milliseconds(timing_run):
    out = timing_run[1]
    assert " ms" not in out and "took" not in out
    for m in STIFF:
        line = next(ln for ln in out.splitlines() if ln.startswith(METHOD_LABELS[m]))
        evals = {"backward_euler": 2, "trapezoidal": 3}.get(m, cl.EVALS_PER_STEP.get(m))
        assert f" {FEWEST[m]:6d} {evals:13d} " in line and line.rstrip().endswith("×"), line
    assert "× FE step" in out and "× FE run" in out


def test_timings_print_only_in_a_cell_whose_output_is_not_compared():
    """A compared cell prints nothing timed: the only cell that times is marked
    NBVAL_IGNORE_OUTPUT (ratios of timings change between runs), in both versions, and no
    compared output quotes milliseconds."""
    for folder in ("solutions", "notebooks"):
        nb = read(ROOT / folder / NB)
        for c in nb.cells:
            if c.cell_type != "code":
                continue
            timed = any(w in c.source for w in ("process_time", "perf_counter", "cpu_per_step",
                                                ".seconds"))
            ignored = c.source.startswith("# NBVAL_IGNORE_OUTPUT")
            assert not timed or ignored, c.source[:200]
            if not ignored:
                for o in c.get("outputs", []):
                    text = o.get("text", "") + o.get("data", {}).get("text/plain", "")
                    assert " ms" not in text and "took" not in text, text


def test_cost_study_keeps_no_wall_clock_time():
    row = lesson.cost_study(["backward_euler"], [32])[0]
    assert not hasattr(row, "seconds")
    assert "perf_counter" not in open(lesson.__file__).read()


@pytest.mark.parametrize("bad", [0, -1, 2.5])
def test_cpu_per_step_refuses_a_bad_repeat_or_step_count(bad):
    with pytest.raises(ValueError, match="repeats"):
        lesson.cpu_per_step({"forward_euler": 10}, repeats=bad)
    with pytest.raises(ValueError, match="steps"):
        lesson.cpu_per_step({"forward_euler": bad})


def test_cpu_per_step_refuses_an_unknown_method():
    with pytest.raises(ValueError, match="euler"):
        lesson.cpu_per_step({"eulr": 10})


def test_clock_prose_says_what_holds_on_any_machine():
    text = _flat(markdown(NB))
    assert "On the wall clock" not in text
    assert "the printed times depend on the machine" not in text
    assert "stays clearly ahead" not in text
    assert ("The cell below times each method's run for $10^{-4}$ m in CPU time "
            "(`time.process_time`, the best of three runs") in text
    assert "The explicit methods cost roughly what their evaluations of $f$ predict" in text
    assert "it took as long as tens of forward Euler steps (30 to 70 on the machines" in text
    assert ("the trapezoid's 26 times fewer steps buy little or nothing on the clock, its run "
            "taking about as long as forward Euler's or longer, and only backward Euler, with "
            "98 times fewer steps, stays ahead") in text
    clock = text.split("Evaluations of $f$ are not the whole cost")[1].split("The left panel")[0]
    assert " ms" not in clock
    # the step ratios the prose quotes: 3147/121 = 26, 3147/32 = 98
    assert round(FEWEST["forward_euler"] / FEWEST["trapezoidal"]) == 26
    assert round(FEWEST["forward_euler"] / FEWEST["backward_euler"]) == 98


# --- 2. Exercise 2: the linear-algebra mistakes escalate to a worked scalar case ----------


def _steps(step):
    """An answer to Exercise 2 that applies ``step(A, dt, x)`` n times (floats)."""
    def answer(A, x0, dt, n):
        out = [np.asarray(x0, dtype=float)]
        for _ in range(n):
            out.append(step(np.asarray(A, dtype=float), dt, out[-1]))
        return np.array(out)
    return answer


def _eye(x):
    return np.eye(len(x))


# each mistake written two ways (the second is this file's own): the nudge names it, the
# second wrong attempt adds the worked case a = -1, dt = 0.5 with the numbers it gives
ESCALATING = [
    (lambda A, dt, x: np.linalg.solve(_eye(x) + dt * A, x), "not (I + dt A)",
     ("x0/(1 + 0.5) = 0.667 x0", "x0/(1 - 0.5) = 2 x0", "a decay that grows")),
    (lambda A, dt, x: np.linalg.inv(_eye(x) + dt * A) @ x, "not (I + dt A)",
     ("x0/(1 + 0.5) = 0.667 x0", "x0/(1 - 0.5) = 2 x0")),
    (lambda A, dt, x: x + dt * A @ x, "FORWARD Euler",
     ("(1 + dt a) x0 = 0.5 x0", "x0/(1 + 0.5) = 0.667 x0")),
    (lambda A, dt, x: (_eye(x) + dt * A) @ x, "FORWARD Euler",
     ("(1 + dt a) x0 = 0.5 x0", "x0/(1 + 0.5) = 0.667 x0")),
    (lambda A, dt, x: (_eye(x) - dt * A) @ x, "SOLVE that system",
     ("(1 + 0.5) x0 = 1.5 x0", "x1 = x0/(1 + 0.5) = 0.667 x0")),
    (lambda A, dt, x: x - dt * A @ x, "SOLVE that system",
     ("(1 + 0.5) x0 = 1.5 x0", "np.linalg.solve(I - dt A, x)")),
]


def _hints(out: str) -> list[str]:
    return [ln.split("hint: ", 1)[1] for ln in out.splitlines() if "hint: " in ln]


@pytest.mark.parametrize("step, names, worked", ESCALATING)
def test_exercise_2_hint_escalates_to_a_worked_case(step, names, worked, capsys):
    from course_lib.check import FAILURES, RESULTS
    from course_lib.check import nb04 as check

    FAILURES.pop("nb04.backward_euler_linear", None)
    try:
        outs = []
        for _ in range(2):
            check.backward_euler_linear(_steps(step))
            assert RESULTS["nb04.backward_euler_linear"]["status"] == "incorrect"
            outs.append(capsys.readouterr().out)
    finally:
        FAILURES.pop("nb04.backward_euler_linear", None)
    first, second = _hints(outs[0]), _hints(outs[1])
    assert first and second and first != second, outs
    for hints in (first, second):
        assert any(names in h for h in hints), hints
    assert not any("worked case" in h for h in first), first
    worked_hints = [h for h in second if "a worked case, the scalar decay a = -1, dt = 0.5" in h]
    assert worked_hints, second
    for words in worked:
        assert any(words in h for h in worked_hints), (words, worked_hints)


def test_worked_case_numbers_are_those_of_the_scalar_decay():
    """The numbers the fuller hints quote: a = -1, dt = 0.5, x0 = 1."""
    a, dt = -1.0, 0.5
    assert round(1 / (1 - dt * a), 3) == 0.667                       # backward Euler
    assert 1 / (1 + dt * a) == 2.0                                   # solve with I + dt A
    assert 1 + dt * a == 0.5                                         # forward Euler
    assert 1 - dt * a == 1.5                                         # multiplied by I - dt A

"""The library rule of every check: an answer may call no course_lib function but what the
prompt hands over (course_lib.check.policy reads the bytecode, course_lib.check.watch
watches the run). Planted answers for each road to the library, one exercise standing for
all (the rule lives in ``evaluate``, which every check goes through), and the roads that
must stay open.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest
from notebook_helpers import ROOT

import course_lib as cl
from course_lib.check import Checker, evaluate, exercise, nb02, nb03


def answer(source: str, name: str = "forward_euler_step", **extra):
    """A function defined the way a notebook defines it (module ``__main__``)."""
    namespace = {"__name__": "__main__", "cl": cl, "np": np, "course_lib": cl, **extra}
    exec(compile(source, "<cell>", "exec"), namespace)
    return namespace[name]


DELEGATING = {
    "by name": "def forward_euler_step(f, t, y, dt):\n    return cl.forward_euler(f, t, y, dt)",
    "imported alias": ("from course_lib.steppers import forward_euler as fe\n"
                       "def forward_euler_step(f, t, y, dt):\n    return fe(f, t, y, dt)"),
    "another door": ("def forward_euler_step(f, t, y, dt):\n"
                     "    return cl.integrate(f, y, (t, t + dt), dt, 'forward_euler').y[-1]"),
    "a sibling method": ("def forward_euler_step(f, t, y, dt):\n"
                         "    return cl.heun(lambda s, z: f(t, y), t, y, dt)"),
    "name built from strings": ("def forward_euler_step(f, t, y, dt):\n"
                                "    return getattr(cl, 'forward' + '_euler')(f, t, y, dt)"),
    "importlib": ("def forward_euler_step(f, t, y, dt):\n    import importlib\n"
                  "    m = importlib.import_module('course_lib.' + 'steppers')\n"
                  "    return m.__dict__['rk4'](lambda s, z: f(t, y), t, y, dt)"),
    "default argument": ("def forward_euler_step(f, t, y, dt, step=cl.forward_euler):\n"
                         "    return step(f, t, y, dt)"),
    "called back by NumPy": ("def forward_euler_step(f, t, y, dt):\n"
                             "    out = np.frompyfunc(lambda k: cl.forward_euler(f, t, y, dt), 1, 1)(0)\n"
                             "    return out"),
    "the checks' own helper": ("from course_lib.check import _answers\n"
                               "def forward_euler_step(f, t, y, dt):\n"
                               "    _answers.one_number(1.0)\n    return y + dt * f(t, y)"),
    "a field the prompt did not hand over": ("def forward_euler_step(f, t, y, dt):\n"
                                             "    return y + dt * cl.fields.vortex(t, y)"),
}


@pytest.mark.parametrize("road", sorted(DELEGATING))
def test_every_road_to_the_library_is_refused(road):
    verdict = evaluate(nb02.forward_euler_step, answer(DELEGATING[road]))
    assert verdict["status"] == "incorrect", road
    assert verdict["reference"] and "uses the reference" in verdict["reference"], road
    assert verdict["failed_cases"][0] == verdict["reference"]


OPEN = {
    "NumPy only": "def forward_euler_step(f, t, y, dt):\n    return np.add(y, dt * f(t, y))",
    "the field handed over, called many times": (
        "def forward_euler_step(f, t, y, dt):\n    k = [f(t, y) for _ in range(3)]\n"
        "    return y + dt * k[0]"),
    "an exception class of the library": (
        "def forward_euler_step(f, t, y, dt):\n    try:\n        return y + dt * f(t, y)\n"
        "    except cl.BlowUpError:\n        raise"),
}


@pytest.mark.parametrize("road", sorted(OPEN))
def test_what_the_prompt_hands_over_stays_open(road):
    verdict = evaluate(nb02.forward_euler_step, answer(OPEN[road]))
    assert verdict["status"] == "correct", (road, verdict["failed_cases"])


def test_allowed_blocks_and_the_objects_they_return():
    # 03's limit-by-experiment exercise allows integrate; the Trajectory it returns is usable
    # (14 halvings of 1000 steps: the answer is right, at a fifth of the cost of 20 of 4000)
    source = ("def largest_stable_dt(f, y0, method, dt_hi):\n"
              "    lo, hi = 0.0, dt_hi\n"
              "    for _ in range(14):\n"
              "        mid = 0.5 * (lo + hi)\n"
              "        run = cl.integrate(f, y0, (0.0, 1000 * mid), mid, method,\n"
              "                           blowup_bound=1e3 * np.max(np.abs(y0)))\n"
              "        lo, hi = (mid, hi) if run.stable else (lo, mid)\n"
              "    return lo\n")
    fn = answer(source, "largest_stable_dt")
    verdict = evaluate(nb03.largest_stable_dt, fn)
    assert "uses the reference" not in " ".join(verdict["failed_cases"]), verdict["failed_cases"]
    assert verdict["status"] == "correct", verdict["failed_cases"]
    # ... but not the library's own answer to it
    cheat = answer("def largest_stable_dt(*args):\n    return cl.max_stable_dt('forward_euler', -1.0)",
                   "largest_stable_dt")
    assert "uses the reference" in evaluate(nb03.largest_stable_dt, cheat)["reference"]


def test_forbid_reaches_outside_the_library_in_python_and_in_c():
    @exercise(forbid=("scipy.integrate",))
    def area(ck: Checker, fn) -> None:
        ck.close(fn(), 0.5, "area under y = x on [0, 1]")

    simulated = answer("def area():\n    from scipy.integrate import solve_ivp\n"
                       "    return solve_ivp(lambda t, y: [t], (0, 1), [0.0]).y[0, -1]", "area")
    by_quadrature = answer("def area():\n    import scipy.integrate as si\n"
                           "    return si.quad(lambda x: x, 0, 1)[0]", "area")
    by_hand = answer("def area():\n    x = np.linspace(0, 1, 3)\n    return np.trapezoid(x, x)", "area")

    assert "scipy.integrate" in evaluate(area, simulated)["reference"]
    # the message names what was refused instead of saying SciPy is fine
    assert "this exercise refuses scipy.integrate" in evaluate(area, simulated)["reference"]
    plain = evaluate(nb02.forward_euler_step, answer(DELEGATING["by name"]))["reference"]
    assert "NumPy and SciPy are fine" in plain
    assert "scipy.integrate" in evaluate(area, by_quadrature)["reference"]
    assert evaluate(area, by_hand)["status"] == "correct"


def test_a_refused_c_class_imported_inside_the_function_is_seen():
    @exercise(forbid=("scipy.spatial",))
    def close_pairs(ck: Checker, fn) -> None:
        ck.close(fn(np.array([[0.0, 0.0], [0.5, 0.0], [3.0, 0.0]]), 1.0), 1, "pairs closer than 1")

    # cKDTree is a C class: calling it makes no Python call for the watch to see
    inside = answer("def close_pairs(x, r):\n    from scipy.spatial import cKDTree\n"
                    "    return len(cKDTree(x).query_pairs(r))", "close_pairs")
    assert "scipy.spatial.cKDTree" in evaluate(close_pairs, inside)["reference"]
    by_hand = answer("def close_pairs(x, r):\n    d = np.linalg.norm(x[:, None] - x[None], axis=-1)\n"
                     "    return int(np.triu(d < r, 1).sum())", "close_pairs")
    assert evaluate(close_pairs, by_hand)["status"] == "correct"

def test_the_library_itself_is_still_verified_and_the_hook_is_restored():
    before = sys.getprofile()
    assert evaluate(nb02.forward_euler_step, cl.forward_euler)["status"] == "correct"
    broken = answer("def forward_euler_step(f, t, y, dt):\n    raise ValueError('no')")
    assert evaluate(nb02.forward_euler_step, broken)["status"] == "incorrect"
    assert sys.getprofile() is before


def test_a_pending_answer_stays_pending():
    stub = answer("def forward_euler_step(f, t, y, dt):\n    cl.fields.vortex(t, y)\n"
                  "    raise NotImplementedError()")
    # the static reading refuses it before it runs; a stub with no library call is pending
    assert evaluate(nb02.forward_euler_step, stub)["status"] == "incorrect"
    blank = answer("def forward_euler_step(f, t, y, dt):\n    raise NotImplementedError()")
    assert evaluate(nb02.forward_euler_step, blank)["status"] == "pending"


def test_the_grader_refuses_a_library_call_that_only_the_run_shows(tmp_path):
    """A name the compiler folds from strings hides the call from the bytecode reading; the
    watch inside the sandboxed worker sees it, and the grader refuses the answer."""
    import nbformat

    from course_lib.instructor import grade_notebook
    from course_lib.instructor.notebooks import BEGIN

    nb = nbformat.read(ROOT / "notebooks" / "02_forward_euler.ipynb", as_version=4)
    hidden = ("def forward_euler_step(f, t, y, dt):\n"
              "    import course_lib\n"
              "    return getattr(course_lib, 'forward_' + 'euler')(f, t, y, dt)\n")
    for cell in nb.cells:
        if cell.cell_type == "code" and "def forward_euler_step(" in cell.source:
            tail = cell.source[cell.source.index("check."):]
            cell.source = hidden + "\n" + tail
    # the imports and the answer's cell: the worker runs every code cell, and the rest of
    # the notebook (its figures and runs) would triple the time without bearing on the rule
    code = [cell for cell in nb.cells if cell.cell_type == "code"]
    nb.cells = [code[0]] + [cell for cell in code if "def forward_euler_step(" in cell.source]
    assert len(nb.cells) == 2 and "import course_lib as cl" in nb.cells[0].source
    assert BEGIN not in hidden
    path = tmp_path / "alice" / "02_forward_euler.ipynb"
    path.parent.mkdir()
    nbformat.write(nb, path)
    rows = {r["exercise"]: r for r in grade_notebook(path, "02_forward_euler")}
    row = rows["forward_euler_step"]
    assert row["status"] == "incorrect" and "uses the reference" in row["message"], row

"""Every exercise's solution passes its check, and every stub is reported pending.

Exercise cells are executed on their own, after only the notebook's imports cell: this
proves that the solution code in the notebook agrees with course_lib (the checks compare
against it), that each check accepts the intended answer, and that a blank student
notebook gets "pending" rather than an error.
"""

import contextlib
import io

import pytest
from notebook_helpers import ROOT, SOLUTIONS, check_module, code_cells, read

from course_lib import check

WITH_EXERCISES = [p for p in SOLUTIONS if check_module(read(p))]


def run_exercises(path):
    nb = read(path)
    cells = code_cells(nb)
    namespace: dict = {"__name__": "__main__"}  # judged like a notebook's own code
    check.RESULTS.clear()
    with contextlib.redirect_stdout(io.StringIO()) as out:
        exec(compile(cells[0].source, f"{path.name}:imports", "exec"), namespace)
        for k, cell in enumerate(cells):
            if "### BEGIN SOLUTION" in cell.source or "YOUR CODE HERE" in cell.source:
                exec(compile(cell.source, f"{path.name}:cell{k}", "exec"), namespace)
    module = check_module(nb)
    keys = [key for key in check.REGISTRY if key.startswith(module + ".")]
    return keys, dict(check.RESULTS), out.getvalue()


@pytest.mark.parametrize("path", WITH_EXERCISES, ids=lambda p: p.name)
def test_solutions_pass_every_check(path):
    keys, results, printed = run_exercises(path)
    assert keys, f"{path.name} imports a check module with no exercises"
    for key in keys:
        assert key in results, f"exercise {key} is never checked in {path.name}"
        assert results[key]["status"] == "correct", f"{key}: {results[key]}\n{printed}"
        assert results[key]["total"] >= 1


@pytest.mark.parametrize("path", WITH_EXERCISES, ids=lambda p: p.name)
def test_student_stubs_are_pending(path):
    keys, results, printed = run_exercises(ROOT / "notebooks" / path.name)
    for key in keys:
        assert results.get(key, {}).get("status") == "pending", f"{key}: {results.get(key)}"
    assert "pending" in printed

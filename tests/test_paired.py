"""The paired notebooks of the second rounding (tests/paired.py) run every student cell and
compare every solution cell: checked on the kit's own pairs and on planted ones."""

from __future__ import annotations

import re

import nbformat
import paired
import pytest
from notebook_helpers import ROOT

SOLUTIONS = sorted((ROOT / "solutions").glob("*.ipynb"))


def code(nb) -> list:
    return [c for c in nb.cells if c.cell_type == "code"]


def tags(cell) -> set[str]:
    return set(cell.metadata.get("tags", []))


def test_every_solution_has_a_student_version_to_pair_with():
    students = {p.name for p in (ROOT / "notebooks").glob("*.ipynb")}
    assert SOLUTIONS and {p.name for p in SOLUTIONS} == students


@pytest.mark.parametrize("path", SOLUTIONS, ids=lambda p: p.stem)
def test_a_kit_pair_runs_each_student_cell_and_compares_each_solution_cell(path):
    solution = nbformat.read(path, as_version=4)
    student = nbformat.read(ROOT / "notebooks" / path.name, as_version=4)
    out = paired.pair(solution, student)
    nbformat.validate(out)
    sol, stu, run = code(solution), code(student), code(out)
    # the student's cells first, in order, then the solution's answers
    assert [c.source for c in run[:len(stu)]] == [c.source for c in stu]
    differs = [k for k, (a, b) in enumerate(zip(sol, stu, strict=True)) if a.source != b.source]
    assert differs, "a student version that shares every cell has no exercise"
    assert [c.source for c in run[len(stu):]] == [sol[k].source for k in differs]
    # every solution cell is compared once, against its stored outputs; only the student's
    # own cells are left uncompared (and they must still run without raising)
    compared = [c for c in run if paired.LAX_TAG not in tags(c)]
    assert sorted(c.source for c in compared) == sorted(c.source for c in sol)
    for cell in compared:
        twin = next(c for c in sol if c.source == cell.source)
        assert cell.outputs == twin.outputs
    lax = [k for k, c in enumerate(run) if paired.LAX_TAG in tags(c)]
    assert lax == differs
    assert len({c.id for c in out.cells}) == len(out.cells)
    assert out.metadata.kernelspec.name == "python3"


def planted(sources: list[str], outputs: bool) -> nbformat.NotebookNode:
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nb.cells = [nbformat.v4.new_markdown_cell("# a planted notebook")]
    for k, src in enumerate(sources):
        cell = nbformat.v4.new_code_cell(src)
        if outputs:
            cell.outputs = [nbformat.v4.new_output("stream", name="stdout", text=f"out {k}\n")]
        nb.cells.append(cell)
    return nb


def test_an_exercise_in_the_middle_is_run_lax_and_its_answer_appended_and_compared():
    solution = planted(["x = 1", "def f():\n    return 2", "print(f())", "y = 3"], outputs=True)
    student = planted(["x = 1", "def f():\n    ...  # your code", "print(f())", "y = 3"],
                      outputs=False)
    run = code(paired.pair(solution, student))
    assert [c.source for c in run] == ["x = 1", "def f():\n    ...  # your code", "print(f())",
                                       "y = 3", "def f():\n    return 2"]
    assert [paired.LAX_TAG in tags(c) for c in run] == [False, True, False, False, False]
    # a shared cell after the blank is compared with the solution's output: if it printed
    # what the answer computes, the pass fails there, loudly
    assert run[2].outputs[0].text == "out 2\n" and run[4].outputs[0].text == "out 1\n"


def test_a_student_version_of_another_notebook_is_refused():
    with pytest.raises(ValueError, match="make student"):
        paired.pair(planted(["a = 1", "b = 2"], True), planted(["a = 1"], False))


def test_the_tool_writes_one_pair_per_namesake(tmp_path):
    sol, stu = tmp_path / "solutions", tmp_path / "notebooks"
    sol.mkdir()
    stu.mkdir()
    for name in ("01_a", "02_b"):
        nbformat.write(planted(["a = 1", "b = 2"], True), sol / f"{name}.ipynb")
    nbformat.write(planted(["a = 1", "b = None"], False), stu / "01_a.ipynb")
    assert paired.main([str(tmp_path / "out"), str(sol), str(stu)]) == 0
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["01_a.ipynb"]
    assert paired.main([str(tmp_path / "none"), str(stu), str(sol / "missing")]) == 1


def test_the_second_rounding_runs_the_pairs_and_nothing_else_runs_the_student_versions():
    make = (ROOT / "Makefile").read_text()
    rounding = re.search(r"^test-rounding:.*?(?=^\S)", make, re.S | re.M)[0]
    assert "tests/paired.py $(PAIRED) solutions notebooks" in rounding
    stages = re.search(r"^TEST_STAGES := (.*)$", make, re.M)[1].split()
    assert "test-rounding" in stages and "test-notebooks" not in stages

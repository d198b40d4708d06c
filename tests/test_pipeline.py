"""The notebook pipeline: solutions are the single source of the student versions."""

import json

import nbformat
import pytest
from notebook_helpers import ROOT, SOLUTIONS, code_cells, read

from course_lib.instructor.notebooks import (
    MarkerError,
    make_student_notebook,
    make_student_versions,
    strip_solution,
)


def test_code_region_becomes_a_stub_with_its_indentation():
    src = "def f(x):\n    ### BEGIN SOLUTION\n    y = 2 * x\n    return y\n    ### END SOLUTION\n\ncheck(f)"
    assert strip_solution(src, code=True) == (
        "def f(x):\n    # YOUR CODE HERE\n    raise NotImplementedError()\n\ncheck(f)"
    )


def test_markdown_region_becomes_answer_prompt():
    src = "Why?\n### BEGIN SOLUTION\nBecause |R| > 1.\n### END SOLUTION"
    assert strip_solution(src, code=False) == "Why?\nYOUR ANSWER HERE"


@pytest.mark.parametrize(
    "src,match",
    [
        ("### BEGIN SOLUTION\nx = 1", "never closed"),
        ("x = 1\n### END SOLUTION", "without a"),
        ("### BEGIN SOLUTION\n### BEGIN SOLUTION\n### END SOLUTION", "inside another"),
        ("x = 1  ### BEGIN SOLUTION", "alone on its line"),
    ],
)
def test_unpaired_or_misplaced_markers_fail(src, match):
    with pytest.raises(MarkerError, match=match):
        strip_solution(src, code=True)


def test_student_notebook_clears_outputs_and_keeps_ids():
    nb = nbformat.v4.new_notebook()
    cell = nbformat.v4.new_code_cell("### BEGIN SOLUTION\nprint(42)\n### END SOLUTION")
    cell.outputs = [nbformat.v4.new_output("stream", text="42\n")]
    cell.execution_count = 3
    nb.cells = [cell]
    student = make_student_notebook(nb)
    assert student.cells[0].outputs == [] and student.cells[0].execution_count is None
    assert student.cells[0].id == cell.id
    assert "42" not in student.cells[0].source
    assert nb.cells[0].outputs  # the solution is untouched


def test_committed_student_notebooks_match_a_fresh_regeneration(tmp_path):
    fresh = make_student_versions(ROOT / "solutions", tmp_path)
    committed = sorted((ROOT / "notebooks").glob("*.ipynb"))
    assert [p.name for p in committed] == [p.name for p in fresh], "run `make student`"
    for path in fresh:
        want = json.loads(path.read_text())
        got = json.loads((ROOT / "notebooks" / path.name).read_text())
        assert got == want, f"notebooks/{path.name} is stale: run `make student`"


@pytest.mark.parametrize("path", SOLUTIONS, ids=lambda p: p.name)
def test_solution_is_stored_executed_and_clean(path):
    assert path.stat().st_size < 2_000_000, "keep each notebook under 2 MB"
    nb = read(path)
    assert nb.metadata.kernelspec.name == "python3"
    for cell in code_cells(nb):
        assert cell.execution_count is not None, "store solutions executed (make execute)"
        assert not any(o.output_type == "error" for o in cell.outputs)
        assert not any(o.get("name") == "stderr" for o in cell.outputs), (
            f"stderr output (a warning?) in cell:\n{cell.source[:200]}"
        )


@pytest.mark.parametrize("path", SOLUTIONS, ids=lambda p: p.name)
def test_student_version_has_no_solution_text(path):
    student = read(ROOT / "notebooks" / path.name)
    solution = read(path)
    for s_cell, cell in zip(solution.cells, student.cells, strict=True):
        assert "### BEGIN SOLUTION" not in cell.source and "### END SOLUTION" not in cell.source
        if "### BEGIN SOLUTION" in s_cell.source:
            inside = s_cell.source.split("### BEGIN SOLUTION")[1].split("### END SOLUTION")[0]
            for line in inside.strip().splitlines():
                if len(line.strip()) > 12:
                    assert line not in cell.source.splitlines(), f"solution line leaked: {line}"


@pytest.mark.parametrize("path", sorted((ROOT / "notebooks").glob("*.ipynb")), ids=lambda p: p.name)
def test_student_versions_are_stored_unrun(path):
    """`make test` runs them with strict nbval beside the solutions; a cell stored unrun
    (no execution count, no output) is only run, never compared, so that is --nbval-lax."""
    for cell in code_cells(read(path)):
        assert cell.execution_count is None and cell.outputs == [], cell.source[:80]


@pytest.mark.parametrize("path", SOLUTIONS, ids=lambda p: p.name)
def test_cell_sources_end_without_whitespace(path):
    """nbgrader's release strips trailing whitespace from every cell: a cell that ends in a
    newline would make its release differ from our student version (test_grading_nbgrader)."""
    for cell in read(path).cells:
        assert cell.source == cell.source.rstrip(), f"trailing whitespace in:\n{cell.source[:200]}"

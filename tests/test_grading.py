"""Grading end to end: run submissions in a kernel, read the checks' verdicts, write CSV."""

import csv

import nbformat

from course_lib.instructor import grade_paths, make_student_notebook

CHECK = '''from course_lib.check import exercise

@exercise(points=2)
def double(ck, fn):
    ck.close(fn(2), 4, "fn(2)", mistakes={"you squared instead of doubling": 4.0 + 1e-3})
    ck.close(fn(-3), -6, "fn(-3)", mistakes={"you squared instead of doubling": 9})
'''
ANSWER = '''def my_double(x):
    ### BEGIN SOLUTION
    return 2 * x
    ### END SOLUTION

double(my_double)'''


def write(path, cells):
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nb.cells = [nbformat.v4.new_code_cell(c) for c in cells]
    nbformat.write(nb, path)
    return nb


def test_grade_solution_student_and_wrong_submissions(tmp_path):
    solution = write(tmp_path / "solution.ipynb", [CHECK, ANSWER])
    nbformat.write(make_student_notebook(solution), tmp_path / "blank.ipynb")
    write(tmp_path / "wrong.ipynb", [CHECK, ANSWER.replace("2 * x", "x * x")])
    write(tmp_path / "crashes.ipynb", [CHECK, "1 / 0", ANSWER])
    out = tmp_path / "grades.csv"
    rows = grade_paths([tmp_path], out)
    by_file = {r["submission"].rsplit("/", 1)[-1]: r for r in rows}
    assert by_file["solution.ipynb"]["status"] == "correct"
    assert by_file["solution.ipynb"]["points"] == 2
    assert by_file["blank.ipynb"]["status"] == "pending"
    assert by_file["blank.ipynb"]["points"] == 0
    assert by_file["wrong.ipynb"]["status"] == "incorrect"
    assert (by_file["wrong.ipynb"]["passed"], by_file["wrong.ipynb"]["total"]) == (1, 2)
    # an error in an unrelated cell does not stop grading of the rest
    assert by_file["crashes.ipynb"]["status"] == "correct"
    with out.open() as fh:
        assert len(list(csv.DictReader(fh))) == 4

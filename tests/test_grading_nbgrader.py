"""nbgrader export, proved with nbgrader itself (installed in a separate venv).

The first run creates ``.venv-nbgrader`` (a pinned nbgrader, about a minute); later runs
reuse it. nbgrader's kernel is the course's own Python (a kernelspec on JUPYTER_PATH),
so nbgrader's dependencies never enter ``.venv``. nbgrader's commands run one after the
other in a single process of that venv (:data:`DRIVER`): its start costs seconds of CPU
(imports), paid once rather than once per command.
"""

import copy
import csv
import json
import os
import subprocess
import sys
import textwrap

import nbformat
import pytest
from notebook_helpers import ROOT

from course_lib.instructor.kit import load_kit
from course_lib.instructor.nbgrader_export import (
    autograde_test,
    ensure_nbgrader,
    export_nbgrader,
    nbgrader_source,
)
from course_lib.instructor.notebooks import make_student_notebook

VENV = ROOT / ".venv-nbgrader"
A02, A05 = "02_forward_euler", "05_newtons_second_law"
#: Runs ``nbgrader <args>`` for each JSON list of arguments read from stdin, in this one
#: process, and answers each with a line ``MARK {"code": exit code, "output": ...}``.
DRIVER = textwrap.dedent("""
    import contextlib, io, json, sys, traceback
    from nbgrader.apps.nbgraderapp import NbGraderApp
    for line in sys.stdin:
        out, code = io.StringIO(), 0
        try:
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
                NbGraderApp.launch_instance(json.loads(line))
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else int(exc.code is not None)
        except BaseException:
            code, _ = 1, out.write(traceback.format_exc())
        app = NbGraderApp.instance()
        if getattr(app, "subapp", None) is not None:
            type(app.subapp).clear_instance()
        NbGraderApp.clear_instance()
        print(sys.argv[1], json.dumps({"code": code, "output": out.getvalue()}), flush=True)
""")
MARK = "@@nbgrader-done@@"


def nbgrader_meta(nb):
    return [c.metadata.get("nbgrader") for c in nb.cells]


def test_source_notebooks_carry_nbgrader_metadata():
    from course_lib.check import nb05

    nb = nbgrader_source(nbformat.read(ROOT / "solutions" / f"{A05}.ipynb", as_version=4))
    meta = [m for m in nbgrader_meta(nb) if m]
    tests = [m for m in meta if m["grade_id"].startswith("test_")]
    exercises = load_kit(ROOT / "solutions")[A05].exercises
    assert [m["grade_id"] for m in tests] == [f"test_{e.name}" for e in exercises]
    assert all(m["grade"] and m["locked"] and not m["solution"] for m in tests)
    assert [m["points"] for m in tests] == [float(getattr(nb05, e.check).points) for e in exercises]
    answers = [m for m in meta if m["grade_id"].startswith("answer_")]
    assert len(answers) == 4 and all(m["solution"] and not m["grade"] and not m["locked"] for m in answers)
    assert any(m["grade_id"] == "imports" and m["locked"] for m in meta)
    written = [m for m in meta if m["grade_id"].startswith("written_answer")]
    assert all(m["grade"] and m["solution"] for m in written)  # nbgrader's rule for Markdown answers
    assert all(m["schema_version"] == 3 for m in meta)


def test_autograde_test_passes_only_a_correct_answer():
    from course_lib.check import nb02

    autograde_test(nb02.radius_after, lambda r0, dt, n, k: r0 * ((1 - k * dt) ** 2 + dt**2) ** (n / 2))
    for answer in (lambda r0, dt, n, k: r0, lambda r0, dt, n, k: 1 / 0):
        with pytest.raises(AssertionError, match="radius_after"):
            autograde_test(nb02.radius_after, answer)

    def stub(r0, dt, n, k):
        raise NotImplementedError

    with pytest.raises(AssertionError, match="pending"):
        autograde_test(nb02.radius_after, stub)


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    exe = ensure_nbgrader(VENV)
    root = tmp_path_factory.mktemp("nbgrader-course")
    export_nbgrader(root, ROOT, assignments=[A02])
    kernel = root / "jupyter" / "kernels" / "python3"
    kernel.mkdir(parents=True)
    (kernel / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "Python 3", "language": "python"}))
    env = {**os.environ, "PATH": f"{exe.parent}{os.pathsep}{os.environ['PATH']}",
           "JUPYTER_PATH": str(root / "jupyter")}

    proc = subprocess.Popen([str(exe.parent / "python"), "-c", DRIVER, MARK], cwd=root, env=env,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    def nbgrader(*args):
        proc.stdin.write(json.dumps(list(args)) + "\n")
        proc.stdin.flush()
        printed = []
        for line in proc.stdout:
            if line.startswith(MARK + " "):
                done = json.loads(line[len(MARK) + 1:])
                assert done["code"] == 0, "".join(printed) + done["output"]
                return done
            printed.append(line)
        raise AssertionError(f"nbgrader {args} ended the process: {''.join(printed)}")

    try:
        nbgrader("generate_assignment", A02, "--force")  # one notebook proves the mechanism
        yield root, nbgrader
    finally:
        proc.stdin.close()
        try:
            proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


@pytest.mark.parametrize("assignment", [A02])
def test_generate_assignment_reproduces_our_student_versions(course, assignment):
    root, _ = course
    released = nbformat.read(root / "release" / assignment / f"{assignment}.ipynb", as_version=4)
    ours = make_student_notebook(nbformat.read(ROOT / "solutions" / f"{assignment}.ipynb", as_version=4))
    kept = [c for c in released.cells
            if not (c.metadata.get("nbgrader") or {}).get("grade_id", "").startswith("test_")]
    assert [(c.cell_type, c.source) for c in kept] == [(c.cell_type, c.source) for c in ours.cells]
    assert "BEGIN SOLUTION" not in str(released)


def test_autograde_scores_correct_blank_and_wrong(course):
    """Two hand-ins: every answer right; and one answer wrong, one left blank (the stub),
    the rest right. Each exercise is scored alone, so the second proves a wrong and a blank
    answer earn nothing and the right ones their points."""
    root, nbgrader = course
    released = nbformat.read(root / "release" / A02 / f"{A02}.ipynb", as_version=4)
    solved = nbformat.read(ROOT / "solutions" / f"{A02}.ipynb", as_version=4)
    solution = {c.id: c.source for c in solved.cells}
    a02 = load_kit(ROOT / "solutions")[A02]
    wrong, blank = a02.exercises[0], a02.exercises[-1]
    assert (wrong.name, blank.name) == ("forward_euler_step", "observed_order")

    def hand_in(student, answer):
        nb = copy.deepcopy(released)
        # The kit's demonstration code cells carry no nbgrader metadata and do not change a
        # score; leaving them out of the hand-ins saves most of autograde's running time.
        nb.cells = [c for c in nb.cells if c.cell_type != "code" or c.metadata.get("nbgrader")]
        for cell in nb.cells:
            grade_id = (cell.metadata.get("nbgrader") or {}).get("grade_id", "")
            if grade_id.startswith("answer_"):
                cell.source = answer(grade_id[len("answer_"):], cell.source, solution[cell.id])
        path = root / "submitted" / student / A02 / f"{A02}.ipynb"
        path.parent.mkdir(parents=True)
        nbformat.write(nb, path)

    def mixed(name, stub, sol):
        if name == wrong.name:
            return stub.replace("    # YOUR CODE HERE\n    raise NotImplementedError()",
                                "    return y + dt * f(t + dt, y)")
        return stub if name == blank.name else sol

    hand_in("correct", lambda name, stub, sol: sol)
    hand_in("mixed", mixed)
    nbgrader("autograde", A02, "--force")
    nbgrader("export")
    with (root / "grades.csv").open() as fh:
        scores = {r["student_id"]: (float(r["score"]), float(r["max_score"]))
                  for r in csv.DictReader(fh) if r["assignment"] == A02}
    full, lost = float(a02.possible), float(wrong.points) + float(blank.points)
    assert 0 < float(wrong.points) and 0 < float(blank.points) and lost < full
    assert scores == {"correct": (full, full), "mixed": (full - lost, full)}

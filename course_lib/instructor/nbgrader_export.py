"""nbgrader export: the kit's solutions as an nbgrader course folder (``make nbgrader``).

:func:`export_nbgrader` writes ``OUT/source/<assignment>/<assignment>.ipynb`` for every
solution notebook, with nbgrader cell metadata (schema 3):

- each exercise cell becomes an **answer cell** (``solution``), unchanged, so nbgrader's
  ``generate_assignment`` turns its ``### BEGIN/END SOLUTION`` region into the same stub
  as ``make student``;
- after it comes a locked, autograded **test cell** worth the check's points, which calls
  :func:`autograde_test`: it fails (no points) unless the kit's check says correct;
- the imports cell is locked (nbgrader restores it before autograding), and a Markdown
  answer region becomes a manually graded answer cell worth 0 points.

With it come ``OUT/nbgrader_config.py`` and nothing else: run ``nbgrader
generate_assignment``, collect, ``nbgrader autograde`` as usual. nbgrader runs the tests
in the student's kernel, so it inherits nbgrader's trust in that kernel; the kit's own
grader (``make grade``) is the one that resists tampering.

:func:`ensure_nbgrader` makes a separate virtual environment holding only a pinned
nbgrader (the tests use it; nbgrader's dependencies never enter the course's ``.venv``).
Imports: nbformat, the standard library, :mod:`.kit`, :mod:`.notebooks`.
"""

from __future__ import annotations

import contextlib
import io
import warnings
from pathlib import Path

import nbformat

from . import nbgrader_venv
from .kit import CHECK_IMPORT, exercise_calls
from .nbgrader_venv import NBGRADER_VERSION
from .notebooks import BEGIN

CONFIG = """\
# nbgrader configuration written by `python -m course_lib.instructor nbgrader`.
c = get_config()  # noqa: F821 (provided by nbgrader)
c.CourseDirectory.course_id = "physanim"
c.ClearSolutions.code_stub = {"python": "# YOUR CODE HERE\\nraise NotImplementedError()"}
c.ClearSolutions.text_stub = "YOUR ANSWER HERE"
c.Execute.timeout = 300
"""

TEST_CELL = """\
# Autograded test (locked): passes only if the check of {name} says correct.
from course_lib.instructor.nbgrader_export import autograde_test
autograde_test({alias}.{check}, {name})"""


def autograde_test(check, answer) -> None:
    """Raise AssertionError unless ``check`` (an ``@exercise``) judges ``answer`` correct.

    Runs the check silently (nbgrader gives no points to a test cell that writes to
    stderr, so warnings from the student's code must not leak out).
    """
    from course_lib.check import evaluate

    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()), \
            warnings.catch_warnings():
        warnings.simplefilter("ignore")
        verdict = evaluate(check, answer)
    if verdict["status"] != "correct":
        reason = verdict["failed_cases"][0].splitlines()[0] if verdict["failed_cases"] else "not attempted"
        raise AssertionError(f"{check.__name__}: {verdict['status']} ({reason})")


def _meta(grade_id: str, *, grade: bool = False, solution: bool = False, locked: bool = False,
          points: float | None = None) -> dict:
    meta = {"grade": grade, "grade_id": grade_id, "locked": locked, "schema_version": 3,
            "solution": solution, "task": False}
    if points is not None:
        meta["points"] = points
    return meta


def nbgrader_source(nb: nbformat.NotebookNode, name: str = "notebook") -> nbformat.NotebookNode:
    """The nbgrader source version of a solution notebook (the input is not modified)."""
    out = nbformat.v4.new_notebook(metadata=dict(nb.metadata))
    code = (c.source for c in nb.cells if c.cell_type == "code")
    match = next((m for source in code if (m := CHECK_IMPORT.search(source))), None)
    checks = None
    if match:
        import importlib

        checks = importlib.import_module(f"course_lib.check.{match.group(1)}")
    markdown_answers = 0
    for cell in nb.cells:
        new = nbformat.from_dict(dict(cell))
        new.metadata = {k: v for k, v in cell.metadata.items() if k != "nbgrader"}
        if cell.cell_type == "code":
            new.outputs, new.execution_count = [], None
        out.cells.append(new)
        if match and cell.cell_type == "code" and cell.source is not None and match.group(0) in cell.source:
            new.metadata["nbgrader"] = _meta("imports", locked=True)
        if BEGIN not in cell.source:
            continue
        if cell.cell_type == "markdown":
            markdown_answers += 1
            new.metadata["nbgrader"] = _meta(f"written_answer_{markdown_answers}", grade=True,
                                             solution=True, points=0)
            continue
        calls = exercise_calls(cell.source, match.group(2)) if match else []
        new.metadata["nbgrader"] = _meta(f"answer_{calls[0][1] if calls else cell.get('id')}", solution=True)
        for check_name, function in calls:
            points = float(getattr(checks, check_name).points)
            test = nbformat.v4.new_code_cell(TEST_CELL.format(name=function, alias=match.group(2),
                                                              check=check_name))
            test.id = f"test-{function}".replace("_", "-")[:64]
            test.metadata["nbgrader"] = _meta(f"test_{function}", grade=True, locked=True, points=points)
            out.cells.append(test)
    return out


def export_nbgrader(out: Path, kit: Path | None = None, assignments: list[str] | None = None) -> list[Path]:
    """Write an nbgrader course folder (config and source notebooks) into ``out``."""
    kit = Path(kit) if kit else Path(__file__).resolve().parents[2]
    out = Path(out)
    sources = sorted((kit / "solutions").glob("*.ipynb"))
    if assignments:
        unknown = set(assignments) - {p.stem for p in sources}
        if unknown:
            raise ValueError(f"assignments: unknown {sorted(unknown)}; valid: {[p.stem for p in sources]}")
        sources = [p for p in sources if p.stem in assignments]
    out.mkdir(parents=True, exist_ok=True)
    (out / "nbgrader_config.py").write_text(CONFIG)
    written = [out / "nbgrader_config.py"]
    for src in sources:
        dst = out / "source" / src.stem / src.name
        dst.parent.mkdir(parents=True, exist_ok=True)
        nbformat.write(nbgrader_source(nbformat.read(src, as_version=4), src.name), dst)
        written.append(dst)
    return written


def ensure_nbgrader(venv: Path, version: str = NBGRADER_VERSION) -> Path:
    """The ``nbgrader`` command of a separate venv holding nbgrader ``version`` (made if
    needed, or waited for if another process is making it: :mod:`.nbgrader_venv`)."""
    return nbgrader_venv.ensure(venv, version)

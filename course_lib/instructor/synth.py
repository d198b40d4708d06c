"""A synthetic class for load tests: N students, each handing in one kind of answer.

``python -m course_lib.instructor synth-class --n 1000 OUT`` writes

- ``OUT/submissions/<student>/<assignment>.ipynb``: the kit's student version of each
  assignment with the answers filled in according to the student's kind;
- ``OUT/roster.csv``: an invented roster (names, e-mail, SIS id, login, Canvas id,
  section) in the format :mod:`.roster` reads, so the LMS exports can be tried end to end;
- ``OUT/expected.csv``: the status every exercise must get, per student.

The kinds are those of the grader's own tests (:data:`KINDS`): right, wrong (the first
exercise returns ``None``), crashing (it divides by zero), looping (it never returns: a
timeout, which costs a full exercise time limit of CPU), tampering (a cell writes the
checker's results), huge output (60 MB printed, every answer right) and missing (no
notebook at all). The first students take each kind once; the rest are drawn with
:data:`WEIGHTS` from a seeded generator, so the same command writes the same class.
By default the demonstration cells of each notebook are left out (imports, exercises and
Markdown stay), which makes a notebook cost about one second of worker CPU; ``full=True``
keeps them (a few seconds each, like real hand-ins).

Imports: nbformat, the standard library, this package.
"""

from __future__ import annotations

import csv
import random
import textwrap
from pathlib import Path

import nbformat

from .kit import Assignment, load_kit
from .notebooks import make_student_notebook

KINDS = ("right", "wrong", "crashing", "looping", "tampering", "huge_output", "missing")
#: Share of each kind after the first len(KINDS) students (a plausible large class).
WEIGHTS = {"right": 50, "wrong": 20, "crashing": 8, "looping": 3, "tampering": 2,
           "huge_output": 2, "missing": 15}
STUB = "    # YOUR CODE HERE\n    raise NotImplementedError()"
_FIRST = ("Ada", "Ben", "Chen", "Dara", "Emil", "Fatou", "Goran", "Hana", "Ines", "Jun", "Kofi", "Lea")
_LAST = ("Alvarez", "Berg", "Costa", "Dubois", "Eze", "Fischer", "Garcia", "Haddad", "Ito", "Jensen")
ROSTER_FIELDS = ["student", "first_name", "last_name", "email", "sis_id", "username", "canvas_id", "section"]


def _cell_of(nb, name: str):
    return next(c for c in nb.cells if c.cell_type == "code" and f"def {name}(" in c.source)


def _notebook(a: Assignment, kind: str, full: bool) -> nbformat.NotebookNode:
    """The hand-in of one kind for assignment ``a``."""
    solution = nbformat.read(a.path, as_version=4)
    nb = make_student_notebook(solution)
    names = [e.name for e in a.exercises]
    if not full:
        code = [c for c in nb.cells if c.cell_type == "code"]
        nb.cells = [c for c in nb.cells if c.cell_type != "code" or c is code[0]
                    or any(f"def {n}(" in c.source for n in names)]
    for n in names:
        _cell_of(nb, n).source = _cell_of(solution, n).source
    first = _cell_of(nb, names[0])
    body = {"wrong": "return None", "crashing": "return 1 // 0", "looping": "while True:\n    pass"}.get(kind)
    if body:
        stub_cell = _cell_of(make_student_notebook(solution), names[0]).source
        first.source = stub_cell.replace(STUB, textwrap.indent(body, "    "))
    extra = {"tampering": "from course_lib.check import RESULTS\n"
                          "for key in list(RESULTS):\n"
                          "    RESULTS[key] = {'status': 'correct', 'points': 100}",
             "huge_output": "for _ in range(60):\n    print('x' * 1_000_000)"}.get(kind)
    if extra:
        nb.cells.insert(2, nbformat.v4.new_code_cell(extra))
    return nb


def expected_statuses(a: Assignment, kind: str) -> list[str]:
    """The status of each exercise of ``a`` for a hand-in of ``kind``."""
    first = {"wrong": "incorrect", "crashing": "error", "looping": "timeout"}.get(kind, "correct")
    whole = {"tampering": "tampered", "missing": "missing"}.get(kind)
    return [whole or (first if i == 0 else "correct") for i in range(len(a.exercises))]


def kinds_for(n: int, seed: int = 0) -> list[str]:
    """The kind of each of ``n`` students: every kind once, then drawn by :data:`WEIGHTS`."""
    rng = random.Random(seed)
    drawn = rng.choices(list(WEIGHTS), weights=list(WEIGHTS.values()), k=max(n - len(KINDS), 0))
    return (list(KINDS) + drawn)[:n]


def synth_class(out: Path, n: int, *, solutions: Path | None = None,
                assignments: list[str] | None = None, seed: int = 0, full: bool = False) -> dict:
    """Write a synthetic class of ``n`` students to ``out`` (see the module docstring).

    Returns ``{"submissions": folder, "roster": csv, "expected": csv, "kinds": {student: kind}}``.
    """
    from .grade import default_solutions

    if not isinstance(n, int) or n < 1:
        raise ValueError(f"n: the number of students must be a positive integer, got {n!r}")
    kit = load_kit(solutions or default_solutions())
    names = assignments or ["05_newtons_second_law" if "05_newtons_second_law" in kit else next(iter(kit))]
    unknown = [a for a in names if a not in kit]
    if unknown:
        raise ValueError(f"assignment: unknown {unknown}; valid choices: {sorted(kit)}")
    out = Path(out)
    folder = out / "submissions"
    if folder.exists() and any(folder.iterdir()):
        raise ValueError(f"out: {folder} is not empty; choose a new folder")
    folder.mkdir(parents=True, exist_ok=True)
    made = {(a, k): nbformat.writes(_notebook(kit[a], k, full))
            for a in names for k in KINDS if k != "missing"}
    kinds = {f"s{i + 1:04d}": kind for i, kind in enumerate(kinds_for(n, seed))}
    rng = random.Random(seed + 1)
    with (out / "roster.csv").open("w", newline="") as r, (out / "expected.csv").open("w", newline="") as x:
        roster = csv.DictWriter(r, fieldnames=ROSTER_FIELDS)
        roster.writeheader()
        expected = csv.writer(x)
        expected.writerow(["student", "kind", "assignment", "exercise", "status"])
        for i, (student, kind) in enumerate(kinds.items()):
            (folder / student).mkdir()
            if kind == "missing":
                (folder / student / "README.txt").write_text("I will hand in next week\n")
            for a in names:
                if kind != "missing":
                    (folder / student / f"{a}.ipynb").write_text(made[(a, kind)], "utf-8")
                for e, status in zip(kit[a].exercises, expected_statuses(kit[a], kind), strict=True):
                    expected.writerow([student, kind, a, e.name, status])
            first, last = rng.choice(_FIRST), rng.choice(_LAST)
            roster.writerow({"student": student, "first_name": first, "last_name": last,
                             "email": f"{student}@students.example.edu", "sis_id": f"{20260000 + i + 1}",
                             "username": f"{first.lower()}.{last.lower()}.{i + 1}",
                             "canvas_id": str(5000 + i + 1), "section": f"Section {i % 3 + 1}"})
    return {"submissions": folder, "roster": out / "roster.csv", "expected": out / "expected.csv",
            "kinds": kinds}

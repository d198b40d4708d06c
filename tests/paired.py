"""One run of a notebook that tests both its student version and its solution.

``make test`` runs every solution strictly (nbval compares every stored output) in the
first rounding, and then needs, in the second rounding, the solutions strictly once more
and the student versions run top to bottom (``--nbval-lax``: no cell raises). A student
version is generated from its solution and shares every cell up to the exercises, so two
separate runs would compute the same scenes twice. This module writes, for each pair, one
notebook that does both in one kernel:

1. the student version's cells, in order. A code cell whose source is the solution's cell
   at the same place carries the solution's stored outputs, so nbval compares them as
   strictly as in the solution itself; a cell that differs (an exercise left blank, a
   check call) is tagged ``nbval-ignore-output`` and only has to run without raising, as
   under ``--nbval-lax``;
2. then the solution's cells that the student version does not share, in order, with their
   stored outputs: the answers and their checks, compared strictly.

Every solution code cell is thus run and compared once, and every student cell run once.
What the pairing cannot see: a solution cell of step 2 that reads a name only the student's
blank cells define would pass here and fail in the solution alone (the first rounding's
strict pass runs each solution alone, so it would fail there); and a shared cell placed
after an exercise whose output depends on the answer fails here, loudly. The kit keeps its
exercises at the end of each notebook (tests/test_paired.py checks the pairing).

``python tests/paired.py OUT SOLUTIONS STUDENTS`` writes ``OUT/<name>.ipynb`` for every
notebook of SOLUTIONS with a namesake in STUDENTS; the Makefile's second-rounding stage runs
strict nbval on OUT.
"""

from __future__ import annotations

import copy
import sys
from pathlib import Path

import nbformat

LAX_TAG = "nbval-ignore-output"
#: The markdown cell between the student version and the solution's own cells.
DIVIDER = ("**Test run (tests/paired.py):** the cells above are the student version; the "
           "cells below are the solution's answers, run after them and compared with the "
           "solution's stored outputs.")


def _code(nb) -> list:
    return [c for c in nb.cells if c.cell_type == "code"]


def pair(solution, student) -> nbformat.NotebookNode:
    """The paired notebook of one solution and its student version (both read as v4).

    Raises
    ------
    ValueError
        If the two have different numbers of code cells (the student version is not
        generated from this solution).
    """
    sol, stu = _code(solution), _code(student)
    if len(sol) != len(stu):
        raise ValueError(f"student: {len(stu)} code cells against the solution's {len(sol)}; "
                         "regenerate the student versions (make student)")
    out = copy.deepcopy(student)
    out.metadata = copy.deepcopy(solution.metadata)
    tail = []
    for mine, theirs in zip(_code(out), sol, strict=True):
        if mine.source == theirs.source:
            mine.outputs = copy.deepcopy(theirs.outputs)
            mine.execution_count = theirs.execution_count
        else:
            tags = mine.metadata.setdefault("tags", [])
            if LAX_TAG not in tags:
                tags.append(LAX_TAG)
            answer = copy.deepcopy(theirs)
            answer.id = f"{theirs.get('id', 'cell')}-solution"   # ids are unique per notebook
            tail.append(answer)
    if tail:
        out.cells.append(nbformat.v4.new_markdown_cell(DIVIDER))
        out.cells.extend(tail)
    return out


def write_pairs(out: Path, solutions: Path, students: Path) -> list[Path]:
    """Write the paired notebook of every solution with a student namesake; returns them."""
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for path in sorted(solutions.glob("*.ipynb")):
        twin = students / path.name
        if not twin.exists():
            continue
        nb = pair(nbformat.read(path, as_version=4), nbformat.read(twin, as_version=4))
        target = out / path.name
        nbformat.write(nb, target)
        written.append(target)
    return written


def main(argv: list[str]) -> int:
    if len(argv) != 3:
        print(__doc__.strip().splitlines()[0], "\nusage: python tests/paired.py OUT SOLUTIONS "
              "STUDENTS", file=sys.stderr)
        return 2
    written = write_pairs(*(Path(a) for a in argv))
    print(f"paired {len(written)} notebooks into {argv[0]}")
    return 0 if written else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

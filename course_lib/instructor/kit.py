"""What the kit says an assignment is: its exercises, their checks and points.

The grader never takes the list of exercises from a submission. It reads each solution
notebook: an exercise is a cell holding a solution region inside a ``def`` and a check
call ``check.<name>(<function>)``; its points come from the ``@exercise`` check in
``course_lib.check.nbNN``. :func:`identify` tells which assignment a submitted notebook
is (by cell ids, exercise functions and check import), to catch a notebook handed in
under another assignment's name.

Imports: nbformat, the standard library, and the check modules.
"""

from __future__ import annotations

import ast
import importlib
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import nbformat

from .notebooks import BEGIN
from .scan import AST_LOCK

CHECK_IMPORT = re.compile(r"^\s*from\s+course_lib\.check\s+import\s+(nb\d+)\s+as\s+(\w+)", re.M)


@dataclass(frozen=True)
class Exercise:
    """One graded exercise: the function the student writes and the check that judges it."""

    name: str
    check: str
    key: str
    points: int
    cell_id: str | None


@dataclass
class Assignment:
    """A solution notebook with exercises."""

    name: str
    path: Path
    check_module: str
    exercises: list[Exercise]
    cell_ids: frozenset[str] = field(default_factory=frozenset)

    @property
    def possible(self) -> int:
        return sum(e.points for e in self.exercises)

    def check(self, exercise: Exercise):
        """The ``@exercise`` check function (imported in the grader's own process)."""
        return getattr(importlib.import_module(self.check_module), exercise.check)


def exercise_calls(source: str, alias: str) -> list[tuple[str, str]]:
    """``(check name, function name)`` of every ``alias.<check>(<function>)`` call in ``source``."""
    try:
        with AST_LOCK:             # see scan.AST_LOCK: the grader parses from several threads
            tree = ast.parse(source)
    except SyntaxError:
        return []
    defs = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    calls = []
    for node in tree.body:
        call = node.value if isinstance(node, ast.Expr) else None
        if (isinstance(call, ast.Call) and isinstance(call.func, ast.Attribute)
                and isinstance(call.func.value, ast.Name) and call.func.value.id == alias
                and call.args and isinstance(call.args[0], ast.Name) and call.args[0].id in defs):
            calls.append((call.func.attr, call.args[0].id))
    return calls


def load_assignment(path: Path) -> Assignment | None:
    """The assignment a solution notebook defines, or None if it has no exercises."""
    path = Path(path)
    nb = nbformat.read(path, as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    match = next((m for c in code if (m := CHECK_IMPORT.search(c.source))), None)
    if match is None:
        return None
    module = f"course_lib.check.{match.group(1)}"
    checks = importlib.import_module(module)
    exercises = []
    for cell in code:
        if BEGIN not in cell.source:
            continue
        for check_name, function in exercise_calls(cell.source, match.group(2)):
            check = getattr(checks, check_name)
            exercises.append(Exercise(function, check_name, check.key, int(check.points),
                                      cell.get("id")))
    if not exercises:
        return None
    ids = frozenset(c.get("id") for c in nb.cells if c.get("id"))
    return Assignment(path.stem, path, module, exercises, ids)


class Kit(dict):
    """Assignments by notebook name; ``skipped`` says why a notebook could not be loaded."""

    def __init__(self):
        super().__init__()
        self.skipped: dict[str, str] = {}


def load_kit(solutions: Path) -> Kit:
    """Every assignment of a kit's ``solutions/`` folder, by notebook name."""
    kit = Kit()
    for path in sorted(Path(solutions).glob("*.ipynb")):
        try:
            assignment = load_assignment(path)
        except Exception as exc:  # one broken notebook or check module must not stop the others
            kit.skipped[path.stem] = f"{type(exc).__name__}: {exc}"
            warnings.warn(f"{path.name} skipped: {kit.skipped[path.stem]}", stacklevel=2)
            continue
        if assignment is not None:
            kit[assignment.name] = assignment
    if not kit:
        raise ValueError(f"solutions: no notebook with exercises in {solutions}")
    return kit


def identify(cells: list, kit: dict[str, Assignment]) -> str | None:
    """Which assignment a notebook's cells (objects with ``source`` and ``id``) belong to.

    Votes, strongest first: cell ids shared with a solution, the exercise functions
    defined, the check module imported. None when nothing points anywhere.
    """
    ids = {c.id for c in cells if c.id}
    code = "\n".join(c.source for c in cells if c.kind == "code")
    imported = set(re.findall(r"from\s+course_lib\.check\s+import\s+(nb\d+)", code))
    scores = {}
    for name, a in kit.items():
        defined = sum(bool(re.search(rf"^\s*def\s+{e.name}\s*\(", code, re.M)) for e in a.exercises)
        scores[name] = (len(ids & a.cell_ids), defined, a.check_module.rsplit(".", 1)[-1] in imported)
    best = max(scores, key=scores.get)
    return best if any(scores[best]) else None

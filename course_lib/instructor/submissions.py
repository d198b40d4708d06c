"""A class folder: who the students are, which file is whose assignment, what it holds.

Layout: one folder per student (any depth below it, so nbgrader's
``submitted/<student>/<assignment>/`` works too); a notebook file given directly stands
for a student named after the file. For each expected assignment the grader picks one
file per student (:func:`choose`): a file named after the assignment (case, extra
``.json``/``.txt`` extensions and copy suffixes such as ``(1)`` or ``-Copy1`` ignored),
the exact name first, else the newest; failing that, a notebook whose *content* is that
assignment. Hidden files, checkpoints and symbolic links are never read.

:func:`read_notebook` never raises on a bad file except :class:`Unreadable`, whose
message says what is wrong; nbformat 3 notebooks are upgraded.
Imports: nbformat, the standard library, :mod:`.kit`.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import nbformat

from .kit import Assignment, identify

MAX_BYTES = 20 << 20


class Unreadable(Exception):
    """A submitted file that is not a notebook the grader can read."""


@dataclass(frozen=True)
class Cell:
    """One cell of a submission: its position, type, source and id (None before nbformat 4.5)."""

    index: int
    kind: str
    source: str
    id: str | None = None


@dataclass
class Notebook:
    cells: list[Cell]
    note: str = ""

    @property
    def code(self) -> list[Cell]:
        return [c for c in self.cells if c.kind == "code"]


def _source(value) -> str:
    if isinstance(value, str):
        return value
    if isinstance(value, list) and all(isinstance(s, str) for s in value):
        return "".join(value)
    raise Unreadable("a cell's source is neither text nor a list of lines")


def read_notebook(path: Path, max_bytes: int = MAX_BYTES) -> Notebook:
    """The cells of a submitted notebook, or :class:`Unreadable` saying why not."""
    path = Path(path)
    try:
        size = path.stat().st_size
        if size > max_bytes:
            raise Unreadable(f"the file is {size / 2**20:.1f} MB, over the {max_bytes / 2**20:g} MB limit")
        raw = path.read_bytes()
    except OSError as exc:
        raise Unreadable(f"cannot read the file ({exc.strerror or exc})") from None
    if not raw.strip():
        raise Unreadable("the file is empty")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise Unreadable("the file is not UTF-8 text (not a notebook)") from None
    try:
        data = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        where = f" (line {exc.lineno}: {exc.msg})" if isinstance(exc, json.JSONDecodeError) else ""
        raise Unreadable(f"the file is not valid JSON{where}; was it saved from Jupyter?") from None
    if not isinstance(data, dict) or ("cells" not in data and "worksheets" not in data):
        raise Unreadable(f"the file is JSON but not a notebook (a {type(data).__name__} without cells)")
    version = data.get("nbformat")
    note = ""
    if version != 4:
        try:
            data = nbformat.reads(text, as_version=4)
        except Exception as exc:
            raise Unreadable(f"a notebook of format {version!r} that cannot be upgraded ({exc})") from None
        note = f"upgraded from nbformat {version}"
    cells = data.get("cells")
    if not isinstance(cells, list):
        raise Unreadable("the notebook's cells are not a list")
    out = []
    for index, cell in enumerate(cells):
        if not isinstance(cell, dict) or not isinstance(cell.get("cell_type"), str):
            raise Unreadable(f"cell {index} is not a notebook cell")
        cid = cell.get("id")
        out.append(Cell(index, cell["cell_type"], _source(cell.get("source", "")),
                        cid if isinstance(cid, str) else None))
    return Notebook(out, note)


_EXTENSIONS = re.compile(r"(\.(ipynb|json|txt|bak|orig))+$")
_COPY = re.compile(r"([\s_-]*\(\d+\)|[\s_-]+copy\d*|[\s_-]+v\d+|[\s_-]+final)$")


def normalized(name: str) -> str:
    """A file name reduced to what identifies an assignment: ``02_Forward_Euler (1).ipynb.json``
    -> ``02_forward_euler``."""
    n = _EXTENSIONS.sub("", name.strip().lower())
    while (m := _COPY.search(n)) and m.start() > 0:
        n = n[: m.start()]
    return re.sub(r"[\s-]+", "_", n)


@dataclass
class Student:
    name: str
    files: list[Path] = field(default_factory=list)


def _visible(path: Path, root: Path) -> bool:
    parts = path.relative_to(root).parts
    return not any(p.startswith(".") or p == "__pycache__" for p in parts)


def students(paths: list[Path]) -> list[Student]:
    """The roster: one student per folder inside each class folder, or per file given."""
    roster: dict[str, Student] = {}
    for root in map(Path, paths):
        if root.is_file() and not root.is_symlink():
            roster.setdefault(root.stem, Student(root.stem)).files.append(root)
            continue
        if not root.is_dir():
            raise ValueError(f"submissions: {root} is neither a folder nor a file")
        for entry in sorted(root.iterdir()):
            if entry.name.startswith(".") or entry.is_symlink():
                continue
            if entry.is_dir():
                files = sorted(p for p in entry.rglob("*") if p.is_file() and not p.is_symlink()
                               and _visible(p, entry) and not _linked(p, entry))
                roster.setdefault(entry.name, Student(entry.name)).files.extend(files)
            elif entry.is_file():
                roster.setdefault(entry.stem, Student(entry.stem)).files.append(entry)
    return sorted(roster.values(), key=lambda s: s.name)


def _linked(path: Path, top: Path) -> bool:
    """True if a folder between ``top`` and ``path`` is a symbolic link."""
    parent = path.parent
    while parent != top and parent != parent.parent:
        if parent.is_symlink():
            return True
        parent = parent.parent
    return False


@dataclass
class Choice:
    path: Path | None
    note: str = ""


def choose(student: Student, assignment: Assignment, kit: dict[str, Assignment]) -> Choice:
    """The file to grade for one student and one assignment (see the module docstring)."""
    by_name = [p for p in student.files if normalized(p.name) == assignment.name.lower()]
    if by_name:
        exact = [p for p in by_name if p.name == f"{assignment.name}.ipynb"]
        pick = exact[0] if exact else max(by_name, key=lambda p: (p.stat().st_mtime, p.name))
        others = [p.name for p in by_name if p != pick]
        note = f"also handed in: {', '.join(others)} (not graded)" if others else ""
        return Choice(pick, note)
    for path in sorted(student.files, key=lambda p: -p.stat().st_mtime):
        if path.stat().st_size > MAX_BYTES:
            continue
        try:
            nb = read_notebook(path)
        except Unreadable:
            continue
        if identify(nb.cells, kit) == assignment.name:
            return Choice(path, f"no file named {assignment.name}.ipynb; graded {path.name}, "
                                "whose content is this assignment")
    listing = ", ".join(p.name for p in student.files[:8]) or "no files"
    return Choice(None, f"no notebook for {assignment.name} ({listing})")

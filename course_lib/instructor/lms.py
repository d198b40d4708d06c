"""Gradebook exports in the import formats of Canvas, Moodle and D2L Brightspace.

:func:`export_grades` reads the grader's gradebook (``grades.csv``: one row per student,
assignment and exercise), adds up each student's points per assignment, maps every
student to the LMS's identifiers through a roster (:mod:`.roster`) and writes one CSV
file the LMS imports as is. A graded student missing from the roster stops the export
with the names (a silent drop would lose a grade); so does a student who lacks every
identifier the format can key on.

Formats, after each system's documentation of its grade import:

- **Canvas** (Grades → Import): columns ``Student, ID, SIS User ID, SIS Login ID,
  Section`` then one column per assignment; the second row, ``Points Possible``, gives
  each assignment's maximum. Canvas identifies a student by ID, SIS User ID or SIS Login
  ID; a column titled ``Name (1234)`` updates assignment 1234, a bare name creates an
  assignment.
- **Moodle** (Grades → Import → CSV file): ``First name, Last name, ID number, Email
  address`` then one column per assignment; on the import page, "Map from" *Email
  address* to *useremail* (or *ID number* to *useridnumber*), and map each column to a
  grade item (or to a new one).
- **D2L Brightspace** (Grades → Enter Grades → Import): ``OrgDefinedId, Username``, one
  ``<item> Points Grade`` column per grade item, and ``End-of-Line Indicator``, whose
  value is ``#`` on every row; identifiers are written with a leading ``#``, as
  Brightspace's own exports do, so a spreadsheet keeps leading zeros.

Grade items are named after the assignments (``02_forward_euler``) unless ``items``
maps an assignment to the LMS's own title. Imports: the standard library, :mod:`.roster`.
"""

from __future__ import annotations

import csv
from collections import defaultdict
from pathlib import Path

from .roster import Person, match, read_roster

FORMATS = ("canvas", "moodle", "brightspace")
#: The identity columns of each format, in the order the file starts with.
HEADERS = {
    "canvas": ["Student", "ID", "SIS User ID", "SIS Login ID", "Section"],
    "moodle": ["First name", "Last name", "ID number", "Email address"],
    "brightspace": ["OrgDefinedId", "Username"],
}
#: Roster columns of which each format needs at least one per student.
KEYS = {"canvas": ("canvas_id", "sis_id", "username"), "moodle": ("email", "sis_id"),
        "brightspace": ("sis_id", "username")}


def read_gradebook(path: Path) -> tuple[list[str], dict[str, dict[str, tuple[float, float]]]]:
    """Assignments (in gradebook order) and ``{student: {assignment: (points, possible)}}``."""
    try:
        with Path(path).open(newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
    except OSError as exc:
        raise ValueError(f"gradebook: cannot read {path} ({exc.strerror or exc})") from None
    needed = {"student", "assignment", "points", "possible"}
    if not rows or not needed <= set(rows[0]):
        raise ValueError(f"gradebook: {path} is not a gradebook of the grader (columns {sorted(needed)})")
    totals: dict[str, dict[str, list[float]]] = defaultdict(lambda: defaultdict(lambda: [0.0, 0.0]))
    assignments: dict[str, None] = {}
    for line, r in enumerate(rows, start=2):
        try:
            points, possible = float(r["points"]), float(r["possible"])
        except (TypeError, ValueError):
            raise ValueError(f"gradebook: {path}, line {line}: points {r['points']!r} / "
                             f"{r['possible']!r} are not numbers") from None
        cell = totals[r["student"]][r["assignment"]]
        cell[0] += points
        cell[1] += possible
        assignments[r["assignment"]] = None
    return list(assignments), {s: {a: tuple(v) for a, v in t.items()} for s, t in totals.items()}


def _number(x: float) -> str:
    return str(int(x)) if float(x).is_integer() else f"{x:.4f}".rstrip("0")


def _identity(fmt: str, p: Person) -> list[str]:
    if fmt == "canvas":
        return [p.display_name, p.get("canvas_id"), p.get("sis_id"), p.get("username"), p.get("section")]
    if fmt == "moodle":
        return [p.get("first_name"), p.get("last_name"), p.get("sis_id"), p.get("email")]
    return [f"#{p.get(k)}" if p.get(k) else "" for k in ("sis_id", "username")]


def export_grades(gradebook: Path, roster: Path, fmt: str, out: Path, *, key: str = "student",
                  items: dict[str, str] | None = None) -> dict:
    """Write ``out``, the import file of ``fmt`` (one of :data:`FORMATS`).

    ``key`` is the roster column that holds the submission folder names; ``items`` maps
    assignment names to the LMS's titles of their grade items. Returns a summary:
    ``{"path", "students", "assignments", "not_graded"}`` (roster entries without any
    graded submission, left out of the file).
    """
    if fmt not in FORMATS:
        raise ValueError(f"fmt: unknown LMS format {fmt!r}; valid choices: {list(FORMATS)}")
    assignments, totals = read_gradebook(gradebook)
    people = read_roster(roster, key=key)
    graded = match(sorted(totals), people)
    lacking = [s for s, p in graded.items() if not any(p.get(k) for k in KEYS[fmt])]
    if lacking:
        raise ValueError(f"roster: {fmt} identifies students by {' or '.join(KEYS[fmt])}, and the roster "
                         f"gives none for {', '.join(lacking[:20])}")
    items = items or {}
    unknown = sorted(set(items) - set(assignments))
    if unknown:
        raise ValueError(f"items: {unknown} are not assignments of the gradebook; valid: {assignments}")
    titles = [items.get(a, a) for a in assignments]
    header = HEADERS[fmt] + (titles if fmt != "brightspace" else [f"{t} Points Grade" for t in titles])
    if fmt == "brightspace":
        header.append("End-of-Line Indicator")
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        if fmt == "canvas":
            possible = [max(t[a][1] for t in totals.values() if a in t) for a in assignments]
            writer.writerow(["    Points Possible", "", "", "", ""] + [_number(p) for p in possible])
        for student in sorted(graded):
            points = [_number(totals[student][a][0]) if a in totals[student] else "" for a in assignments]
            end = ["#"] if fmt == "brightspace" else []
            writer.writerow(_identity(fmt, graded[student]) + points + end)
    return {"path": out, "students": len(graded), "assignments": assignments,
            "not_graded": sorted(set(people) - set(graded))}

"""The class roster: who each submission folder belongs to, in the LMS's own identifiers.

A roster is a CSV file with a header; column names are matched without regard to case,
spaces or underscores. One column names the **submission folder** of each student (the
``student`` column of the gradebook): ``student`` by default, or any other column chosen
with ``key=`` (``username``, ``email``, ``sis_id``) when the folders are named that way.
The other columns carry the identifiers the LMS imports need:

=============  =====================================================================
column         used by
=============  =====================================================================
first_name     Canvas (Student), Moodle (First name)
last_name      Canvas (Student), Moodle (Last name)
email          Moodle (Email address, the usual "Map from" key)
sis_id         Canvas (SIS User ID), Moodle (ID number), Brightspace (OrgDefinedId)
username       Canvas (SIS Login ID), Brightspace (Username)
canvas_id      Canvas (ID: the numeric Canvas user id)
section        Canvas (Section)
=============  =====================================================================

:func:`read_roster` raises ``ValueError`` naming the row for a missing key column, an
empty or repeated key. Imports: the standard library.
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass, field
from pathlib import Path

COLUMNS = ("student", "first_name", "last_name", "email", "sis_id", "username", "canvas_id", "section")
_ALIASES = {"folder": "student", "firstname": "first_name", "lastname": "last_name", "emailaddress": "email",
            "sisuserid": "sis_id", "orgdefinedid": "sis_id", "idnumber": "sis_id", "studentnumber": "sis_id",
            "login": "username", "sisloginid": "username", "loginid": "username", "canvasuserid": "canvas_id",
            "id": "canvas_id"}


def _column(name: str) -> str:
    plain = re.sub(r"[\s_\-.]+", "", name.strip().lower())
    for col in COLUMNS:
        if plain == col.replace("_", ""):
            return col
    return _ALIASES.get(plain, name.strip())


@dataclass
class Person:
    """One roster row: the submission folder and the identifiers an LMS knows."""

    student: str
    fields: dict[str, str] = field(default_factory=dict)

    def get(self, column: str) -> str:
        return self.fields.get(column, "").strip()

    @property
    def display_name(self) -> str:
        """``Last, First`` as Canvas shows it (the folder name if the roster has no names)."""
        last, first = self.get("last_name"), self.get("first_name")
        return f"{last}, {first}" if last and first else (last or first or self.student)


def read_roster(path: Path, key: str = "student") -> dict[str, Person]:
    """The roster's people by submission folder name (see the module docstring)."""
    key = _column(key)
    if key not in COLUMNS:
        raise ValueError(f"key: {key!r} is not a roster column; valid choices: {list(COLUMNS)}")
    try:
        text = Path(path).read_text("utf-8-sig")
    except OSError as exc:
        raise ValueError(f"roster: cannot read {path} ({exc.strerror or exc})") from None
    reader = csv.DictReader(text.splitlines())
    if not reader.fieldnames:
        raise ValueError(f"roster: {path} is empty; it needs a header row with a {key!r} column")
    columns = {name: _column(name) for name in reader.fieldnames}
    if key not in columns.values():
        raise ValueError(f"roster: {path} has no {key!r} column (it has {reader.fieldnames}); "
                         f"the {key!r} column names each student's submission folder")
    people: dict[str, Person] = {}
    for line, raw in enumerate(reader, start=2):
        row = {columns[k]: (v or "") for k, v in raw.items() if k is not None}
        student = row.get(key, "").strip()
        if not student:
            raise ValueError(f"roster: {path}, line {line}: the {key!r} column is empty")
        if student in people:
            raise ValueError(f"roster: {path}, line {line}: {student!r} appears twice")
        people[student] = Person(student, row)
    return people


def match(students: list[str], roster: dict[str, Person]) -> dict[str, Person]:
    """Each graded student's roster entry; ``ValueError`` naming every student who has none
    (an export that silently dropped a student would lose a grade)."""
    unknown = [s for s in students if s not in roster]
    if unknown:
        shown = ", ".join(unknown[:20]) + (f" and {len(unknown) - 20} more" if len(unknown) > 20 else "")
        raise ValueError(f"roster: {len(unknown)} graded submission(s) match no roster entry: {shown}. "
                         "Add them to the roster (or fix the folder names) before exporting")
    return {s: roster[s] for s in students}

"""Instructor tools: student versions, grading, feedback, the student release, nbgrader export.

Command line: ``python -m course_lib.instructor {student,execute,figures,grade,release,nbgrader}``
(or ``make student``, ``make execute``, ``make grade``, ``make release``, ``make nbgrader``);
docs/INSTRUCTORS.md walks through the whole cycle.

Submodules are imported on first use.
"""

from __future__ import annotations

import importlib

_EXPORTS = {
    "execute_notebook": "notebooks",
    "make_student_notebook": "notebooks",
    "make_student_versions": "notebooks",
    "grade_class": "grade",
    "grade_paths": "grade",
    "grade_notebook": "grade",
    "build_release": "release",
    "export_nbgrader": "nbgrader_export",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    if name in _EXPORTS:
        return getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

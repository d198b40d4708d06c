"""Instructor tools: student versions, grading (here or on a Dask cluster), feedback, LMS
exports, the student release, nbgrader export, synthetic classes, clips.

Command line: ``python -m course_lib.instructor {student,execute,figures,grade,release,nbgrader,
synth-class,export,clips}`` (or ``make student``, ``make execute``, ``make grade``,
``make release``, ``make nbgrader``, ``make clips``); docs/INSTRUCTORS.md walks through the
whole cycle.

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
    "export_grades": "lms",
    "synth_class": "synth",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    if name in _EXPORTS:
        return getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

"""Instructor tools: student versions, executing solutions, grading submissions.

Command line: ``python -m course_lib.instructor {student,execute,grade} ...``
(or ``make student``, ``make execute``, ``make grade``).
"""

from .grade import grade_notebook, grade_paths
from .notebooks import execute_notebook, make_student_notebook, make_student_versions

__all__ = [
    "execute_notebook",
    "grade_notebook",
    "grade_paths",
    "make_student_notebook",
    "make_student_versions",
]

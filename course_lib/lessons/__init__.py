"""Lessons: one module per notebook, ``nbNN_topic.py``, mirroring ``course_lib/check/nbNN.py``.

A lesson holds what belongs to one notebook only: its scenes (pure functions that build
and run a simulation from the core), runners, drawings and widget views. Lessons import
the core (``course_lib.*``) and the view helpers (:mod:`course_lib.plotting`,
:mod:`course_lib.widgets`); the core never imports a lesson. Notebooks import their lesson
as ``from course_lib.lessons import nbNN_topic as lesson``.
"""

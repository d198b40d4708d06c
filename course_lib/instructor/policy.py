"""Where the grader finds the library rule: :mod:`course_lib.check.policy` (moved there so
that the checks, one layer below the instructor tools, no longer import upwards).

Kept so that ``course_lib.instructor.policy`` still names the same functions.
"""

from course_lib.check.policy import (  # noqa: F401 (re-exported)
    answer_is_reference,
    exercise_rules,
    import_path,
    message,
    name_chains,
    reference_use,
    references_in_code,
)

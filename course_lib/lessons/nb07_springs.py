"""Notebook 07 (springs): what the notebook imports as ``lesson``, in one place.

The computations live in :mod:`course_lib.lessons.nb07_spring_runs` (step matrices,
stability limits with damping, the widget's pure function :func:`run_spring`), the drawing
and the widget in :mod:`course_lib.lessons.nb07_spring_view`, which imports the runs. This
module only gathers both, so imports point one way: runs ← view ← this module.
"""

from __future__ import annotations

from .nb07_spring_runs import (
    SpringRun,
    damped_dt_limit,
    limit_text,
    matrix_powers,
    run_spring,
    settling_time,
    spectral_radius,
    spring_dt_max,
    step_matrix,
    symplectic_euler_limit,
)
from .nb07_spring_view import SpringPlot, draw_spring_run, spring_explorer

__all__ = ["SpringPlot", "SpringRun", "damped_dt_limit", "draw_spring_run", "limit_text",
           "matrix_powers", "run_spring", "settling_time", "spectral_radius", "spring_dt_max",
           "spring_explorer", "step_matrix", "symplectic_euler_limit"]

"""Notebook 07 (springs): what the notebook imports as ``lesson``, in one place.

The step matrices and where they are stable live in
:mod:`course_lib.lessons.nb07_spring_limits`, the runs (the widget's pure function
:func:`run_spring`, settling times, the step limit measured by simulation) in
:mod:`course_lib.lessons.nb07_spring_runs`, the drawings and the widget in
:mod:`course_lib.lessons.nb07_spring_view`. This module only gathers them, so imports point
one way: limits ← runs ← view ← this module.
"""

from __future__ import annotations

from .nb07_spring_limits import (
    damped_dt_limit,
    growth,
    limit_text,
    matrix_powers,
    scan_windows,
    spectral_radius,
    stable_windows,
    step_matrix,
    symplectic_euler_limit,
    velocity_verlet_gap_end,
    velocity_verlet_windows,
)
from .nb07_spring_runs import SpringRun, run_spring, settling_time, spring_dt_max, verdict_growth
from .nb07_spring_view import SpringPlot, draw_damped_limits, draw_spring_run, spring_explorer

__all__ = ["SpringPlot", "SpringRun", "damped_dt_limit", "draw_damped_limits", "draw_spring_run",
           "growth", "limit_text",
           "matrix_powers", "run_spring", "scan_windows", "settling_time", "spectral_radius",
           "spring_dt_max", "spring_explorer", "stable_windows", "step_matrix",
           "symplectic_euler_limit", "velocity_verlet_gap_end", "velocity_verlet_windows",
           "verdict_growth"]

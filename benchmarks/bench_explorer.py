"""Stability explorer: time from a control change to a redrawn figure (target 50 ms).

Measured outside a kernel, where :class:`course_lib.widgets.ExplorerView` recomputes and
draws the figure with Agg on every change, as the notebook's explorer does.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

from benchmarks.__main__ import Result, median_time
from course_lib.lessons import nb03_explorer_view as exv
from course_lib.lessons import nb03_stability as ex
from course_lib.plotting import use_course_style

TARGET = 0.050  # s, compute + draw after one control change, default settings


def run() -> list[Result]:
    use_course_style()
    view = exv.stability_explorer()
    dt = view.controls["dt"]
    values = iter([0.5, 0.51] * 1000)

    def change_dt() -> None:  # alternate so that every assignment is a real change
        dt.value = next(values)

    def compute() -> None:
        ex.run_experiment(**view.params)

    return [
        Result("explorer: run_experiment (defaults)", median_time(compute)),
        Result("explorer: dt change -> recompute + redraw (defaults)", median_time(change_dt),
               TARGET),
    ]

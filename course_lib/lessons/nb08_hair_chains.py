"""Notebook 08 (hair chains): what the notebook imports as ``lesson``, in one place.

The computations live in :mod:`course_lib.lessons.nb08_hair_runs` (the held strand and
the widget's pure function :func:`run_held_strand`, substep studies, twist experiments),
the drawings, the widget and the animations in :mod:`course_lib.lessons.nb08_hair_view`,
which imports the runs. This module only gathers both, so imports point one way:
runs ← view ← this module.
"""

from __future__ import annotations

from .nb08_hair_runs import (
    HeldStrandRun,
    SaddleEscape,
    damped_step_limit,
    drooped_equilibrium,
    flipped_bends,
    held_strand,
    max_strain_vs_substeps,
    run_held_strand,
    saddle_escape,
    stiffest_edge,
    tip_sag,
    twist_energy,
    twist_release,
    twist_releases,
    twist_shapes,
)
from .nb08_hair_view import (
    HeldStrandPlot,
    animate,
    draw_hairstyle,
    draw_held_strand,
    draw_saddle,
    held_strand_explorer,
)

__all__ = ["HeldStrandPlot", "HeldStrandRun", "SaddleEscape", "animate", "damped_step_limit",
           "draw_hairstyle", "draw_held_strand", "draw_saddle", "drooped_equilibrium",
           "flipped_bends", "held_strand", "held_strand_explorer",
           "max_strain_vs_substeps", "run_held_strand", "saddle_escape", "stiffest_edge",
           "tip_sag", "twist_energy", "twist_release", "twist_releases", "twist_shapes"]

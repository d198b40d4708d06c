"""course_lib: integrators, forces and models for a course on physics-based animation.

Layers (a module may import only from layers above it):

- **core** (this package's top level): integrators, implicit solves, stability, fields,
  systems, forces, springs, hair strands, statics, collisions, events, neighbour search,
  and, grouped by subject, the large-step cloth solvers (:mod:`~course_lib.largestep`),
  SPH liquids (:mod:`~course_lib.sph`) and rigid bodies (:mod:`~course_lib.rigid`).
  Reusable outside the course: no widgets, no plotting, no notebook scenes.
- **view helpers** (:mod:`~course_lib.plotting`, :mod:`~course_lib.widgets`): styles,
  animation players, the pure-function + thin-view widget pattern.
- **lessons** (:mod:`course_lib.lessons`): one module per notebook
  (``lessons/nbNN_topic.py``) with its scenes, runners, drawings and widget views.
- **checks** (:mod:`course_lib.check`) and **instructor** tools
  (:mod:`course_lib.instructor`).

The pieces follow Baraff & Witkin's split: a model exposes ``f(t, y) -> dy/dt``
(:mod:`~course_lib.fields`, :mod:`~course_lib.systems`, :mod:`~course_lib.forces`,
:mod:`~course_lib.springs`), and a solver (:mod:`~course_lib.integrators`) advances any
such ``f`` without knowing the physics.
"""

import importlib

from .implicit import ConvergenceError, NewtonSolver
from .integrators import (
    EVALS_PER_STEP,
    IMPLICIT_METHODS,
    MAX_STEPS,
    METHODS,
    NEWTONIAN_METHODS,
    ORDER,
    BlowUpError,
    Trajectory,
    backward_euler,
    forward_euler,
    get_stepper,
    heun,
    integrate,
    midpoint,
    rk4,
    step,
    symplectic_euler,
    time_grid,
    trapezoidal,
    velocity_verlet,
)
from .stability import amplification_factor, is_stable, max_stable_dt
from .systems import NewtonianSystem, newtonian, split_particles, split_state, stack_state

#: Submodules loaded on first use (``cl.sph``), so that ``import course_lib`` stays cheap:
#: a sandboxed grading run or a kernel that needs only the integrators does not load
#: SciPy's sparse solvers.
_LAZY = frozenset({
    "baraff_witkin", "boids", "cloth", "collisions", "events", "fields", "flock_measures",
    "forces", "hair", "implicit", "largestep", "neighbors", "particles", "rigid", "sph",
    "springs", "stability", "statics", "steppers", "strands", "systems", "timegrid",
})


def __getattr__(name: str):
    """A submodule of :data:`_LAZY`, imported on first access (PEP 562)."""
    if name in _LAZY:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | _LAZY)


__all__ = [
    "EVALS_PER_STEP",
    "IMPLICIT_METHODS",
    "MAX_STEPS",
    "METHODS",
    "NEWTONIAN_METHODS",
    "ORDER",
    "BlowUpError",
    "ConvergenceError",
    "NewtonSolver",
    "NewtonianSystem",
    "Trajectory",
    "amplification_factor",
    "backward_euler",
    "baraff_witkin",
    "boids",
    "cloth",
    "collisions",
    "events",
    "fields",
    "forces",
    "forward_euler",
    "get_stepper",
    "hair",
    "heun",
    "implicit",
    "integrate",
    "is_stable",
    "largestep",
    "max_stable_dt",
    "midpoint",
    "neighbors",
    "newtonian",
    "particles",
    "rigid",
    "rk4",
    "sph",
    "split_particles",
    "split_state",
    "springs",
    "stability",
    "stack_state",
    "statics",
    "step",
    "steppers",
    "strands",
    "symplectic_euler",
    "systems",
    "time_grid",
    "timegrid",
    "trapezoidal",
    "velocity_verlet",
]
__version__ = "0.1.0"

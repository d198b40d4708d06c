"""Notebook 12 (constraints and large steps): the frame widget's computation.

The widget (:func:`~course_lib.lessons.nb12_drawings.frame_explorer`) runs one 1/60 s frame
of a 32 × 32 sheet in mid-swing with the chosen method, stiffness and iterations
(:func:`frame_experiment`) and compares its peak structural strain with the converged
implicit Euler frame. A widget must answer within 100 ms, also the first time a student
picks a stiffness, so what a stiffness needs before its first frame is made once and
stored with the course (``nb12_widget_states.npz``, by :func:`make_widget_states`): the
start state, the sheet after 15 frames of fast mass-springs from rest
(:func:`~course_lib.lessons.nb12_constraints.swinging_state`), and the converged frame's
peak strain (:func:`converged_peak`: 1,600 L-BFGS iterations, within 0.1 % of 3,200's).
The tests make both again and compare. Building the widget loads them and factors fast
mass-springs' matrix for every stiffness (:func:`warm_up`).

Lesson layer: imports the core and the lesson's compute module.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from .. import cloth
from ..forces import G_EARTH
from ..largestep import FactorCache, FastMassSpring
from . import nb12_constraints as lesson

#: The widget's grid, its stiffness multiples, and the stored start states and peaks.
WIDGET_N, WIDGET_FACTORS = 32, (1.0, 10.0, 100.0, 1000.0)
STATES = Path(__file__).with_name("nb12_widget_states.npz")
#: L-BFGS iterations (memory 8) of the converged frame (see :func:`converged_peak`).
CONVERGED_ITERATIONS = 1600


def converged_peak(c: cloth.Cloth, x, v, iterations: int = CONVERGED_ITERATIONS) -> float:
    """Peak structural strain (a fraction) after one implicit Euler step of 1/60 s from
    ``(x, v)``, solved by ``iterations`` L-BFGS iterations (memory 8)."""
    solver = FastMassSpring(c.network, c.mass, pinned=c.pinned, gravity=G_EARTH,
                            iterations=iterations, memory=8)
    x1, _ = solver.step(x, v, 1 / 60)
    return float(c.network.select("struct").strain(x1).max())


def make_widget_states(path: Path | None = STATES, factors=WIDGET_FACTORS) -> dict:
    """Compute (about 10 s) and store in ``path`` (unless ``None``) what the widget needs
    per stiffness: ``{factor: (x, v, peak)}``, start positions and velocities (N, 3) and
    the converged frame's peak strain."""
    out = {}
    for factor in factors:
        c, x, v = lesson.swinging_state(WIDGET_N, float(factor))
        out[float(factor)] = (x, v, converged_peak(c, x, v))
    if path is not None:
        np.savez_compressed(path, factors=np.array(list(out)),
                            x=np.array([s[0] for s in out.values()]),
                            v=np.array([s[1] for s in out.values()]),
                            peak=np.array([s[2] for s in out.values()]))
    return out


@lru_cache(maxsize=1)
def widget_states() -> dict:
    """The stored ``{factor: (x, v, peak)}`` of :func:`make_widget_states`."""
    with np.load(STATES) as data:
        return {float(f): (data["x"][k], data["v"][k], float(data["peak"][k]))
                for k, f in enumerate(data["factors"])}


@lru_cache(maxsize=8)
def _sheet(stiffness: float) -> tuple[cloth.Cloth, FactorCache]:
    return lesson.scene(WIDGET_N, stiffness), FactorCache()


def warm_up() -> None:
    """Load the stored states and factor fast mass-springs' matrix for every stiffness, so
    that no first frame pays for either."""
    widget_states()
    for stiffness in WIDGET_FACTORS:
        c, cache = _sheet(stiffness)
        FastMassSpring(c.network, c.mass, pinned=c.pinned, cache=cache).system(1 / 60)


@dataclass
class FrameResult:
    """One 1/60 s frame of the widget: start and end positions, strain per spring, peak
    structural strain against the converged frame's, and the verdict."""

    params: dict
    cloth: cloth.Cloth
    x_start: np.ndarray
    x_end: np.ndarray
    strain: np.ndarray
    peak: float
    reference_peak: float
    work: int
    stable: bool
    verdict: str


def frame_experiment(method: str = "fast_mass_spring", stiffness: float = 100.0,
                     iterations: int = 10) -> FrameResult:
    """The widget's computation: one 1/60 s frame from the swinging 32² sheet (stiffness ×
    300 N/m, one of :data:`WIDGET_FACTORS`) with ``iterations`` meaning substeps
    (symplectic Euler), the CG cap (Baraff–Witkin), L-BFGS iterations (fast mass-springs)
    or small steps of one sweep (XPBD); compared with the converged implicit Euler frame."""
    stiffness = float(stiffness)
    if stiffness not in WIDGET_FACTORS:
        raise ValueError(f"stiffness must be one of {WIDGET_FACTORS}, got {stiffness!r}")
    c, cache = _sheet(stiffness)
    x, v, ref = widget_states()[stiffness]
    its = int(iterations)
    kw = {"symplectic_euler": {"substeps": its}, "baraff_witkin": {"iterations": its},
          "fast_mass_spring": {"iterations": its, "options": {"cache": cache}},
          "xpbd": {"options": {"substeps": its}}}.get(method)
    if kw is None:
        raise ValueError(f"method must be one of {cloth.METHODS}, got {method!r}")
    run = cloth.simulate(c, method, frames=1, fps=60, x0=x, v0=v, **kw)
    x1 = run.x[-1]
    strain = c.network.strain(x1) if run.stable else np.full(c.network.n_springs, np.nan)
    peak = float(np.nanmax(strain[c.network.kind == "struct"])) if run.stable else np.nan
    verdict = (f"peak strain {100 * peak:.2f} % (converged implicit Euler {100 * ref:.2f} %)"
               if run.stable else f"blew up: {its} steps of {1e3 / 60 / its:.2f} ms are too long")
    return FrameResult({"method": method, "stiffness": stiffness, "iterations": its,
                        "n": WIDGET_N}, c, x, x1, strain, peak, ref, its, run.stable, verdict)

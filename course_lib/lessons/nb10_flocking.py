"""Notebook 10 (flocking): flock runs, the alignment relaxation, a predator, and the widget.

Holds the pure computations of the notebook: :func:`run_flock` (boids from a random start,
with order parameters over time; the computation behind the widget), :func:`relaxation`
(alignment alone on a fully connected flock, against its exact geometric decay),
:func:`chase` (a predator hunting the flock), :func:`neighbour_timings` (all pairs against
the k-d tree); and the widget view :func:`flock_explorer` (drawings in
:mod:`course_lib.lessons.nb10_drawings`). Built on :mod:`course_lib.boids`; the core never
imports this module.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .. import boids
from ..boids import Rules

#: The notebook's flock: 150 boids in a periodic 20 m square, 75 steps of 0.2 s.
N_BOIDS, BOX, DT, STEPS = 150, 20.0, 0.2, 75


@dataclass
class FlockRun:
    """Result of :func:`run_flock`."""

    t: np.ndarray              # time of each step's end (s)
    polarization: np.ndarray   # order parameter after each step
    t_nn: np.ndarray           # times at which the nearest-neighbour distance was measured (s)
    nn: np.ndarray             # mean nearest-neighbour distance (m)
    x: np.ndarray              # final positions (m), (N, 2)
    v: np.ndarray              # final velocities (m/s), (N, 2)
    rules: Rules
    reversal: float            # mean cosine between the last two velocities of each boid
    random_polarization: float
    random_nn: float


def run_flock(separation: float = 0.3, alignment: float = 2.0, cohesion: float = 1.0, *,
              n: int = N_BOIDS, box: float = BOX, dt: float = DT, steps: int = STEPS,
              seed: int = 2026, nn_every: int = 5, method: str = "tree") -> FlockRun:
    """Run ``n`` boids from a seeded random start with the three weights; record the
    polarization every step and the mean nearest-neighbour distance every ``nn_every``."""
    rules = Rules(separation=separation, alignment=alignment, cohesion=cohesion, box=box)
    rng = np.random.default_rng(seed)
    x, v = boids.random_flock(n, box, 1.0, rng)
    pol = np.empty(steps)
    t_nn, nn = [0.0], [boids.nearest_distances(x, box).mean()]
    v_prev = v
    for k in range(steps):
        v_prev = v
        x, v = boids.step(x, v, dt, rules, method)
        pol[k] = boids.polarization(v)
        if (k + 1) % nn_every == 0:
            t_nn.append((k + 1) * dt)
            nn.append(boids.nearest_distances(x, box).mean())
    u0 = v_prev / np.linalg.norm(v_prev, axis=1, keepdims=True)
    u1 = v / np.linalg.norm(v, axis=1, keepdims=True)
    return FlockRun(dt * np.arange(1, steps + 1), pol, np.array(t_nn), np.array(nn), x, v, rules,
                    float(np.mean(np.sum(u0 * u1, axis=1))), boids.random_polarization(n),
                    boids.random_nearest_distance(n, box))


def relaxation(w: float, dt: float = 0.1, n: int = 20, steps: int = 30, seed: int = 7):
    """Alignment alone on a fully connected flock without speed limits: every boid moves
    its velocity towards the mean of the other ``n − 1``. Returns the RMS deviation from
    the mean velocity after each step (m/s), its exact value
    ``|1 − w dt n/(n−1)|^k × initial``, and the largest error of the mean velocity."""
    rules = Rules(separation=0.0, alignment=w, cohesion=0.0, radius=1e9, view_angle=2 * np.pi,
                  min_speed=0.0, max_speed=np.inf)
    rng = np.random.default_rng(seed)
    x, v = boids.random_flock(n, 5.0, 1.0, rng)
    mean0 = v.mean(axis=0)
    rms = [np.sqrt(np.mean(np.sum((v - mean0) ** 2, axis=1)))]
    drift = 0.0
    for _ in range(steps):
        x, v = boids.step(x, v, dt, rules, "all_pairs")
        rms.append(np.sqrt(np.mean(np.sum((v - v.mean(axis=0)) ** 2, axis=1))))
        drift = max(drift, float(np.abs(v.mean(axis=0) - mean0).max()))
    factor = 1.0 - w * dt * n / (n - 1)
    return np.array(rms), rms[0] * np.abs(factor) ** np.arange(steps + 1), drift


@dataclass
class ChaseRun:
    """Result of :func:`chase`."""

    t: np.ndarray          # time (s)
    closest: np.ndarray    # distance from the predator to the nearest boid (m)
    x: np.ndarray          # boids at the end (m)
    v: np.ndarray
    predator: np.ndarray   # predator at the end (m)
    path: np.ndarray       # predator positions over the last seconds (m), (k, 2)


def chase(flee_strength: float = 3.0, flee_radius: float = 3.0, predator_speed: float = 1.8,
          warmup: int = 100, steps: int = 75, seed: int = 2026) -> ChaseRun:
    """A predator enters a formed flock and heads for the nearest boid at
    ``predator_speed`` (m/s, between the boids' cruising and top speeds); boids within
    ``flee_radius`` (m)
    accelerate away with :func:`course_lib.boids.flee`."""
    rules = Rules(box=BOX)
    rng = np.random.default_rng(seed)
    x, v = boids.random_flock(N_BOIDS, BOX, 1.0, rng)
    for _ in range(warmup):
        x, v = boids.step(x, v, DT, rules)
    p = np.mod(x.mean(axis=0) + 5.0, BOX)               # enters 5 m off the flock's centroid
    closest, path = np.empty(steps), []
    for k in range(steps):
        d = boids.wrap(x - p, BOX)
        dist = np.linalg.norm(d, axis=1)
        target = d[np.argmin(dist)]
        p = np.mod(p + DT * predator_speed * target / max(np.linalg.norm(target), 1e-12), BOX)
        extra = boids.flee(x, p, flee_radius, flee_strength, BOX)
        x, v = boids.step(x, v, DT, rules, extra=extra)
        closest[k] = np.linalg.norm(boids.wrap(x - p, BOX), axis=1).min()
        path.append(p)
    return ChaseRun(DT * np.arange(1, steps + 1), closest, x, v, p, np.array(path[-30:]))


def neighbour_timings(sizes, density: float = 0.75, repeats: int = 3, seed: int = 2026):
    """Best-of-``repeats`` wall time (s) of one flock step with all pairs and with the
    k-d tree, for random flocks of each size at ``density`` boids per m²; all pairs is
    skipped (NaN) above 1600 boids. Also checks that both give the same step."""
    rng = np.random.default_rng(seed)
    out = {"all_pairs": [], "tree": []}
    for n in sizes:
        box = float(np.sqrt(n / density))
        rules = Rules(box=box)
        x, v = boids.random_flock(n, box, 1.0, rng)
        results = {}
        for method in out:
            if method == "all_pairs" and n > 1600:
                out[method].append(np.nan)
                continue
            best = np.inf
            for _ in range(repeats):
                t0 = time.perf_counter()
                results[method] = boids.step(x, v, DT, rules, method)
                best = min(best, time.perf_counter() - t0)
            out[method].append(best)
        if len(results) == 2 and not np.allclose(results["tree"][1], results["all_pairs"][1],
                                                 rtol=0, atol=1e-12):
            raise AssertionError(f"all pairs and tree disagree for n = {n}")
    return {k: np.array(val) for k, val in out.items()}


def flock_explorer(separation: float = 0.3, alignment: float = 2.0, cohesion: float = 1.0):
    """An :class:`~course_lib.widgets.ExplorerView` over :func:`run_flock` with one
    slider per rule weight."""
    import ipywidgets as w

    from ..widgets import ExplorerView
    from .nb10_drawings import FlockPlot

    def slider(label, value, hi):
        return w.FloatSlider(value=value, min=0.0, max=hi, step=0.1, description=label,
                             continuous_update=False, style={"description_width": "initial"})

    controls = {"separation": slider("separation (m²/s²)", separation, 5.0),
                "alignment": slider("alignment (1/s)", alignment, 10.0),
                "cohesion": slider("cohesion (1/s²)", cohesion, 3.0)}
    return ExplorerView(run_flock, FlockPlot(N_BOIDS, BOX, DT * STEPS), controls)

"""Notebook 10 (flocking): flock runs, the alignment relaxation, a predator, and the widget.

Holds :func:`run_flock` (boids from a random start, with order parameters over time; the
computation behind the widget), :func:`neighbour_timings` (all pairs against the k-d
tree), :func:`ring_radius` (where separation and cohesion balance on a ring of boids, the
answer of Exercise 2) and the widget view :func:`flock_explorer` (drawings in
:mod:`course_lib.lessons.nb10_drawings`). The studies over many seeds (ensembles, the flock
under two roundings, the alignment relaxation, the predator, the pillars) are in
:mod:`course_lib.lessons.nb10_studies`. Built on :mod:`course_lib.boids`; the core never
imports this module.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .. import boids
from ..boids import Rules
from ..neighbors import squared_norms

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
    turn: np.ndarray           # after each step: mean cosine between each boid's headings
                               # before and after it (1: steady, −1: reversing)
    snapshot: tuple | None = None   # (x, v) after ``snapshot_at`` steps, if asked for


def run_flock(separation: float = 0.3, alignment: float = 2.0, cohesion: float = 1.0, *,
              n: int = N_BOIDS, box: float = BOX, dt: float = DT, steps: int = STEPS,
              seed: int = 2026, nn_every: int = 5, method: str = "tree",
              snapshot_at: int | None = None) -> FlockRun:
    """Run ``n`` boids from a seeded random start with the three weights; record the
    polarization every step, the mean nearest-neighbour distance every ``nn_every``, and
    the state after ``snapshot_at`` steps if asked."""
    rules = Rules(separation=separation, alignment=alignment, cohesion=cohesion, box=box)
    rng = np.random.default_rng(seed)
    x, v = boids.random_flock(n, box, 1.0, rng)
    t_nn, nn = [0.0], [boids.nearest_distances(x, box).mean()]
    vs, snapshot = [v], None
    for k in range(steps):
        x, v = boids.step(x, v, dt, rules, method)
        vs.append(v)
        if k + 1 == snapshot_at:
            snapshot = (x, v)
        if (k + 1) % nn_every == 0:
            t_nn.append((k + 1) * dt)
            nn.append(boids.nearest_distances(x, box).mean())
    # the headings of all steps at once (row by row the same bits as step by step)
    vs = np.stack(vs)
    u = vs / np.linalg.norm(vs, axis=2, keepdims=True)         # speeds >= min_speed > 0
    pol = np.sqrt(squared_norms(u[1:].mean(axis=1)))
    turn = np.mean(np.sum(u[:-1] * u[1:], axis=2), axis=1)
    return FlockRun(dt * np.arange(1, steps + 1), pol, np.array(t_nn), np.array(nn), x, v, rules,
                    float(turn[-1]), boids.random_polarization(n),
                    boids.random_nearest_distance(n, box), turn, snapshot)


def neighbour_timings(sizes, density: float = 0.75, repeats: int = 3, seed: int = 2026,
                      largest_all_pairs: int = 700):
    """Median CPU time (s) of one flock step with all pairs and with the k-d tree over
    ``repeats`` runs, for random flocks of each size at ``density`` boids per m²; all pairs
    is skipped (NaN) above ``largest_all_pairs`` boids. Also checks that both give the same
    step (to round-off: the neighbour sums run in different orders)."""
    rng = np.random.default_rng(seed)
    out = {"all_pairs": [], "tree": []}
    for n in sizes:
        box = float(np.sqrt(n / density))
        rules = Rules(box=box)
        x, v = boids.random_flock(n, box, 1.0, rng)
        results = {}
        for method in out:
            if method == "all_pairs" and n > largest_all_pairs:
                out[method].append(np.nan)
                continue
            times = []
            for _ in range(repeats):
                t0 = time.process_time()
                results[method] = boids.step(x, v, DT, rules, method)
                times.append(time.process_time() - t0)
            out[method].append(float(np.median(times)))
        if len(results) == 2 and not np.allclose(results["tree"][1], results["all_pairs"][1],
                                                 rtol=0, atol=1e-12):
            raise AssertionError(f"all pairs and tree disagree for n = {n}")
    return {k: np.array(val) for k, val in out.items()}


def ring_radius(n: int, separation: float, cohesion: float) -> float:
    """Radius (m) of the ring of ``n`` evenly spaced boids, all flying the same velocity and
    all in view of each other, on which separation (``w_s``, m²/s²) and cohesion (``w_c``,
    1/s²) cancel: each neighbour's push ``d/|d|²`` has the radial part ``1/(2r)`` (a chord
    of length ``|d|`` reaches ``|d|²/(2r)`` towards the centre), so the ``n − 1`` pushes add
    to ``w_s (n − 1)/(2r)`` outwards; cohesion pulls towards the centre of the other
    ``n − 1``, ``n/(n − 1)`` times as far as the ring's centre, ``w_c r n/(n − 1)``. Equal
    when ``r² = w_s (n − 1)² / (2 n w_c)``; a pair (``n = 2``) sits ``√(w_s/w_c)`` apart."""
    if int(n) != n or n < 2:
        raise ValueError(f"n must be a whole number of boids >= 2, got {n!r}")
    if not (separation > 0 and cohesion > 0):
        raise ValueError(f"separation and cohesion must be > 0, got {separation!r} and {cohesion!r}")
    return float(np.sqrt(separation * (n - 1) ** 2 / (2.0 * n * cohesion)))


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

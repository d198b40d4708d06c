"""Notebook 10 (flocking): the studies over many seeds, and the flock under two roundings.

A flock is chaotic: two runs that start one unit in the last place apart end as different
flocks. So the notebook quotes what holds over an ensemble of seeds (how many of 8 runs
order, orderings between settings), never one run's digits. Holds :func:`ensemble`
(order parameters of :func:`~course_lib.lessons.nb10_flocking.run_flock` over seeds),
:func:`twins` (the same flock under second, equally valid roundings),
:func:`relaxation` (alignment alone against its exact geometric decay, with a round-off
bound), :func:`chase` (a predator, with and without the flee rule) and :func:`pillars`
(steering to avoid obstacles). Built on :mod:`course_lib.boids`; the drawings are in
:mod:`course_lib.lessons.nb10_figures`. The core never imports this module.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from .. import boids
from ..boids import Rules
from ..neighbors import squared_norms
from .nb10_flocking import BOX, DT, N_BOIDS, STEPS, run_flock

#: The seeds of every ensemble in the notebook.
SEEDS = tuple(range(8))


@dataclass
class Ensemble:
    """Order parameters of one setting over :data:`SEEDS`, one entry per seed."""

    t: np.ndarray             # time of each step's end (s)
    polarization: np.ndarray  # (seeds, steps)
    t_nn: np.ndarray          # times of the nearest-neighbour measurements (s)
    nn: np.ndarray            # (seeds, len(t_nn)) mean nearest-neighbour distance (m)
    turn: np.ndarray          # (seeds, steps) mean cosine between successive headings
    t_order: np.ndarray       # (seeds,) first time the polarization exceeds 0.5 (inf: never)
    random_polarization: float
    random_nn: float
    snapshots: list | None = None   # per seed, (x, v) after ``snapshot_at`` steps
    finals: list | None = None      # per seed, (x, v) at the end of the run

    def until(self, seconds: float) -> Ensemble:
        """The same runs cut after ``seconds`` (the first steps of longer runs are the
        shorter runs: the same seeds, the same rules)."""
        k = round(seconds / (self.t[1] - self.t[0]))
        m = int(np.searchsorted(self.t_nn, seconds + 1e-9))
        above = self.polarization[:, :k] > 0.5
        t_order = np.where(above.any(axis=1), self.t[np.argmax(above, axis=1)], np.inf)
        return Ensemble(self.t[:k], self.polarization[:, :k], self.t_nn[:m], self.nn[:, :m],
                        self.turn[:, :k], t_order, self.random_polarization, self.random_nn)

    @property
    def reversal(self) -> np.ndarray:
        """Mean cosine between each boid's last two headings, per seed (−1: reversing)."""
        return self.turn[:, -1]

    @property
    def final(self) -> np.ndarray:
        """Polarization at the end of each run."""
        return self.polarization[:, -1]

    @property
    def spacing(self) -> np.ndarray:
        """Mean nearest-neighbour distance (m) at the end of each run."""
        return self.nn[:, -1]


def ensemble(seeds=SEEDS, **kw) -> Ensemble:
    """:func:`run_flock` with the keyword arguments ``kw`` for every seed in ``seeds``."""
    runs = [run_flock(seed=s, **kw) for s in seeds]
    pol = np.array([r.polarization for r in runs])
    above = pol > 0.5
    t = runs[0].t
    t_order = np.where(above.any(axis=1), t[np.argmax(above, axis=1)], np.inf)
    return Ensemble(t, pol, runs[0].t_nn, np.array([r.nn for r in runs]),
                    np.array([r.turn for r in runs]), t_order, runs[0].random_polarization,
                    runs[0].random_nn, [r.snapshot for r in runs], [(r.x, r.v) for r in runs])


def rms_distance(xa, xb, box: float) -> float:
    """Root-mean-square distance (m) between two flocks, boid by boid (minimum image)."""
    return float(np.sqrt(np.mean(squared_norms(boids.wrap(xb - xa, box)))))


def twins(seed: int = 0, steps: int = 650, hows=("ulp", "order"), n: int = N_BOIDS,
          box: float = BOX, dt: float = DT) -> dict:
    """The same flock run as in the notebook and, beside it, under second roundings,
    equally valid: ``"ulp"`` moves one coordinate of one boid by one unit in the last place
    (``np.nextafter``); ``"order"`` numbers the boids in reverse, so that every boid's
    neighbour terms are summed in another order (the same rules, the same start). Returns,
    per twin, the times (s), the RMS distance between the two flocks after each step (m)
    and the polarization of each run after each step, shape ``(2, steps)``; the flock
    itself is run once for all twins."""
    for how in hows:
        if how not in ("ulp", "order"):
            raise ValueError(f"how must be 'ulp' or 'order', got {how!r}")
    rules = Rules(box=box)
    x, v = boids.random_flock(n, box, 1.0, np.random.default_rng(seed))
    states, backs = {}, {}
    for how in hows:
        if how == "ulp":
            xb, vb, backs[how] = x.copy(), v.copy(), slice(None)
            xb[0, 0] = np.nextafter(xb[0, 0], np.inf)
        else:
            backs[how] = slice(None, None, -1)       # boid k of the twin is boid n - 1 - k
            xb, vb = x[backs[how]].copy(), v[backs[how]].copy()
        states[how] = (xb, vb)
    xa, va = x, v
    distance = {how: np.empty(steps) for how in hows}
    pol = {how: np.empty((2, steps)) for how in hows}
    for k in range(steps):
        xa, va = boids.step(xa, va, dt, rules)
        own = boids.polarization(va)
        for how in hows:
            xb, vb = states[how] = boids.step(*states[how], dt, rules)
            distance[how][k] = rms_distance(xa, xb[backs[how]], box)
            pol[how][:, k] = own, boids.polarization(vb)
    t = dt * np.arange(1, steps + 1)
    return {how: (t, distance[how], pol[how]) for how in hows}


def divergence(seed: int = 0, steps: int = 650, how: str = "ulp", **kw):
    """One twin of :func:`twins`: ``(t, distance, polarizations)``."""
    return twins(seed, steps, (how,), **kw)[how]


def growth_rate(t, distance, lo: float = 1e-13, hi: float = 1e-3) -> float:
    """Exponential growth rate (1/s) of ``distance`` where it lies between ``lo`` and
    ``hi`` m: the slope of a least-squares line through ``ln distance`` against ``t``."""
    band = (distance > lo) & (distance < hi)
    return float(np.polyfit(np.asarray(t)[band], np.log(distance[band]), 1)[0])


def relaxation(w: float, dt: float = 0.1, n: int = 20, steps: int = 30, seed: int = 7):
    """Alignment alone on a fully connected flock without speed limits: every boid moves
    its velocity towards the mean of the other ``n − 1``, and each deviation from the mean
    velocity is multiplied by ``f = 1 − w dt n/(n−1)`` per step. Returns the RMS deviation
    after each step (m/s), its exact value ``|f|^k × initial``, the largest drift of the
    mean velocity (m/s), and a round-off bound on ``|measured − exact|`` per step (m/s):
    each step rounds each velocity component by at most ``(n + 8) ε max|v|`` (a sum of
    ``n − 1`` terms, then a few operations), and errors already made are multiplied by
    ``f`` like the deviations, so the bound is ``2√2 (n + 8) ε Σ_m |f|^{k−1−m} V_m``
    plus the rounding of the measurement itself, ``V_m`` the largest speed at step ``m``."""
    rules = Rules(separation=0.0, alignment=w, cohesion=0.0, radius=1e9, view_angle=2 * np.pi,
                  min_speed=0.0, max_speed=np.inf)
    x, v = boids.random_flock(n, 5.0, 1.0, np.random.default_rng(seed))
    mean0 = v.mean(axis=0)
    rms, speeds, drift = [np.sqrt(np.mean(squared_norms(v - mean0)))], [np.abs(v).max()], 0.0
    for _ in range(steps):
        x, v = boids.step(x, v, dt, rules, "all_pairs")
        rms.append(np.sqrt(np.mean(squared_norms(v - v.mean(axis=0)))))
        speeds.append(np.abs(v).max())
        drift = max(drift, float(np.abs(v.mean(axis=0) - mean0).max()))
    f = 1.0 - w * dt * n / (n - 1)
    per_step = 2.0 * np.sqrt(2.0) * (n + 8) * np.finfo(float).eps * np.array(speeds)
    bound = np.empty(steps + 1)
    carried = 0.0
    for k in range(steps + 1):
        bound[k] = carried + per_step[k]
        carried = abs(f) * carried + per_step[k]
    return np.array(rms), rms[0] * np.abs(f) ** np.arange(steps + 1), drift, bound


@dataclass
class Chase:
    """Result of :func:`chase` for one seed."""

    start: float                # distance from the predator's entry to the nearest boid (m)
    closest: dict               # flee strength -> distance to the nearest boid per step (m)
    x: dict                     # flee strength -> boids at the end (m)
    v: dict
    path: dict                  # flee strength -> predator positions (m), (steps, 2)


def chase(seed: int = 0, strengths=(3.0, 0.0), flee_radius: float = 3.0,
          predator_speed: float = 1.8, warmup: int = 100, steps: int = 75,
          formed: tuple | None = None) -> Chase:
    """A flock forms for ``warmup`` steps (or is given: ``formed = (x, v)``, the state of
    the same seed's run after ``warmup`` steps); then a predator enters at the point of a
    1 m grid farthest from every boid and flies at ``predator_speed`` (m/s) towards the
    nearest boid, once per flee strength (m²/s²; 0: no flee rule), from the same formed
    flock."""
    rules = Rules(box=BOX)
    if formed is None:
        x, v = boids.random_flock(N_BOIDS, BOX, 1.0, np.random.default_rng(seed))
        for _ in range(warmup):
            x, v = boids.step(x, v, DT, rules)
    else:
        x, v = formed
    g = np.arange(0.5, BOX, 1.0)
    grid = np.stack(np.meshgrid(g, g), axis=-1).reshape(-1, 2)
    gap, _ = cKDTree(np.mod(x, BOX) % BOX, boxsize=BOX).query(grid)
    entry = grid[np.argmax(gap)]
    out = Chase(float(gap.max()), {}, {}, {}, {})
    for strength in strengths:
        xs, vs, p = x, v, entry
        closest, path = np.empty(steps), np.empty((steps, 2))
        for k in range(steps):
            d = boids.wrap(xs - p, BOX)
            target = d[np.argmin(squared_norms(d))]
            p = np.mod(p + DT * predator_speed * target / max(np.sqrt(squared_norms(target)), 1e-12), BOX)
            xs, vs = boids.step(xs, vs, DT, rules, extra=boids.flee(xs, p, flee_radius, strength, BOX))
            closest[k] = np.sqrt(squared_norms(boids.wrap(xs - p, BOX)).min())
            path[k] = p
        out.closest[strength], out.x[strength], out.v[strength], out.path[strength] = closest, xs, vs, path
    return out


#: Three round pillars in the notebook's box: centres (m) and radii (m).
PILLARS = (np.array([[5.0, 5.0], [14.0, 8.0], [8.0, 15.0]]), np.array([1.5, 2.0, 1.0]))


def pillar_gaps(x, box: float = BOX) -> np.ndarray:
    """Distance (m) from each boid to the surface of the nearest pillar (negative inside)."""
    c, rho = PILLARS
    return (np.sqrt(squared_norms(boids.wrap(x[:, None, :] - c[None], box))) - rho).min(axis=1)


def pillars(seed: int = 0, strength: float = 6.0, lookahead: float = 3.0,
            clearance: float = 0.5, steps: int = STEPS):
    """Boids among :data:`PILLARS`, from a random start outside them (0.3 m clear), steering
    to avoid them (``strength`` m/s², ``lookahead`` and ``clearance`` m; 0: no rule).
    Returns the fraction of boid-steps spent inside a pillar, the smallest gap to a pillar
    over the run (m), and the final positions and velocities."""
    rules = Rules(box=BOX)
    rng = np.random.default_rng(seed)
    x, v = boids.random_flock(N_BOIDS, BOX, 1.0, rng)
    bad = pillar_gaps(x) < 0.3
    while bad.any():                       # start every boid outside the pillars
        x[bad] = rng.uniform(0.0, BOX, (int(bad.sum()), 2))
        bad = pillar_gaps(x) < 0.3
    inside, smallest = 0, np.inf
    for _ in range(steps):
        extra = boids.avoid(x, v, *PILLARS, lookahead, strength, BOX, clearance) if strength else None
        x, v = boids.step(x, v, DT, rules, extra=extra)
        gaps = pillar_gaps(x)
        inside += int(np.sum(gaps < 0))
        smallest = min(smallest, float(gaps.min()))
    return inside / (steps * N_BOIDS), smallest, x, v

"""Notebook 01 (particles in vector fields): a short flocking demo, vectorised.

Reynolds' boids (1987) in a periodic square: every boid steers by three local rules,
computed for all boids at once from the ``(N, N)`` arrays of offsets between them,

- **separation**: away from neighbours closer than ``r_sep``, weighted by 1/distance²;
- **alignment**: towards the mean velocity of the neighbours within ``radius``;
- **cohesion**: towards the mean position of the same neighbours,

then takes a symplectic Euler step (new velocity first, clamped to a speed range, then
the position with it). :func:`run_flock` returns the whole run and its *polarisation*
``|mean(V/|V|)|`` (1: all boids fly the same way; about √π/(2√N) for N headings at
random, :func:`course_lib.boids.random_polarization`). A flock is chaotic: the last bit of
one number (another CPU's rounding) changes a run's path after some seconds, so
:func:`flock_ensemble` measures what is reproducible, the statistics over many seeds.
Notebook 10 teaches flocking in full; this is the one-screen version notebook 01 shows.

Imports NumPy only (the drawing helper takes a matplotlib Axes); no course_lib core is needed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Default rule weights: separation, alignment, cohesion (1/s², 1/s, 1/s²).
WEIGHTS = (1.0, 1.0, 0.6)


def periodic_offsets(X: np.ndarray, box: float, out=None) -> tuple[np.ndarray, np.ndarray]:
    """``(dx, dy)``: ``dx[..., i, j] = x_j - x_i`` (m) to the nearest periodic image, each
    ``(..., N, N)`` for ``X`` of shape ``(..., N, 2)`` (leading axes: independent flocks).

    Two ``(N, N)`` arrays rather than one ``(N, N, 2)``: every later sum then runs over
    contiguous memory, about twice as fast for a flock of 80. ``out``: optional
    :class:`FlockBuffers` to write into instead of new arrays (same numbers).
    """
    b = FlockBuffers(np.shape(X)) if out is None else out
    x, y = X[..., 0], X[..., 1]
    for c, d in ((x, b.dx), (y, b.dy)):
        np.subtract(c[..., None, :], c[..., :, None], out=d)
        np.divide(d, box, out=b.tmp)           # d -= box * rint(d / box), without temporaries
        np.rint(b.tmp, out=b.tmp)
        b.tmp *= box
        d -= b.tmp
    return b.dx, b.dy


class FlockBuffers:
    """Work arrays of :func:`flock_acceleration` for positions of shape ``(..., N, 2)``:
    float ``dx, dy, tmp, dist2, weight, inv2`` and bool ``near, close``, each ``(..., N, N)``.

    A run reuses one set for every step. Fresh ``(..., N, N)`` temporaries each step cost
    more than the arithmetic: the allocator hands their memory back to the system and
    takes it again (page faults, counted as system CPU time), 3 of the 4 s of 16 flocks of
    80 over 600 steps on Linux.
    """

    def __init__(self, shape: tuple[int, ...]):
        pairs = (*shape[:-1], shape[-2])
        self.dx, self.dy, self.tmp, self.dist2, self.weight, self.inv2 = (
            np.empty(pairs) for _ in range(6))
        self.near, self.close = np.empty(pairs, dtype=bool), np.empty(pairs, dtype=bool)


def flock_acceleration(X, V, box: float = 10.0, radius: float = 1.5, r_sep: float = 0.5,
                       weights=WEIGHTS, buffers: FlockBuffers | None = None) -> np.ndarray:
    """Steering acceleration (m/s²) of every boid, shape ``(..., N, 2)``.

    Parameters
    ----------
    X, V : ndarray, shape (..., N, 2)
        Positions (m) in ``[0, box)²`` and velocities (m/s); leading axes hold independent
        flocks, each computed with the same formulas as alone (equal to round-off: a
        stacked product may add in another order on another processor).
    box : float
        Side of the periodic square (m).
    radius : float
        A boid sees the others closer than this (m); it never counts itself.
    r_sep : float
        Separation acts on neighbours closer than this (m).
    weights : (float, float, float)
        Weights of separation, alignment and cohesion; 0 switches a rule off.
    buffers : FlockBuffers, optional
        Work arrays for ``X``'s shape, reused from call to call (same numbers, less time).
    """
    w_sep, w_ali, w_coh = weights
    V = np.asarray(V, dtype=float)
    X = np.asarray(X, dtype=float)
    b = FlockBuffers(X.shape) if buffers is None else buffers
    dx, dy = periodic_offsets(X, box, out=b)
    dist2 = np.multiply(dx, dx, out=b.dist2)
    dist2 += np.multiply(dy, dy, out=b.tmp)
    near = np.less(dist2, radius**2, out=b.near)
    diagonal = np.arange(near.shape[-1])
    near[..., diagonal, diagonal] = False              # a boid is not its own neighbour
    weight = b.weight
    np.copyto(weight, near)                            # 1.0 for a neighbour, else 0.0
    count = np.count_nonzero(near, axis=-1).astype(float)
    safe = np.maximum(count, 1.0)[..., None]           # a boid alone feels no pull
    out = np.zeros_like(V)
    if w_coh:
        out += w_coh * np.stack((np.einsum("...ij,...ij->...i", weight, dx),
                                 np.einsum("...ij,...ij->...i", weight, dy)), axis=-1) / safe
    if w_ali:
        out += w_ali * np.where(count[..., None] > 0, weight @ V / safe - V, 0.0)
    if w_sep:
        close = np.less(dist2, r_sep**2, out=b.close)
        close &= near
        inv2 = b.inv2
        inv2.fill(0.0)
        np.divide(1.0, dist2, out=inv2, where=close)
        out -= w_sep * np.stack((np.einsum("...ij,...ij->...i", inv2, dx),
                                 np.einsum("...ij,...ij->...i", inv2, dy)), axis=-1)
    return out


@dataclass
class Flock:
    """A boids run: ``t`` ``(n+1,)`` (s), ``X`` and ``V`` ``(n+1, N, 2)`` (m, m/s), the box
    side (m) and the ``polarisation`` ``(n+1,)`` (dimensionless, 0 to 1)."""

    t: np.ndarray
    X: np.ndarray
    V: np.ndarray
    box: float
    polarisation: np.ndarray


def polarisation(V) -> np.ndarray:
    """``|mean over boids of V/|V||``, for velocities of shape ``(..., N, 2)``."""
    V = np.asarray(V, dtype=float)
    headings = V / np.linalg.norm(V, axis=-1, keepdims=True)
    return np.linalg.norm(headings.mean(axis=-2), axis=-1)


def _start(n: int, box: float, speed, seed: int, nudge: float) -> tuple[np.ndarray, np.ndarray]:
    """Seeded random positions in the box and headings at the mean speed, each ``(n, 2)``."""
    rng = np.random.default_rng(seed)
    X = rng.uniform(0.0, box, size=(n, 2))
    X[0, 0] += nudge
    angle = rng.uniform(0.0, 2 * np.pi, size=n)
    V = np.mean(speed) * np.stack((np.cos(angle), np.sin(angle)), axis=-1)
    return X, V


def _fly(X, V, steps: int, dt: float, box: float, weights, speed, keep_positions: bool):
    """``steps`` symplectic Euler steps of the flocks ``X, V`` ``(..., N, 2)``; returns the
    velocities ``(steps+1, ..., N, 2)`` and the positions likewise (or ``None``)."""
    Xs = np.empty((steps + 1, *X.shape)) if keep_positions else None
    Vs = np.empty((steps + 1, *V.shape))
    Vs[0] = V
    if keep_positions:
        Xs[0] = X
    lo, hi = speed
    buffers = FlockBuffers(X.shape)
    for k in range(steps):
        V = V + dt * flock_acceleration(X, V, box, weights=weights, buffers=buffers)
        s = np.linalg.norm(V, axis=-1, keepdims=True)
        V = V * np.clip(s, lo, hi) / np.maximum(s, 1e-12)
        X = (X + dt * V) % box
        Vs[k + 1] = V
        if keep_positions:
            Xs[k + 1] = X
    return Vs, Xs


def run_flock(n: int = 80, steps: int = 600, dt: float = 0.05, box: float = 10.0,
              weights=WEIGHTS, speed=(0.6, 1.5), seed: int = 2026, nudge: float = 0.0) -> Flock:
    """Fly ``n`` boids for ``steps`` steps of ``dt`` (s) from random positions and headings.

    Each step: acceleration from :func:`flock_acceleration`, velocity update, speed clamped
    to ``speed = (min, max)`` (m/s), position update with the new velocity, wrapped into
    the box. Seeded: the same arguments give the same flock on one machine. ``nudge`` (m)
    moves the first boid's start along x, e.g. by 1e-13 m, to see what a change in the last
    digit (another machine's rounding) does to a run.
    """
    _check(n, steps, dt, box)
    Vs, Xs = _fly(*_start(n, box, speed, seed, nudge), steps, dt, box, weights, speed, True)
    return Flock(dt * np.arange(steps + 1), Xs, Vs, box, polarisation(Vs))


def _check(n, steps, dt, box) -> None:
    if n < 2 or steps < 1 or not dt > 0 or not box > 0:
        raise ValueError(f"need n >= 2, steps >= 1, dt > 0 and box > 0; got n={n}, "
                         f"steps={steps}, dt={dt}, box={box}")


def flock_ensemble(seeds, weights=WEIGHTS, n: int = 80, steps: int = 600, dt: float = 0.05,
                   average_from: float = 15.0, nudge: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Polarisation of one flock per seed, averaged over ``t >= average_from`` (s).

    Returns ``(curves, late)``: ``curves`` of shape ``(len(seeds), steps + 1)``, the
    polarisation against time of each run, and ``late`` of shape ``(len(seeds),)``, each
    run's time average over the last part. A single chaotic run is no measurement; the
    spread of ``late`` over seeds says how much one run can vary. ``nudge`` (m) moves the
    first boid of every start (see :func:`run_flock`): the ensemble another machine's
    rounding might give. All flocks fly at once, as one stack of arrays (each one's numbers
    are those :func:`run_flock` gives it, to round-off over the first seconds, before the
    chaos amplifies a different last digit: a test checks it).
    """
    box, speed = 10.0, (0.6, 1.5)
    _check(n, steps, dt, box)
    starts = [_start(n, box, speed, s, nudge) for s in seeds]
    if not starts:
        raise ValueError("seeds must hold at least one seed")
    X, V = (np.stack(part) for part in zip(*starts, strict=True))
    Vs, _ = _fly(X, V, steps, dt, box, weights, speed, False)
    curves = np.ascontiguousarray(polarisation(np.moveaxis(Vs, 0, 1)))   # rows, as one by one
    late = curves[:, round(average_from / dt):].mean(axis=1)
    return curves, late


def draw_flock(ax, flock: Flock, step: int, color: str = "#1f4e8c") -> None:
    """Arrows at the boids' positions, along their headings, at one step of a run."""
    X, V = flock.X[step], flock.V[step]
    U = V / np.linalg.norm(V, axis=1, keepdims=True)
    ax.quiver(X[:, 0], X[:, 1], U[:, 0], U[:, 1], color=color, angles="xy", scale=22,
              width=0.007, headwidth=4)
    ax.set(xlim=(0, flock.box), ylim=(0, flock.box), aspect="equal", xlabel="x (m)",
           ylabel="y (m)")
    # no polarisation in the title: one chaotic run's value is no measurement (the ensemble is)
    ax.set_title(f"t = {flock.t[step]:.0f} s", fontsize=10)

"""How ordered a flock is, and what chance alone gives (notebooks 01 and 10).

Holds the headings of velocities without overflow (:func:`_headings`, shared with
:mod:`course_lib.boids`), the order parameters of Vicsek et al. (1995) and of spacing,
:func:`polarization` and :func:`nearest_distances`, their values for boids placed at random
(:func:`random_polarization`, :func:`random_nearest_distance`), and such a random flock
(:func:`random_flock`). :mod:`course_lib.boids` re-exports all of them. Core module:
imports NumPy, SciPy and :mod:`course_lib.neighbors` only.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree
from scipy.special import beta, betainc

from . import neighbors
from ._validate import nonnegative, positive_finite, positive_int, real_array
from .neighbors import squared_norms


def _headings(v):
    """Unit vectors along ``v`` (zero rows stay zero) and the speeds, without overflow or
    underflow: each row is first divided by its largest component."""
    v = np.asarray(v, dtype=float)
    top = np.max(np.abs(v), axis=-1, keepdims=True)
    u = v / np.where(top > 0, top, 1.0)
    size = np.sqrt(squared_norms(u))[..., None]          # 1 to √dim, or 0
    with np.errstate(over="ignore"):
        return u / np.where(size > 0, size, 1.0), top * size


def polarization(v) -> float:
    """Order parameter ``|(1/N) Σ v_i/|v_i||`` in [0, 1]: 1 when all head the same way
    (a boid at rest has no heading and counts as zero)."""
    return float(np.sqrt(squared_norms(np.mean(_headings(real_array("v", v, (None, None)))[0], axis=0))))


def nearest_distances(x, box: float | None = None) -> np.ndarray:
    """Distance (m) from each boid to its nearest neighbour (periodic if ``box``)."""
    pts = neighbors.wrap_positions(real_array("x", x, (None, None)), box)
    dist, _ = cKDTree(pts, boxsize=box).query(pts, k=2)
    return dist[:, 1]


def random_polarization(n: int) -> float:
    """Expected polarization of ``n`` independent uniformly random 2D headings, to
    ``O(1/n)``: the sum of ``n`` unit vectors is nearly Gaussian with variance ``n/2``
    per axis, so its length is Rayleigh with mean ``√(π n)/2``: ``√π / (2 √n)``."""
    return float(np.sqrt(np.pi) / (2.0 * np.sqrt(positive_int("n", n))))


def random_nearest_distance(n: int, box: float) -> float:
    """Exact mean nearest-neighbour distance (m) of ``n`` uniform random points in a
    periodic square of side ``box`` (``n >= 2``): ``∫ (1 − π r²/A)^{n−1} dr`` over ``r <= box/2``
    (where the disc fits; the chance of no neighbour nearer, (1 − π/4)^{n−1}, is 1e-200 at n = 300); with
    ``u = π r²/A``, ``½ √(A/π) B(½, n) I_{π/4}(½, n)``, close to ``1/(2√ρ)`` for large ``n``."""
    n, area = positive_int("n", n), positive_finite("box", box) ** 2
    if n < 2:
        raise ValueError(f"n must be at least 2 (one point has no nearest neighbour), got {n}")
    return float(0.5 * np.sqrt(area / np.pi) * beta(0.5, n) * betainc(0.5, n, np.pi / 4))


def random_flock(n: int, box: float, speed: float, rng: np.random.Generator):
    """``n`` boids uniform in the square ``[0, box)²`` with random headings at ``speed``."""
    n, box, speed = positive_int("n", n), positive_finite("box", box), nonnegative("speed", speed)
    x, theta = rng.uniform(0.0, box, (n, 2)), rng.uniform(0.0, 2.0 * np.pi, n)
    return x, speed * np.stack((np.cos(theta), np.sin(theta)), axis=1)

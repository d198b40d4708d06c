"""Flocking after Reynolds (1987): boids steered by separation, alignment and cohesion.

Holds :class:`Rules` (the three weights, the neighbour radius and view angle, speed limits,
an optional periodic box), the two neighbour searches, all pairs (:func:`all_pairs`,
dense N × N arrays) and a k-d tree (:func:`tree_pairs`, :class:`scipy.spatial.cKDTree`),
which find the same neighbours; the steering of each (:func:`steering`); a time step
(:func:`step`); a predator to flee (:func:`flee`); and the order parameters
(:func:`polarization`, :func:`nearest_distances`) with their values for boids placed at
random (:func:`random_polarization`, :func:`random_nearest_distance`). Core module:
imports NumPy and SciPy only.

Boid ``i`` sees boid ``j`` when ``0 < |d_ij| <= radius`` and the angle between its
velocity ``v_i`` and ``d_ij = x_j − x_i`` is at most half the view angle. With ``n_i``
neighbours (none: no steering),

    separation  S_i = −Σ_j d_ij / |d_ij|²       (1/m: push away, harder when close)
    alignment   A_i = (1/n_i) Σ_j v_j − v_i     (m/s: match the neighbours' velocity)
    cohesion    C_i = (1/n_i) Σ_j d_ij          (m: steer to the neighbours' centre)

and the acceleration is ``w_s S + w_a A + w_c C``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree
from scipy.special import beta, betainc

METHODS = ("tree", "all_pairs")


@dataclass(frozen=True)
class Rules:
    """Weights (``separation`` m²/s², ``alignment`` 1/s, ``cohesion`` 1/s²), neighbour
    ``radius`` (m), full ``view_angle`` (rad; 2π sees all around), speed limits (m/s) and
    the side ``box`` (m) of a periodic square (None: open space)."""

    separation: float = 0.3
    alignment: float = 2.0
    cohesion: float = 1.0
    radius: float = 2.0
    view_angle: float = 1.5 * np.pi
    min_speed: float = 1.0
    max_speed: float = 2.0
    box: float | None = None

    def __post_init__(self):
        if not self.radius > 0:
            raise ValueError(f"radius must be > 0, got {self.radius!r}")
        if not 0 < self.view_angle <= 2 * np.pi:
            raise ValueError(f"view_angle must lie in (0, 2π] rad, got {self.view_angle!r}")
        if not 0 <= self.min_speed <= self.max_speed:
            raise ValueError("speeds must satisfy 0 <= min_speed <= max_speed, got "
                             f"{self.min_speed!r}, {self.max_speed!r}")
        if self.box is not None and not self.box > 2 * self.radius:
            raise ValueError(f"box must exceed 2 × radius (or be None), got {self.box!r}")


def wrap(d, box: float | None):
    """Minimum-image offsets in a periodic box of side ``box`` (unchanged if None)."""
    return d if box is None else d - box * np.round(d / box)


def _in_view(dv, dist2, speed2, view_angle: float):
    """Is the angle between ``v`` and ``d`` within ``view/2``? From ``dv = d·v``, ``|d|²``
    and ``|v|²``: ``cos = dv / (|d||v|) >= cos(view/2)``, squared with care for signs."""
    if view_angle >= 2 * np.pi:
        return np.ones(dist2.shape, dtype=bool)
    c = np.cos(view_angle / 2)
    if c >= 0:
        return (dv >= 0) & (dv * dv >= c * c * dist2 * speed2)
    return (dv >= 0) | (dv * dv <= c * c * dist2 * speed2)


def _dense(x, v, rules: Rules):
    """All N² offsets ``d[i, j] = x_j − x_i``, squared distances and the neighbour mask."""
    d = wrap(x[None, :, :] - x[:, None, :], rules.box)
    dist2 = np.einsum("ijk,ijk->ij", d, d)
    mask = dist2 <= rules.radius**2
    np.fill_diagonal(mask, False)
    speed2 = np.einsum("ik,ik->i", v, v)[:, None]
    mask &= _in_view(np.einsum("ijk,ik->ij", d, v), dist2, speed2, rules.view_angle)
    return d, dist2, mask


def all_pairs(x, v, rules: Rules):
    """Neighbours by testing all N² pairs: ``(i, j, d)`` sorted by ``(i, j)``, with
    ``d = x_j − x_i`` (minimum image), shape ``(P, dim)``. Memory grows as N²."""
    d, _, mask = _dense(np.asarray(x, dtype=float), np.asarray(v, dtype=float), rules)
    i, j = np.nonzero(mask)
    return i, j, d[i, j]


def _rowdot(a, b):
    """Row-wise dot products of two ``(P, dim)`` arrays, column by column (for small
    ``dim`` this is faster than ``einsum`` and gives the same bits)."""
    out = a[:, 0] * b[:, 0]
    for k in range(1, a.shape[1]):
        out += a[:, k] * b[:, k]
    return out


def _directed_pairs(x, v, rules: Rules):
    """Unsorted directed neighbour pairs: ``(i, j, d, |d|²)``. ``query_pairs`` gives each
    close pair ``(a, b)`` once; its offset ``x_b − x_a`` is computed once, and the reverse
    offset is its exact negative (subtraction, division and rounding are odd functions in
    IEEE arithmetic), so both directions cost one offset."""
    pts = x if rules.box is None else np.mod(x, rules.box) % rules.box
    a, b = cKDTree(pts, boxsize=rules.box).query_pairs(rules.radius, output_type="ndarray").T
    half = wrap(np.take(x, b, axis=0) - np.take(x, a, axis=0), rules.box)
    i, j, d = np.concatenate((a, b)), np.concatenate((b, a)), np.concatenate((half, -half))
    dist2 = _rowdot(half, half)
    dist2 = np.concatenate((dist2, dist2))
    speed2 = _rowdot(v, v)
    keep = np.flatnonzero((dist2 <= rules.radius**2)
                          & _in_view(_rowdot(d, np.take(v, i, axis=0)), dist2,
                                     np.take(speed2, i), rules.view_angle))
    return (np.take(i, keep), np.take(j, keep), np.take(d, keep, axis=0),
            np.take(dist2, keep))


def tree_pairs(x, v, rules: Rules, sort: bool = True):
    """The same neighbours as :func:`all_pairs`, found with a k-d tree in
    ``O(N log N + P)``: ``cKDTree.query_pairs`` (periodic when ``rules.box``) gives each
    close pair once; both directions are then tested against the view angle. ``sort``
    orders the pairs by ``(i, j)`` as :func:`all_pairs` does."""
    i, j, d, _ = _directed_pairs(np.asarray(x, dtype=float), np.asarray(v, dtype=float), rules)
    if not sort:
        return i, j, d
    order = np.lexsort((j, i))
    return i[order], j[order], d[order]


def steering(x, v, rules: Rules, method: str = "tree"):
    """Separation, alignment and cohesion of every boid, each ``(N, dim)``.

    ``method="all_pairs"`` sums over dense N × N masks; ``"tree"`` scatters the
    neighbour pairs with ``np.bincount`` (each boid's sums accumulate in pair order). The
    two agree to round-off.
    """
    x, v = np.asarray(x, dtype=float), np.asarray(v, dtype=float)
    n, dim = x.shape
    if method == "all_pairs":
        d, dist2, mask = _dense(x, v, rules)
        count = mask.sum(axis=1)
        inv = np.divide(1.0, dist2, out=np.zeros_like(dist2), where=mask)
        sep = -np.einsum("ij,ijk->ik", inv, d)
        mean_v = (mask @ v) / np.maximum(count, 1)[:, None]
        mean_d = np.einsum("ij,ijk->ik", mask.astype(float), d) / np.maximum(count, 1)[:, None]
    elif method == "tree":
        i, j, d, dist2 = _directed_pairs(x, v, rules)
        count = np.bincount(i, minlength=n)
        per, inv, v_j = np.maximum(count, 1), 1.0 / dist2, np.take(v, j, axis=0)
        sep, mean_v, mean_d = np.empty((n, dim)), np.empty((n, dim)), np.empty((n, dim))
        for k in range(dim):                      # columns: bincount sums 1D weights
            sep[:, k] = np.bincount(i, d[:, k] * inv, minlength=n)
            mean_v[:, k] = np.bincount(i, v_j[:, k], minlength=n) / per
            mean_d[:, k] = np.bincount(i, d[:, k], minlength=n) / per
        sep = -sep
    else:
        raise ValueError(f"unknown method {method!r}; valid choices are: {', '.join(METHODS)}")
    has = (count > 0)[:, None]
    return sep, np.where(has, mean_v - v, 0.0), np.where(has, mean_d, 0.0)


def clamp_speed(v, min_speed: float, max_speed: float):
    """Velocities rescaled so that every speed lies in ``[min_speed, max_speed]``."""
    speed = np.linalg.norm(v, axis=1, keepdims=True)
    target = np.clip(speed, min_speed, max_speed)
    return v * np.divide(target, speed, out=np.ones_like(speed), where=speed > 0)


def flee(x, predator, radius: float, strength: float, box: float | None = None):
    """Acceleration (m/s²) away from a predator at ``predator`` for boids within
    ``radius``: ``strength × (x − x_p) / |x − x_p|²``, zero beyond."""
    d = wrap(np.asarray(x, dtype=float) - np.asarray(predator, dtype=float), box)
    dist2 = np.einsum("nk,nk->n", d, d)
    near = (dist2 <= radius**2) & (dist2 > 0)
    return strength * d * np.divide(1.0, dist2, out=np.zeros_like(dist2), where=near)[:, None]


def step(x, v, dt: float, rules: Rules, method: str = "tree", extra=None):
    """One step: ``v += dt a`` (rules, plus ``extra`` m/s²), speeds clamped to the limits,
    ``x += dt v``, positions wrapped into the box. Returns new ``(x, v)``."""
    if not dt > 0:
        raise ValueError(f"dt must be > 0, got {dt!r}")
    sep, ali, coh = steering(x, v, rules, method)
    a = rules.separation * sep + rules.alignment * ali + rules.cohesion * coh
    if extra is not None:
        a = a + extra
    v_new = clamp_speed(v + dt * a, rules.min_speed, rules.max_speed)
    x_new = x + dt * v_new
    return (x_new if rules.box is None else np.mod(x_new, rules.box)), v_new


def polarization(v) -> float:
    """Order parameter ``|(1/N) Σ v_i/|v_i||`` in [0, 1]: 1 when all head the same way."""
    v = np.asarray(v, dtype=float)
    return float(np.linalg.norm(np.mean(v / np.linalg.norm(v, axis=1, keepdims=True), axis=0)))


def nearest_distances(x, box: float | None = None) -> np.ndarray:
    """Distance (m) from each boid to its nearest neighbour (periodic if ``box``)."""
    pts = np.asarray(x, dtype=float)
    pts = pts if box is None else np.mod(pts, box) % box
    dist, _ = cKDTree(pts, boxsize=box).query(pts, k=2)
    return dist[:, 1]


def random_polarization(n: int) -> float:
    """Expected polarization of ``n`` independent uniformly random 2D headings, to
    ``O(1/n)``: the sum of ``n`` unit vectors is nearly Gaussian with variance ``n/2``
    per axis, so its length is Rayleigh with mean ``√(π n)/2``: ``√π / (2 √n)``."""
    return float(np.sqrt(np.pi) / (2.0 * np.sqrt(n)))


def random_nearest_distance(n: int, box: float) -> float:
    """Exact mean nearest-neighbour distance (m) of ``n`` uniform random points in a
    periodic square of side ``box``: ``∫ (1 − π r²/A)^{n−1} dr`` over ``r <= box/2``
    (where the disc fits; beyond, the integrand is below 10⁻³⁰⁰ for any realistic n).
    With ``u = π r²/A`` it is an incomplete beta function, computed in closed form:
    ``½ √(A/π) B(½, n) I_{π/4}(½, n)``, close to ``1/(2√ρ)`` for large ``n``."""
    area = float(box) ** 2
    return float(0.5 * np.sqrt(area / np.pi) * beta(0.5, n) * betainc(0.5, n, np.pi / 4))


def random_flock(n: int, box: float, speed: float, rng: np.random.Generator):
    """``n`` boids uniform in the square ``[0, box)²`` with random headings at ``speed``."""
    x = rng.uniform(0.0, box, (n, 2))
    theta = rng.uniform(0.0, 2.0 * np.pi, n)
    return x, speed * np.stack((np.cos(theta), np.sin(theta)), axis=1)

"""Flocking after Reynolds (1987): boids steered by separation, alignment and cohesion.

Holds :class:`Rules` (the three weights, the neighbour radius and view angle, speed limits,
an optional periodic box), the two neighbour searches, all pairs (:func:`all_pairs`,
dense N × N arrays) and a k-d tree (:func:`tree_pairs`, through
:func:`course_lib.neighbors.pairs`), which find exactly the same neighbours with the same
offsets; the steering of each (:func:`steering`); a time step (:func:`step`); two
steering behaviours of Reynolds (1999), fleeing a predator (:func:`flee`) and steering
to avoid obstacles (:func:`avoid`); and the order parameters (:func:`polarization`,
:func:`nearest_distances`) with their values for boids placed at random
(:func:`random_polarization`, :func:`random_nearest_distance`), which live in
:mod:`course_lib.flock_measures` and are re-exported here. Core module: imports NumPy,
SciPy and :mod:`course_lib.neighbors` and :mod:`course_lib.flock_measures` only.

Boid ``i`` sees boid ``j`` when ``0 < |d_ij| <= radius`` (the pair definition of
:mod:`course_lib.neighbors`: ``d_ij = x_j − x_i``, the minimum image in a box) and the
angle between its velocity ``v_i`` and ``d_ij`` is at most half the view angle. A boid at
the very same point as another does not see it: there is no direction to steer away
from. With ``n_i`` neighbours (none: no steering),

    separation  S_i = −Σ_j d_ij / |d_ij|²       (1/m: push away, harder when close)
    alignment   A_i = (1/n_i) Σ_j v_j − v_i     (m/s: match the neighbours' velocity)
    cohesion    C_i = (1/n_i) Σ_j d_ij          (m: steer to the neighbours' centre)

and the acceleration is ``w_s S + w_a A + w_c C``. Every rule is finite for every finite
state (positions anywhere, speeds below 1e150 m/s): separation is at most
``1/|d|`` per neighbour, and offsets beyond the float range are never neighbours.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import neighbors
from ._validate import finite_real, nonnegative, positive_finite, real_array
from .flock_measures import (  # noqa: F401  (re-exported: boids.polarization etc.)
    _headings,
    nearest_distances,
    polarization,
    random_flock,
    random_nearest_distance,
    random_polarization,
)
from .neighbors import squared_norms

METHODS = ("tree", "all_pairs")
#: Heading (rad) of boid ``k`` when it is at rest and must fly: ``k`` times the golden angle,
#: so that boids at rest leave in well-spread directions, the same on every run.
GOLDEN_ANGLE = np.pi * (3.0 - np.sqrt(5.0))


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
        for name in ("separation", "alignment", "cohesion"):
            if not np.isfinite(getattr(self, name)):
                raise ValueError(f"{name} must be a finite weight, got {getattr(self, name)!r}")
        if not (np.isfinite(self.radius) and self.radius > 0):
            raise ValueError(f"radius must be finite and > 0, got {self.radius!r}")
        if not 0 < self.view_angle <= 2 * np.pi:
            raise ValueError(f"view_angle must lie in (0, 2π] rad, got {self.view_angle!r}")
        if not (0 <= self.min_speed <= self.max_speed and np.isfinite(self.min_speed)):
            raise ValueError("speeds must satisfy 0 <= min_speed <= max_speed, got "
                             f"{self.min_speed!r}, {self.max_speed!r}")
        if self.box is not None and not (np.isfinite(self.box) and self.box > 2 * self.radius):
            raise ValueError(f"box must exceed 2 × radius (or be None), got {self.box!r}")


def wrap(d, box: float | None):
    """Minimum-image offsets in a periodic box of side ``box`` (unchanged if None)."""
    return neighbors.minimum_image(d, box)


def _state(x, v):
    """``x`` and ``v`` as float ``(N, dim)`` arrays of one shape, finite, or a clear error."""
    x, v = real_array("x", x), real_array("v", v)
    if x.ndim != 2 or x.shape != v.shape:
        raise ValueError(f"x and v must have the same shape (N, dim), got {x.shape} and {v.shape}")
    return x, v


def _dot(a, b):
    """Dot products over the last axis, coordinate by coordinate in order (broadcasting)."""
    with np.errstate(over="ignore"):
        out = a[..., 0] * b[..., 0]
        for k in range(1, a.shape[-1]):
            out = out + a[..., k] * b[..., k]
    return out


def _in_view(dv, dist2, speed2, view_angle: float):
    """Is the angle between ``v`` and ``d`` within ``view/2``? From ``dv = d·v``, ``|d|²``
    and ``|v|²``: ``cos = dv / (|d||v|) >= cos(view/2)``, squared with care for signs."""
    if view_angle >= 2 * np.pi:
        return np.ones(np.shape(dist2), dtype=bool)
    c = np.cos(view_angle / 2)
    with np.errstate(over="ignore", invalid="ignore"):     # non-neighbours may hold inf
        if c >= 0:
            return (dv >= 0) & (dv * dv >= c * c * dist2 * speed2)
        return (dv >= 0) | (dv * dv <= c * c * dist2 * speed2)


def _dense(x, v, rules: Rules):
    """All N² offsets ``d[i, j] = x_j − x_i`` (zero where ``j`` is no neighbour of ``i``),
    squared distances and the neighbour mask: offsets and distances bit for bit those of
    :func:`course_lib.neighbors.pairs` (one definition, the minimum image of wrapped
    positions; ``x_i − x_j`` is exactly ``−(x_j − x_i)`` in floating point)."""
    w = neighbors.wrap_positions(x, rules.box)
    with np.errstate(over="ignore"):
        d = neighbors.minimum_image(w[None, :, :] - w[:, None, :], rules.box)
    dist2 = squared_norms(d)
    mask = (dist2 <= rules.radius * rules.radius) & (dist2 > 0)
    d = np.where(mask[..., None], d, 0.0)
    mask &= _in_view(_dot(d, v[:, None, :]), np.where(mask, dist2, 0.0), squared_norms(v)[:, None],
                     rules.view_angle)
    return np.where(mask[..., None], d, 0.0), dist2, mask


def all_pairs(x, v, rules: Rules):
    """Neighbours by testing all N² pairs: ``(i, j, d)`` sorted by ``(i, j)``, with
    ``d = x_j − x_i`` (minimum image), shape ``(P, dim)``. Memory grows as N²."""
    d, _, mask = _dense(*_state(x, v), rules)
    i, j = np.nonzero(mask)
    return i, j, d[i, j]


def _sides(x, rules: Rules):
    """The box as :mod:`course_lib.neighbors` wants it (validated by :class:`Rules`)."""
    return None if rules.box is None else np.full(x.shape[1], float(rules.box))


def _directed_pairs(x, v, rules: Rules):
    """Unsorted directed neighbour pairs ``(i, j, d, |d|²)`` from the unordered pairs of
    :func:`course_lib.neighbors.pairs`: the reverse offset is the exact negative."""
    p = neighbors.pairs_unchecked(x, rules.radius, _sides(x, rules), sort=False)
    i, j = np.concatenate((p.i, p.j)), np.concatenate((p.j, p.i))
    d = np.concatenate((p.offset, -p.offset))
    dist2 = np.tile(squared_norms(p.offset), 2)
    keep = np.flatnonzero((dist2 > 0) & _in_view(_dot(d, np.take(v, i, axis=0)), dist2,
                                                 np.take(squared_norms(v), i), rules.view_angle))
    return np.take(i, keep), np.take(j, keep), np.take(d, keep, axis=0), np.take(dist2, keep)


def tree_pairs(x, v, rules: Rules, sort: bool = True):
    """The same neighbours as :func:`all_pairs` (same pairs, same offset bits), found with
    a k-d tree in ``O(N log N + P)``; both directions of each close pair are tested
    against the view angle. ``sort`` orders the pairs by ``(i, j)`` as :func:`all_pairs`."""
    i, j, d, _ = _directed_pairs(*_state(x, v), rules)
    if not sort:
        return i, j, d
    order = np.lexsort((j, i))
    return i[order], j[order], d[order]


def steering(x, v, rules: Rules, method: str = "tree"):
    """Separation, alignment and cohesion of every boid, each ``(N, dim)``.

    ``method="all_pairs"`` sums over dense N × N masks; ``"tree"`` scatters the
    neighbour pairs with ``np.bincount`` (each boid's sums accumulate in pair order). The
    two see the same neighbours and agree to round-off (their sums run in other orders).
    """
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; valid choices are: {', '.join(METHODS)}")
    return _steering(*_state(x, v), rules, method)


def _steering(x, v, rules: Rules, method: str):
    """:func:`steering` on validated ``x``, ``v`` and ``method``."""
    n, dim = x.shape
    if method == "all_pairs":
        d, dist2, mask = _dense(x, v, rules)
        count = mask.sum(axis=1)
        sep = -np.divide(d, dist2[..., None], out=np.zeros_like(d), where=mask[..., None]).sum(axis=1)
        mean_v = (mask.astype(float) @ v) / np.maximum(count, 1)[:, None]
        mean_d = d.sum(axis=1) / np.maximum(count, 1)[:, None]
    else:
        i, j, d, dist2 = _directed_pairs(x, v, rules)
        count = np.bincount(i, minlength=n)
        per, v_j, push = np.maximum(count, 1), np.take(v, j, axis=0), d / dist2[:, None]
        sep, mean_v, mean_d = np.empty((n, dim)), np.empty((n, dim)), np.empty((n, dim))
        for k in range(dim):                      # columns: bincount sums 1D weights
            sep[:, k] = -np.bincount(i, push[:, k], minlength=n)
            mean_v[:, k] = np.bincount(i, v_j[:, k], minlength=n) / per
            mean_d[:, k] = np.bincount(i, d[:, k], minlength=n) / per
    has = (count > 0)[:, None]
    return sep, np.where(has, mean_v - v, 0.0), np.where(has, mean_d, 0.0)


def clamp_speed(v, min_speed: float, max_speed: float):
    """Velocities rescaled so that every speed lies in ``[min_speed, max_speed]`` (rows
    already inside are returned unchanged). A boid at rest that must fly
    (``min_speed > 0``) sets off along heading ``k × GOLDEN_ANGLE`` (boid ``k``)."""
    v, min_speed = real_array("v", v, (None, None)), nonnegative("min_speed", min_speed)
    if not max_speed >= min_speed:
        raise ValueError(f"max_speed must be >= min_speed = {min_speed!r}, got {max_speed!r}")
    return _clamp(v, min_speed, max_speed)


def _clamp(v, min_speed: float, max_speed: float):
    """:func:`clamp_speed` on a validated ``(N, dim)`` float ``v`` and valid limits."""
    unit, speed = _headings(v)
    target = np.clip(speed, min_speed, max_speed)
    rest = (speed[:, 0] == 0) & (target[:, 0] > 0)
    if np.any(rest):
        angle = GOLDEN_ANGLE * np.flatnonzero(rest)
        unit[rest] = 0.0
        unit[rest, 0] = np.cos(angle)
        if unit.shape[1] > 1:
            unit[rest, 1] = np.sin(angle)
    return np.where(speed == target, v, unit * target)


def flee(x, predator, radius: float, strength: float, box: float | None = None):
    """Acceleration (m/s², ``(N, dim)``) away from a predator at ``predator`` for boids
    within ``radius`` (m): ``strength × (x − x_p) / |x − x_p|²`` (m²/s²), zero beyond
    and at the predator's own position."""
    x = real_array("x", x, (None, None))
    radius, strength = positive_finite("radius", radius), finite_real("strength", strength)
    d = wrap(x - real_array("predator", predator, x.shape[1:]), box)
    dist2 = squared_norms(d)
    near = ((dist2 <= radius**2) & (dist2 > 0))[:, None]
    return strength * np.divide(d, dist2[:, None], out=np.zeros_like(d), where=near)


def avoid(x, v, centers, radii, lookahead: float, strength: float, box: float | None = None,
          clearance: float = 0.0):
    """Steer to avoid (Reynolds 1999): a lateral acceleration (m/s², ``(N, dim)``) away from
    the nearest obstacle ahead.

    Each boid looks ``lookahead`` (m) along its heading ``u``. A sphere (a circle in 2D)
    of centre ``c_k`` and radius ``ρ_k`` (``centers`` ``(K, dim)``, ``radii`` ``(K,)``, m),
    widened by ``clearance`` (m, the boid's half-width: the radius of Reynolds' cylinder
    along the path), is *ahead* when its centre projects onto the forward axis at
    ``0 < s < lookahead + ρ`` and its lateral offset ``p = (c − x) − s u`` is shorter than
    ``ρ``: flying on, the boid would hit it. The nearest such obstacle (smallest ``s``)
    pushes the boid sideways, along ``−p/|p|``, with ``strength × (1 − s/(lookahead + ρ))``
    (m/s²): harder the closer it is. A boid heading straight at the centre (``p = 0``)
    turns to its left (2D) or along an axis across ``u``. A boid inside an obstacle is
    pushed straight out at full ``strength`` (exactly at its centre: across ``u`` as above,
    or along the first axis at rest). Boids at rest steer only out of an obstacle.
    """
    x, v = _state(x, v)
    c, rho = real_array("centers", centers).reshape(-1, x.shape[1]), real_array("radii", radii).ravel()
    if rho.shape != (len(c),) or np.any(rho <= 0):
        raise ValueError(f"radii must hold one radius > 0 per centre ({len(c)}), got {radii!r}")
    rho, lookahead = rho + nonnegative("clearance", clearance), positive_finite("lookahead", lookahead)
    strength = finite_real("strength", strength)
    out = np.zeros_like(x)
    if len(c) == 0:
        return out
    u, speed = _headings(v)
    rel = wrap(c[None, :, :] - x[:, None, :], box)               # (N, K, dim)
    s = _dot(rel, u[:, None, :])
    lateral = rel - s[..., None] * u[:, None, :]
    reach = lookahead + rho[None, :]
    ahead = (s > 0) & (s < reach) & (squared_norms(lateral) < rho**2) & (speed > 0)
    inside = squared_norms(rel) < rho**2
    first = np.argmin(np.where(ahead, s, np.inf), axis=1)
    rows = np.arange(len(x))
    hit = ahead[rows, first]
    p = lateral[rows, first]
    side, length = _headings(-p)
    if u.shape[1] == 2:                                        # left of the heading
        across = np.stack((-u[:, 1], u[:, 0]), axis=1)
    else:                                                      # the axis least along u
        axis = np.eye(u.shape[1])[np.argmin(np.abs(u), axis=1)]
        across = _headings(axis - _dot(axis, u)[:, None] * u)[0]
    side = np.where(length > 0, side, across)
    urgency = 1.0 - s[rows, first] / reach[0, first]
    out = np.where(hit[:, None], strength * urgency[:, None] * side, 0.0)
    out_dir, depth = _headings(-rel[rows, np.argmax(inside, axis=1)])   # at a centre: across u
    out_dir = np.where(depth > 0, out_dir, np.where(speed > 0, across, np.eye(x.shape[1])[0]))
    return np.where(inside.any(axis=1)[:, None], strength * out_dir, out)


def step(x, v, dt: float, rules: Rules, method: str = "tree", extra=None):
    """One step: ``v += dt a`` (rules, plus ``extra`` m/s²), speeds clamped to the limits,
    ``x += dt v``, positions wrapped into the box. Returns new ``(x, v)``."""
    dt = positive_finite("dt", dt)
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; valid choices are: {', '.join(METHODS)}")
    x, v = _state(x, v)
    sep, ali, coh = _steering(x, v, rules, method)
    a = rules.separation * sep + rules.alignment * ali + rules.cohesion * coh
    if extra is not None:
        a = a + np.broadcast_to(real_array("extra", extra), a.shape)
    v_new = _clamp(v + dt * a, rules.min_speed, rules.max_speed)
    if not np.all(np.isfinite(v_new)):
        raise ValueError("the step blew up: a velocity is no longer finite (check weights and dt)")
    x_new = x + dt * v_new
    return (x_new if rules.box is None else neighbors.wrap_unchecked(x_new, _sides(x, rules))), v_new

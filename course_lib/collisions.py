"""Collision responses applied after a step: project out of the obstacle, fix velocity.

These act on a stacked state ``y = (x, v)`` of shape ``(2, N, d)`` and suit
``integrate(..., post_step=...)``. A penetrating particle is moved to the surface; the
normal part of its velocity is reversed and scaled by the restitution ``e`` (``e = 0``
removes it, ``e = 1`` is a perfect bounce) and its tangential part is reduced by Coulomb
friction ``μ`` (at most to zero). A single particle may be stored as ``y`` of shape
``(2, d)``. Every argument is checked when the response is built (``ValueError`` naming
it), and the state's dimension when it is applied. :func:`self_contact` keeps the
particles of one body (a cloth) at least a thickness apart, finding close pairs with
``scipy.spatial.cKDTree``. Imports: numpy, scipy.spatial, ``_validate`` (core).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from . import _validate


def _coefficients(restitution: float, friction: float) -> tuple[float, float]:
    restitution = _validate.finite_real("restitution", restitution)
    friction = _validate.finite_real("friction", friction)
    if not 0 <= restitution <= 1:
        raise ValueError(f"restitution must lie in [0, 1], got {restitution}")
    if friction < 0:
        raise ValueError(f"friction must be >= 0, got {friction}")
    return restitution, friction


def _particles(y, dim: int, what: str) -> tuple[np.ndarray, np.ndarray, bool]:
    """``(x, v)`` as ``(N, d)`` arrays, and whether ``y`` was a single particle ``(2, d)``."""
    y = np.asarray(y, dtype=float)
    single = y.ndim == 2
    if y.ndim not in (2, 3) or y.shape[0] != 2 or y.shape[-1] != dim:
        raise ValueError(f"y must be a state (2, N, {dim}) or (2, {dim}) to collide with this "
                         f"{dim}-D {what}, got shape {y.shape}")
    return (y[0][None], y[1][None], True) if single else (y[0], y[1], False)


def _respond(v, normal, hit, restitution, friction):
    vn = np.einsum("nd,nd->n", v, normal)
    approaching = hit & (vn < 0)
    v_n = vn[:, None] * normal
    v_t = v - v_n
    t_speed = np.linalg.norm(v_t, axis=1)
    # Coulomb friction: tangential speed drops by μ times the normal speed change.
    dvn = (1.0 + restitution) * np.abs(vn)
    slowed = 1.0 - friction * dvn / np.maximum(t_speed, 1e-300)
    scale = np.where(t_speed > 0, np.maximum(0.0, slowed), 0.0)
    v_new = v.copy()
    v_new[approaching] = (scale[:, None] * v_t - restitution * v_n)[approaching]
    return v_new


def plane(normal=(0.0, 1.0, 0.0), offset: float = 0.0, restitution: float = 0.5,
          friction: float = 0.0):
    """Post-step collision with the half-space ``n·x >= offset`` (e.g. the ground ``y >= 0``).

    ``normal`` is any non-zero finite vector (normalized here; its length sets the
    dimension ``d``), ``offset`` in metres along it.
    """
    n = _validate.vector("normal", normal, nonzero=True)
    n = n / np.linalg.norm(n)
    offset = _validate.finite_real("offset", offset)
    restitution, friction = _coefficients(restitution, friction)

    def post_step(t, y):
        x, v, single = _particles(y, n.size, "plane")
        depth = offset - x @ n
        hit = depth > 0
        if not hit.any():
            return np.asarray(y, dtype=float)
        x_new = x + np.where(hit, depth, 0.0)[:, None] * n
        out = np.stack((x_new, _respond(v, np.broadcast_to(n, x.shape), hit, restitution,
                                        friction)))
        return out[:, 0] if single else out

    return post_step


def sphere(center=(0.0, 0.0, 0.0), radius: float = 1.0, restitution: float = 0.0,
           friction: float = 0.0):
    """Post-step collision with a solid sphere (a head): particles inside are projected to
    its surface and lose their inward normal velocity.

    A particle exactly at the centre has no outward direction; it leaves against its
    velocity (back the way it came), or along ``+y`` (the first axis in 1-D) at rest.
    """
    c = _validate.vector("center", center)
    radius = _validate.finite_real("radius", radius)
    if radius <= 0:
        raise ValueError(f"radius must be > 0, got {radius}")
    restitution, friction = _coefficients(restitution, friction)
    up = np.zeros(c.size)
    up[min(1, c.size - 1)] = 1.0

    def post_step(t, y):
        x, v, single = _particles(y, c.size, "sphere")
        r = x - c
        dist = np.linalg.norm(r, axis=1)
        # A particle resting exactly on the surface must not be nudged by round-off.
        hit = dist < radius * (1.0 - 1e-12)
        if not hit.any():
            return np.asarray(y, dtype=float)
        normals = r / np.where(dist > 0, dist, 1.0)[:, None]
        centred = hit & (dist == 0)
        if centred.any():
            speed = np.linalg.norm(v[centred], axis=1, keepdims=True)
            away = np.where(speed > 0, -v[centred] / np.where(speed > 0, speed, 1.0), up)
            normals[centred] = away
        x_new = np.where(hit[:, None], c + radius * normals, x)
        out = np.stack((x_new, _respond(v, normals, hit, restitution, friction)))
        return out[:, 0] if single else out

    return post_step


def chain(*post_steps):
    """Apply several post-step functions in turn."""
    for i, p in enumerate(post_steps):
        _validate.callable_arg(f"post_steps[{i}]", p)

    def post_step(t, y):
        for p in post_steps:
            y = p(t, y)
        return y

    return post_step


def self_contact(thickness: float, mass=None, iterations: int = 2):
    """Post-step contact between the particles of one body (a cloth folding onto itself).

    Every pair closer than ``thickness`` (m; choose it below the rest spacing of the grid,
    so that neighbours at rest never touch) is pushed apart along the line joining it to
    ``thickness``, each particle by its share of the overlap (``1/m``-weighted; equal
    shares by default), and loses the part of their relative velocity that brings the two
    closer (an inelastic contact that keeps their momentum). Pairs come from
    ``cKDTree.query_pairs`` (no loop over particles); corrections are summed per particle,
    ``iterations`` times. A coincident pair has no direction and is left alone.
    """
    thickness = _validate.positive_finite("thickness", thickness)
    iterations = _validate.positive_int("iterations", iterations)
    inv = None if mass is None else 1.0 / _validate.positive_array("mass", mass)
    if inv is not None and inv.ndim != 1:
        raise ValueError("mass must be a 1-D array of positive masses, one per particle")

    def post_step(t, y):
        y = np.asarray(y, dtype=float)
        if y.ndim != 3 or y.shape[0] != 2:
            raise ValueError(f"y must be a state (2, N, d) for self_contact, got shape {y.shape}")
        x, v = y[0].copy(), y[1].copy()
        w = np.ones(len(x)) if inv is None else inv
        if w.shape != (len(x),):
            raise ValueError(f"mass must have one entry per particle ({len(x)}), got {w.shape}")
        for _ in range(iterations):
            pairs = cKDTree(x).query_pairs(thickness, output_type="ndarray")
            if not len(pairs):
                break
            a, b = pairs[:, 0], pairs[:, 1]
            d = x[a] - x[b]
            dist = np.linalg.norm(d, axis=1)
            keep = dist > 0
            a, b, d, dist = a[keep], b[keep], d[keep], dist[keep]
            n = d / dist[:, None]
            share = (thickness - dist) / (w[a] + w[b])
            dx = np.zeros_like(x)
            np.add.at(dx, a, (w[a] * share)[:, None] * n)
            np.add.at(dx, b, -(w[b] * share)[:, None] * n)
            x += dx
            closing = np.einsum("pd,pd->p", v[a] - v[b], n)
            hit = closing < 0
            impulse = np.where(hit, closing, 0.0) / (w[a] + w[b])
            dv = np.zeros_like(v)
            np.add.at(dv, a, -(w[a] * impulse)[:, None] * n)
            np.add.at(dv, b, (w[b] * impulse)[:, None] * n)
            v += dv
        return np.stack((x, v))

    return post_step

"""Collision responses applied after a step: project out of the obstacle, fix velocity.

These act on a stacked state ``y = (x, v)`` of shape ``(2, N, d)`` and suit
``integrate(..., post_step=...)``. A penetrating particle is moved to the surface; the
normal part of its velocity is reversed and scaled by the restitution ``e`` (``e = 0``
removes it, ``e = 1`` is a perfect bounce) and its tangential part is reduced by Coulomb
friction ``μ`` (at most to zero).
"""

from __future__ import annotations

import numpy as np


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
    """Post-step collision with the half-space ``n·x >= offset`` (e.g. the ground ``y >= 0``)."""
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    if not 0 <= restitution <= 1:
        raise ValueError(f"restitution must lie in [0, 1], got {restitution}")
    if friction < 0:
        raise ValueError(f"friction must be >= 0, got {friction}")

    def post_step(t, y):
        x, v = y[0], y[1]
        if x.ndim == 1:
            return post_step(t, y[:, None, :])[:, 0, :]
        depth = offset - x @ n
        hit = depth > 0
        if not hit.any():
            return y
        x_new = x + np.where(hit, depth, 0.0)[:, None] * n
        normals = np.broadcast_to(n, x.shape)
        return np.stack((x_new, _respond(v, normals, hit, restitution, friction)))

    return post_step


def sphere(center=(0.0, 0.0, 0.0), radius: float = 1.0, restitution: float = 0.0,
           friction: float = 0.0):
    """Post-step collision with a solid sphere (a head): particles inside are projected to
    its surface and lose their inward normal velocity."""
    c = np.asarray(center, dtype=float)
    if radius <= 0:
        raise ValueError(f"radius must be > 0, got {radius}")

    def post_step(t, y):
        x, v = y[0], y[1]
        r = x - c
        dist = np.linalg.norm(r, axis=1)
        # A particle resting exactly on the surface must not be nudged by round-off.
        hit = dist < radius * (1.0 - 1e-12)
        if not hit.any():
            return y
        normals = r / np.maximum(dist, 1e-12)[:, None]
        x_new = np.where(hit[:, None], c + radius * normals, x)
        return np.stack((x_new, _respond(v, normals, hit, restitution, friction)))

    return post_step


def chain(*post_steps):
    """Apply several post-step functions in turn."""

    def post_step(t, y):
        for p in post_steps:
            y = p(t, y)
        return y

    return post_step

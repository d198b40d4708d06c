"""Unit quaternions for orientations: product, rotation matrix, and the time step.

A quaternion is stored scalar first, ``q = (w, x, y, z)``, in arrays of shape ``(..., 4)``;
every function is vectorized over the leading axes. A unit quaternion
``(cos θ/2, sin θ/2 n)`` is the rotation by ``θ`` about the unit axis ``n``; its matrix
:func:`to_matrix` maps body coordinates to world coordinates, ``r_world = R r_body``.

The orientation moves as ``dq/dt = ½ (0, ω) ⊗ q`` with ``ω`` the *world* angular velocity,
or equivalently ``dq/dt = ½ q ⊗ (0, Ω)`` with ``Ω = Rᵀω`` in the *body* frame (Baraff
2001, "Physically Based Modeling: Rigid Body Simulation", SIGGRAPH course notes).
:func:`step` takes one explicit Euler step of it and renormalises. That step is an exact
rotation, the Cayley rotation ``q ⊗ (1, Δt Ω/2)/|…|`` by the angle ``2 atan(|Ω| Δt/2)``
(one more than the exact ``|Ω| Δt`` by ``|Ω|³Δt³/12``). :func:`exp_step` rotates by the exact
angle. Imports NumPy only.
"""

from __future__ import annotations

import numpy as np

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def cross(a, b) -> np.ndarray:
    """``a × b`` along the last axis (broadcast); much faster than ``np.cross`` on small arrays."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def hat(v) -> np.ndarray:
    """Cross-product matrices ``v̂`` (``v̂ u = v × u``), shape ``(..., 3, 3)``."""
    v = np.asarray(v, dtype=float)
    out = np.zeros((*v.shape[:-1], 3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


def multiply(p, q) -> np.ndarray:
    """Hamilton product ``p ⊗ q`` of quaternions of shape ``(..., 4)`` (broadcast).

    ``(p0, p) ⊗ (q0, q) = (p0 q0 − p·q, p0 q + q0 p + p × q)``; the rotation of ``p ⊗ q``
    applies ``q`` first, then ``p``.
    """
    p, q = np.asarray(p, dtype=float), np.asarray(q, dtype=float)
    w = p[..., :1] * q[..., :1] - np.sum(p[..., 1:] * q[..., 1:], axis=-1, keepdims=True)
    v = p[..., :1] * q[..., 1:] + q[..., :1] * p[..., 1:] + cross(p[..., 1:], q[..., 1:])
    return np.concatenate((w, v), axis=-1)


def conjugate(q) -> np.ndarray:
    """``(w, −x, −y, −z)``: the inverse rotation of a unit quaternion."""
    q = np.asarray(q, dtype=float)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def normalize(q) -> np.ndarray:
    """``q / |q|`` along the last axis (raises ``ValueError`` on a zero quaternion)."""
    q = np.asarray(q, dtype=float)
    norm = np.linalg.norm(q, axis=-1, keepdims=True)
    if np.any(norm == 0) or not np.all(np.isfinite(norm)):
        raise ValueError("q must be a finite, non-zero quaternion")
    return q / norm


def from_axis_angle(axis, angle) -> np.ndarray:
    """The unit quaternion of a rotation by ``angle`` (rad) about ``axis`` (any length > 0).

    ``axis`` has shape ``(..., 3)``, ``angle`` broadcasts against ``axis[..., 0]``.
    """
    axis = np.asarray(axis, dtype=float)
    norm = np.linalg.norm(axis, axis=-1, keepdims=True)
    if np.any(norm == 0):
        raise ValueError("axis must be a non-zero vector")
    half = 0.5 * np.asarray(angle, dtype=float)[..., None]
    return np.concatenate((np.cos(half), np.sin(half) * axis / norm), axis=-1)


def from_rotvec(rotvec) -> np.ndarray:
    """The unit quaternion of the rotation vector ``θ n`` (rad), zero giving the identity."""
    rotvec = np.asarray(rotvec, dtype=float)
    angle = np.linalg.norm(rotvec, axis=-1, keepdims=True)
    # sin(θ/2)/θ → 1/2 at θ = 0: np.sinc(x) = sin(πx)/(πx) stays finite there.
    scale = 0.5 * np.sinc(angle / (2.0 * np.pi))
    return np.concatenate((np.cos(0.5 * angle), scale * rotvec), axis=-1)


def to_matrix(q) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` of quaternions ``(..., 4)`` (normalised first)."""
    w, x, y, z = np.moveaxis(normalize(q), -1, 0)
    out = np.empty((*w.shape, 3, 3))
    out[..., 0, 0] = 1 - 2 * (y * y + z * z)
    out[..., 0, 1] = 2 * (x * y - w * z)
    out[..., 0, 2] = 2 * (x * z + w * y)
    out[..., 1, 0] = 2 * (x * y + w * z)
    out[..., 1, 1] = 1 - 2 * (x * x + z * z)
    out[..., 1, 2] = 2 * (y * z - w * x)
    out[..., 2, 0] = 2 * (x * z - w * y)
    out[..., 2, 1] = 2 * (y * z + w * x)
    out[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return out


def rotate(q, r) -> np.ndarray:
    """Rotate vectors ``r`` (..., 3) by unit quaternions ``q`` (..., 4): ``q ⊗ (0, r) ⊗ q*``."""
    q, r = np.asarray(q, dtype=float), np.asarray(r, dtype=float)
    u, w = q[..., 1:], q[..., :1]
    t = 2.0 * cross(u, r)
    return r + w * t + cross(u, t)


def step(q, omega, dt: float, renormalise: bool = True) -> np.ndarray:
    """One explicit step of ``dq/dt = ½ (0, ω) ⊗ q``, renormalised (Baraff 2001).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Orientations (unit or nearly unit quaternions).
    omega : array_like, shape (..., 3)
        World-frame angular velocities (rad/s).
    dt : float
        Step (s).
    renormalise : bool
        Divide by the length after the step (the default). ``False`` shows why it is
        needed: the length then grows by ``√(1 + |ω|²Δt²/4)`` every step.

    Returns
    -------
    ndarray, shape (..., 4)
        ``normalize(q + ½ Δt (0, ω) ⊗ q)``.
    """
    omega = np.asarray(omega, dtype=float)
    pure = np.concatenate((np.zeros((*omega.shape[:-1], 1)), omega), axis=-1)
    q = np.asarray(q, dtype=float)
    q1 = q + 0.5 * dt * multiply(pure, q)
    return normalize(q1) if renormalise else q1


def body_step(q, omega_body, dt: float) -> np.ndarray:
    """:func:`step` with the angular velocity in the body frame: ``normalize(q ⊗ (1, ΔtΩ/2))``.

    The same rotation as ``step(q, R Ω, dt)``, the Cayley rotation of ``Δt Ω``.
    """
    omega_body = np.asarray(omega_body, dtype=float)
    half = np.concatenate((np.ones((*omega_body.shape[:-1], 1)), 0.5 * dt * omega_body), axis=-1)
    return normalize(multiply(q, half))


def exp_step(q, omega_body, dt: float) -> np.ndarray:
    """Rotate ``q`` about the body axis ``Ω`` by the exact angle ``|Ω| Δt``: ``q ⊗ exp(ΔtΩ/2)``."""
    return normalize(multiply(q, from_rotvec(dt * np.asarray(omega_body, dtype=float))))

"""Inertia tensors of solid shapes, in the body frame and in the world frame.

In its body frame (origin at the centre of mass, axes along the shape's symmetry axes)
each shape's inertia tensor is diagonal; the diagonal holds the *principal moments*
(kg m²). For a solid box of mass ``m`` and side lengths ``(a, b, c)`` along x, y, z,

    I = m/12 · diag(b² + c², a² + c², a² + b²),

for a solid sphere of radius ``r`` ``I = 2/5 m r² · 1``, and for a solid cylinder of radius
``r`` and height ``h`` along its axis ``I_axis = m r²/2``, ``I_across = m (3r² + h²)/12``.
A body turned by the rotation ``R`` (body to world) has the world tensor
``R I_body Rᵀ`` and its inverse ``R I_body⁻¹ Rᵀ`` (Baraff 2001): the world tensor changes
as the body turns, the body tensor never does. Imports NumPy and :mod:`course_lib._validate`.
"""

from __future__ import annotations

import numpy as np

from .. import _validate

AXES = {"x": 0, "y": 1, "z": 2}


def box_moments(mass: float, sides) -> np.ndarray:
    """Principal moments (kg m², shape (3,)) of a solid box of ``mass`` (kg) and side lengths
    ``sides = (a, b, c)`` (m) along the body x, y, z axes."""
    mass = _validate.positive_finite("mass", mass)
    a, b, c = _positive_vector("sides", sides)
    return mass / 12.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])


def sphere_moments(mass: float, radius: float) -> np.ndarray:
    """Principal moments (kg m², shape (3,)) of a solid sphere: ``2/5 m r²`` about every axis."""
    mass = _validate.positive_finite("mass", mass)
    radius = _validate.positive_finite("radius", radius)
    return np.full(3, 0.4 * mass * radius * radius)


def cylinder_moments(mass: float, radius: float, height: float, axis: str = "z") -> np.ndarray:
    """Principal moments (kg m², shape (3,)) of a solid cylinder of ``radius`` and ``height``
    (m) whose symmetry axis is the body ``axis`` (``"x"``, ``"y"`` or ``"z"``)."""
    mass = _validate.positive_finite("mass", mass)
    radius = _validate.positive_finite("radius", radius)
    height = _validate.positive_finite("height", height)
    k = AXES[_validate.choice("axis", axis, AXES)]
    moments = np.full(3, mass * (3.0 * radius * radius + height * height) / 12.0)
    moments[k] = 0.5 * mass * radius * radius
    return moments


def body_tensor(moments) -> np.ndarray:
    """The diagonal body-frame tensor ``diag(moments)``, shape ``(..., 3, 3)``."""
    moments = np.asarray(moments, dtype=float)
    return moments[..., :, None] * np.eye(3)


def world_tensor(R, moments) -> np.ndarray:
    """World-frame inertia ``R diag(moments) Rᵀ`` (kg m²) for rotations ``R`` (..., 3, 3)."""
    R, moments = np.asarray(R, dtype=float), np.asarray(moments, dtype=float)
    return np.einsum("...ik,...k,...jk->...ij", R, moments, R)


def world_inverse(R, moments) -> np.ndarray:
    """Inverse world inertia ``R diag(1/moments) Rᵀ`` (1/(kg m²)), shape ``(..., 3, 3)``."""
    return world_tensor(R, 1.0 / np.asarray(moments, dtype=float))


def check_moments(name: str, moments) -> np.ndarray:
    """``moments`` as principal moments (shape (3,), or (N, 3) for N bodies), finite and > 0,
    obeying the triangle inequality ``I_i ≤ I_j + I_k`` of every real mass distribution."""
    arr = _validate.state_array(name, moments)
    if np.iscomplexobj(arr) or arr.shape[-1:] != (3,) or arr.ndim > 2:
        raise ValueError(f"{name} must hold the three principal moments, shape (3,) or (N, 3) "
                         f"in kg m², got shape {arr.shape}")
    if np.any(arr <= 0):
        raise ValueError(f"{name} must be > 0 (kg m²), got {arr.tolist()}")
    total = arr.sum(axis=-1, keepdims=True)
    if np.any(2.0 * arr > total * (1 + 1e-12)):
        raise ValueError(f"{name} {arr.tolist()} break the triangle inequality I1 ≤ I2 + I3 "
                         "that every mass distribution obeys")
    return arr


def _positive_vector(name: str, value) -> np.ndarray:
    arr = _validate.state_array(name, value)
    if np.iscomplexobj(arr) or arr.shape != (3,) or np.any(arr <= 0):
        raise ValueError(f"{name} must be three lengths > 0 (m), got {np.asarray(value).tolist()}")
    return arr

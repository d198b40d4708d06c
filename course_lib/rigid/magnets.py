"""Point magnetic dipoles: field, energy, force and torque, exact and with μ₀.

A dipole of moment ``m`` (A m²) at the origin makes the field (T)

    B(r) = μ₀ / (4π |r|³) · (3 (m·r̂) r̂ − m).

A second dipole ``m₂`` at ``r`` (``r̂ = r/|r|``, pointing from dipole 1 to dipole 2) has the
energy ``U = −m₂·B₁(r) = μ₀/(4π|r|³) (m₁·m₂ − 3 (m₁·r̂)(m₂·r̂))``, feels the torque
``τ₂ = m₂ × B₁(r)`` and the force ``F₂ = −∇_r U``:

    F₂ = 3μ₀ / (4π |r|⁴) · ((m₁·r̂) m₂ + (m₂·r̂) m₁ + (m₁·m₂) r̂ − 5 (m₁·r̂)(m₂·r̂) r̂),

with ``F₁ = −F₂`` (Newton's third law) but ``τ₁ ≠ −τ₂``: the pair's angular momentum is
kept by ``τ₁ + τ₂ + r × F₂ = 0``. Two coaxial dipoles pull with ``3μ₀m₁m₂/(2π r⁴)``.
A uniformly magnetised sphere's outside field is exactly a point dipole's at its centre,
so for spherical magnets these formulas are exact, not an approximation, while the
spheres do not overlap. :func:`interactions` sums every pair of ``N`` dipoles without a
Python loop. Imports NumPy and SciPy's constants.
"""

from __future__ import annotations

import numpy as np
from scipy.constants import mu_0

from .quaternion import cross

#: The vacuum permeability (N/A², CODATA via SciPy).
MU0 = float(mu_0)
_K = MU0 / (4.0 * np.pi)


def _unit(r):
    r = np.asarray(r, dtype=float)
    dist = np.linalg.norm(r, axis=-1, keepdims=True)
    if np.any(dist == 0):
        raise ValueError("two dipoles at one point: their interaction is infinite")
    return r / dist, dist


def field(m, r) -> np.ndarray:
    """Field ``B`` (T) of dipoles ``m`` (..., 3) at offsets ``r`` (..., 3) (m) from them."""
    rhat, dist = _unit(r)
    m = np.asarray(m, dtype=float)
    return _K / dist**3 * (3.0 * np.sum(m * rhat, axis=-1, keepdims=True) * rhat - m)


def energy(m1, m2, r) -> np.ndarray:
    """Interaction energy ``−m₂·B₁(r)`` (J) of dipole pairs, ``r = x₂ − x₁`` (m), shape (...)."""
    return -np.sum(np.asarray(m2, dtype=float) * field(m1, r), axis=-1)


def force(m1, m2, r) -> np.ndarray:
    """Force (N) on dipole 2 from dipole 1, ``r = x₂ − x₁`` (m); broadcasts over (..., 3)."""
    rhat, dist = _unit(r)
    m1, m2 = np.asarray(m1, dtype=float), np.asarray(m2, dtype=float)
    a = np.sum(m1 * rhat, axis=-1, keepdims=True)
    b = np.sum(m2 * rhat, axis=-1, keepdims=True)
    c = np.sum(m1 * m2, axis=-1, keepdims=True)
    return 3.0 * _K / dist**4 * (a * m2 + b * m1 + (c - 5.0 * a * b) * rhat)


def torque(m1, m2, r) -> np.ndarray:
    """Torque (N m) on dipole 2 from dipole 1: ``m₂ × B₁(r)``, ``r = x₂ − x₁`` (m)."""
    return cross(np.asarray(m2, dtype=float), field(m1, r))


def interactions(x, m) -> tuple[np.ndarray, np.ndarray, float]:
    """Total force (N) and torque (N m) on each of ``N`` dipoles at ``x`` (N, 3) (m) with
    world moments ``m`` (N, 3) (A m²), and the total interaction energy (J)."""
    x, m = np.asarray(x, dtype=float), np.asarray(m, dtype=float)
    n = len(x)
    if n < 2:
        return np.zeros_like(x), np.zeros_like(x), 0.0
    i, j = np.triu_indices(n, 1)
    r = x[j] - x[i]
    f = force(m[i], m[j], r)
    forces = np.zeros_like(x)
    np.add.at(forces, j, f)
    np.add.at(forces, i, -f)
    torques = np.zeros_like(x)
    np.add.at(torques, j, torque(m[i], m[j], r))
    np.add.at(torques, i, torque(m[j], m[i], -r))
    return forces, torques, float(np.sum(energy(m[i], m[j], r)))


def coaxial_force(m1: float, m2: float, r: float) -> float:
    """Attraction (N) of two dipoles on one axis, pointing the same way: ``3μ₀m₁m₂/(2πr⁴)``."""
    return 3.0 * MU0 * m1 * m2 / (2.0 * np.pi * r**4)


def sphere_moment(radius: float, remanence: float) -> float:
    """Dipole moment (A m²) of a uniformly magnetised sphere: ``B_r V / μ₀`` for the
    remanence ``B_r`` (T) of its material (about 1.3 T for sintered NdFeB)."""
    return remanence * 4.0 / 3.0 * np.pi * radius**3 / MU0

"""Forces on particles, each a small vectorized function of positions and velocities.

Conventions: positions ``x`` and velocities ``v`` have shape ``(N, d)`` (N particles,
d = 2 or 3), masses ``(N,)``; every function returns forces ``(N, d)`` in newtons.
The factories (``constant_gravity``, ``drag``, ...) return a force ``F(t, x, v)`` ready
for :class:`course_lib.systems.NewtonianSystem`; add several with
:func:`course_lib.systems.sum_forces`.
"""

from __future__ import annotations

import numpy as np

from . import _validate
from .systems import split_state

#: Standard gravity (m/s²), pointing down the y axis as in the syllabus.
G_EARTH = np.array([0.0, -9.81, 0.0])
#: Gravitational constant (m³ kg⁻¹ s⁻²).
G_NEWTON = 6.674e-11


def _mass_column(mass, n: int) -> np.ndarray:
    m = np.broadcast_to(np.asarray(mass, dtype=float), (n,))
    return m[:, None]


def gravity_force(mass, g=G_EARTH) -> np.ndarray:
    """Weight ``m g`` of each particle: shape ``(N, d)`` with ``d = len(g)``."""
    g = np.asarray(g, dtype=float)
    m = np.atleast_1d(np.asarray(mass, dtype=float))
    return m[:, None] * g[None, :]


def constant_gravity(mass, g=G_EARTH):
    """Force ``F(t, x, v) = m g`` (uniform gravity). ``g`` must match the dimension of x."""
    g = _validate.state_array("g", g)

    def F(t, x, v):
        if x.shape[-1] != g.shape[-1]:
            raise ValueError(f"g has {g.shape[-1]} components but x is {x.shape[-1]}-D")
        return np.broadcast_to(_mass_column(mass, x.shape[0]) * g, x.shape).copy()

    return F


def nbody_gravity_force(x, mass, G: float = 1.0, softening: float = 0.0) -> np.ndarray:
    """Pairwise Newtonian gravitation ``F_i = -Σ_j G m_i m_j r_ij / (|r_ij|² + ε²)^{3/2}``.

    Parameters
    ----------
    x : ndarray, shape (N, d)
        Positions (m).
    mass : array_like, shape (N,)
        Masses (kg).
    G : float
        Gravitational constant in the units used (1 for a dimensionless demo).
    softening : float
        Plummer softening length ε (m): keeps close encounters finite.

    Returns
    -------
    ndarray, shape (N, d)
        Forces (N). They sum to zero (Newton's third law).

    Notes
    -----
    Vectorized over all pairs with broadcasting: O(N²) memory, fine for a few hundred
    bodies.
    """
    x = np.asarray(x, dtype=float)
    m = np.broadcast_to(np.asarray(mass, dtype=float), x.shape[:1])
    r = x[:, None, :] - x[None, :, :]                      # r_ij = x_i - x_j
    dist2 = np.sum(r * r, axis=-1) + softening**2
    np.fill_diagonal(dist2, np.inf)                        # no self-force
    inv_d3 = dist2**-1.5
    return -G * m[:, None] * np.einsum("ij,ijk->ik", m[None, :] * inv_d3, r)


def nbody_gravity(mass, G: float = 1.0, softening: float = 0.0):
    """Force factory for :func:`nbody_gravity_force`."""
    softening = float(softening)
    if softening < 0:
        raise ValueError(f"softening must be >= 0, got {softening}")

    def F(t, x, v):
        return nbody_gravity_force(x, mass, G, softening)

    return F


def nbody_potential_energy(x, mass, G: float = 1.0, softening: float = 0.0) -> np.ndarray:
    """``-Σ_{i<j} G m_i m_j / sqrt(|r_ij|² + ε²)`` (J); ``x`` may be ``(N, d)`` or ``(n, N, d)``."""
    x = np.asarray(x, dtype=float)
    m = np.asarray(mass, dtype=float)
    r = x[..., :, None, :] - x[..., None, :, :]
    dist = np.sqrt(np.sum(r * r, axis=-1) + softening**2)
    iu = np.triu_indices(x.shape[-2], 1)
    mm = (m[:, None] * m[None, :])[iu]
    return -G * np.sum(mm / dist[..., iu[0], iu[1]], axis=-1)


def linear_drag_force(v, b, wind=0.0) -> np.ndarray:
    """Viscous (Stokes) drag ``-b (v - w)``: ``b`` in kg/s (scalar or per particle ``(N,)``),
    wind ``w`` in m/s."""
    b = np.asarray(b, dtype=float)
    if b.ndim:
        b = b[:, None]
    return -b * (np.asarray(v, dtype=float) - wind)


def quadratic_drag_force(v, c, wind=0.0) -> np.ndarray:
    """Air drag ``-c |v - w| (v - w)``: ``c`` in kg/m (``½ ρ C_d A``), wind ``w`` in m/s."""
    rel = np.asarray(v) - wind
    speed = np.linalg.norm(rel, axis=-1, keepdims=True)
    return -float(c) * speed * rel


def drag(b: float = 0.0, c: float = 0.0, wind=0.0):
    """Force factory: linear drag ``b`` (kg/s) plus quadratic drag ``c`` (kg/m) in a wind.

    Terminal velocity of a falling mass with linear drag only is ``m g / b``.
    """
    b = float(b)
    c = float(c)
    if b < 0 or c < 0:
        raise ValueError(f"drag coefficients must be >= 0, got b={b}, c={c}")
    w = np.asarray(wind, dtype=float)

    def F(t, x, v):
        out = -b * (v - w)
        if c:
            out = out + quadratic_drag_force(v, c, w)
        return out

    return F


def viscous_damping(c: float):
    """Force factory ``-c v``: damping against absolute motion (kg/s), e.g. to calm a strand."""
    c = float(c)
    if c < 0:
        raise ValueError(f"c must be >= 0, got {c}")

    def F(t, x, v):
        return -c * v

    return F


def lorentz_force(v, q, B, E=None) -> np.ndarray:
    """Electromagnetic force ``q (E + v × B)`` on charges ``q`` (C), 3D only."""
    v = np.asarray(v, dtype=float)
    if v.shape[-1] != 3:
        raise ValueError(f"lorentz_force needs 3D velocities, got shape {v.shape}")
    q = np.asarray(q, dtype=float)
    q = q[..., None] if q.ndim else q
    out = np.cross(v, np.asarray(B, dtype=float))
    if E is not None:
        out = out + np.asarray(E, dtype=float)
    return q * out


def magnetic(q, B, E=None):
    """Force factory for :func:`lorentz_force`. A charge in a uniform ``B`` moves on a helix
    of radius ``m |v⊥| / (|q| |B|)`` with angular frequency ``|q| |B| / m``."""

    def F(t, x, v):
        return lorentz_force(v, q, B, E)

    return F


def attractor(center, strength: float, softening: float = 0.1):
    """Force factory pulling every particle toward ``center`` with ``strength / (r² + ε²)``
    (a user-steerable "magnet"); ``center`` may be a callable ``center(t)``."""

    def F(t, x, v):
        c = np.asarray(center(t) if callable(center) else center, dtype=float)
        r = c - x
        d2 = np.sum(r * r, axis=-1, keepdims=True) + softening**2
        return strength * r / d2**1.5

    return F


def angular_momentum(y, mass) -> np.ndarray:
    """Total angular momentum ``Σ m (x v_y - y v_x)`` (2D, scalar) of a state or trajectory."""
    x, v = split_state(y)
    return np.sum(np.asarray(mass) * (x[..., 0] * v[..., 1] - x[..., 1] * v[..., 0]), axis=-1)


def nbody_energy(y, mass, G: float = 1.0, softening: float = 0.0) -> np.ndarray:
    """Kinetic plus (softened) gravitational potential energy of a state or trajectory."""
    x, v = split_state(y)
    kinetic = 0.5 * np.sum(np.asarray(mass) * np.sum(v * v, axis=-1), axis=-1)
    return kinetic + nbody_potential_energy(x, mass, G, softening)

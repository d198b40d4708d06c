"""Forces on particles, each a small vectorized function of positions and velocities.

Conventions: positions ``x`` and velocities ``v`` have shape ``(N, d)`` (N particles,
d = 2 or 3), or ``(d,)`` for a single particle; masses and other per-particle
coefficients are scalars or ``(N,)``; every function returns forces of the shape of ``x``
(or ``v``) in newtons. The factories (``constant_gravity``, ``drag``, ...) return a force
``F(t, x, v)`` ready for :class:`course_lib.systems.NewtonianSystem`; add several with
:func:`course_lib.systems.sum_forces`. Imports: numpy, ``_validate``, ``systems`` (core).
"""

from __future__ import annotations

import numpy as np

from . import _validate
from .systems import split_particles

#: Standard gravity (m/s²), pointing down the y axis as in the syllabus.
G_EARTH = np.array([0.0, -9.81, 0.0])
#: Gravitational constant (m³ kg⁻¹ s⁻²).
G_NEWTON = 6.674e-11


def _per_particle(values, like: np.ndarray, name: str = "mass"):
    """A scalar or ``(N,)`` coefficient shaped to multiply vectors ``like`` ``(N, d)``/``(d,)``."""
    c = np.asarray(values, dtype=float)
    if c.ndim == 0:
        return c
    n = like.shape[0] if like.ndim >= 2 else 1
    if c.shape != (n,):
        raise ValueError(f"{name} must be a scalar or have one entry per particle ({n},), "
                         f"got shape {c.shape}")
    return c.reshape(-1, *([1] * (like.ndim - 1))) if like.ndim >= 2 else c[0]


def _nbody(name, mass, shape, G, softening, of="x"):
    """Masses (> 0, broadcast to ``shape`` if given), ``G`` > 0 and ``softening`` >= 0, checked."""
    m = _validate.positive_array(name, mass)
    if shape is not None:
        if m.ndim > 1 or (m.ndim == 1 and m.shape != shape):
            raise ValueError(f"{name} must be a scalar or have one entry per body of {of} {shape}, "
                             f"got {m.shape}")
        m = np.broadcast_to(m, shape)
    return m, _validate.positive_finite("G", G), _validate.nonnegative("softening", softening)


def gravity_force(mass, g=G_EARTH) -> np.ndarray:
    """Weight ``m g`` of each particle: shape ``(N, d)`` with ``d = len(g)``."""
    g = _validate.vector("g", g)
    m = np.atleast_1d(_validate.positive_array("mass", mass))
    return m[:, None] * g[None, :]


def constant_gravity(mass, g=G_EARTH):
    """Force ``F(t, x, v) = m g`` (uniform gravity). ``g`` must match the dimension of x;
    ``mass`` is a scalar or ``(N,)`` (kg); ``x`` is ``(N, d)`` or ``(d,)``."""
    g = _validate.vector("g", g)
    mass = _validate.positive_array("mass", mass)

    def F(t, x, v):
        x = np.asarray(x)
        if x.shape[-1:] != g.shape:
            raise ValueError(f"g has {g.size} components but x is {x.shape[-1:]}-D "
                             f"(x of shape {x.shape})")
        return np.broadcast_to(_per_particle(mass, x) * g, x.shape).copy()

    return F


#: Pairs per block of the N-body sums: the two work arrays (2 × PAIR_BLOCK floats) stay in
#: cache however many bodies there are.
PAIR_BLOCK = 32768


def _pair_blocks(x: np.ndarray, softening: float, power: int):
    """Yield ``(a, b, s)`` covering every pair once: for the bodies ``i`` in ``a:b`` and
    ``j >= a``, ``s[i - a, j - a] = (|x_i - x_j|² + ε²)^(-power/2)``, zero for ``i = j``.

    Pairs with ``j < a`` were in an earlier block (``s`` is symmetric in ``i, j``). ``s`` is a
    work array, overwritten by the next block.
    """
    n, dim = x.shape
    rows_of = np.ascontiguousarray(x.T)                     # (d, N): one row per component
    size = max(PAIR_BLOCK, n)
    r2_buf, s_buf = np.empty(size), np.empty(size)
    a = 0
    while a < n:
        b = min(n, a + max(1, size // (n - a)))
        shape = (b - a, n - a)
        r2 = r2_buf[: shape[0] * shape[1]].reshape(shape)
        s = s_buf[: shape[0] * shape[1]].reshape(shape)
        for k in range(dim):                                # r² = Σ_k (x_ik - x_jk)²
            target = r2 if k == 0 else s
            np.subtract(rows_of[k, a:b, None], rows_of[k, None, a:], out=target)
            np.multiply(target, target, out=target)
            if k:
                r2 += s
        if softening:
            r2 += softening**2
        np.sqrt(r2, out=s)                                  # r
        if power == 3:
            s *= r2                                         # r³
        own = np.arange(b - a)
        s[own, own] = 1.0                                   # self pairs: no division by zero
        np.divide(1.0, s, out=s)
        s[own, own] = 0.0                                   # ... and no self-interaction
        yield a, b, s
        a = b


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
    With the symmetric ``s_ij = (|r_ij|² + ε²)^{-3/2}`` the force is
    ``F_i = G m_i (Σ_j s_ij m_j x_j - x_i Σ_j s_ij m_j)``: matrix products. Each pair is
    computed once (Newton's third law gives the other half), a block of rows at a time
    (:data:`PAIR_BLOCK` pairs), so the work arrays stay in cache and take ``2 × PAIR_BLOCK``
    floats however large ``N`` is. Positions are taken about their mean, so that the two
    sums cancel as little as possible.
    """
    x = _validate.positions("x", x)
    return _nbody_force(x, *_nbody("mass", mass, x.shape[:1], G, softening))


def _nbody_force(x, m, G, softening):
    """:func:`nbody_gravity_force` on checked arguments (the force factory's every call)."""
    m = np.broadcast_to(m, x.shape[:1])
    centred = x - x.mean(axis=0)
    weighted = m[:, None] * centred                         # m_j x_j
    out = np.zeros_like(x)                                  # Σ_j s_ij m_j x_j
    pull = np.zeros(len(x))                                 # Σ_j s_ij m_j
    for a, b, s in _pair_blocks(centred, softening, 3):
        out[a:b] += s @ weighted[a:]                        # rows a:b, every j >= a ...
        pull[a:b] += s @ m[a:]
        later = s[:, b - a:]                                # ... and each j >= b, the rows a:b
        out[b:] += later.T @ weighted[a:b]
        pull[b:] += later.T @ m[a:b]
    out -= centred * pull[:, None]
    out *= (G * m)[:, None]
    return out


def nbody_gravity(mass, G: float = 1.0, softening: float = 0.0):
    """Force factory for :func:`nbody_gravity_force`."""
    mass, G, softening = _nbody("mass", mass, None, G, softening)

    def F(t, x, v):
        if np.ndim(x) == 1:                  # a lone body feels no pull
            return np.zeros(np.shape(x))
        return _nbody_force(np.asarray(x, dtype=float), mass, G, softening)

    return F


def nbody_potential_energy(x, mass, G: float = 1.0, softening: float = 0.0) -> np.ndarray:
    """``-Σ_{i<j} G m_i m_j / sqrt(|r_ij|² + ε²)`` (J); ``x`` may be ``(N, d)`` or ``(n, N, d)``.

    Each state is summed a block of rows at a time, like :func:`nbody_gravity_force`.
    """
    x = _validate.numbers("x", x)  # NaN rows allowed: a trajectory after a blow-up
    m, G, softening = _nbody("mass", mass, x.shape[-2:-1], G, softening)
    states = x.reshape(-1, *x.shape[-2:])
    if states.shape[1] <= 16:                              # few bodies: all pairs at once
        iu = np.triu_indices(states.shape[1], 1)
        r = states[:, iu[0]] - states[:, iu[1]]
        dist = np.sqrt(np.sum(r * r, axis=-1) + softening**2)
        energy = -G * np.sum(m[iu[0]] * m[iu[1]] / dist, axis=-1)
    else:
        energy = np.zeros(states.shape[0])
        for k, state in enumerate(states):
            for a, b, s_ in _pair_blocks(state, softening, 1):
                inside = m[a:b] @ (s_[:, : b - a] @ m[a:b])  # pairs within a:b, counted twice
                energy[k] -= G * (0.5 * inside + m[a:b] @ (s_[:, b - a:] @ m[b:]))
    return energy.reshape(x.shape[:-2])[()]


def linear_drag_force(v, b, wind=0.0) -> np.ndarray:
    """Viscous (Stokes) drag ``-b (v - w)``: ``b`` in kg/s (scalar or per particle ``(N,)``),
    wind ``w`` in m/s."""
    v, b = _validate.real_array("v", v), _validate.real_array("b", b)
    if np.any(b < 0):
        raise ValueError(f"b must be >= 0 (kg/s), got {b!r}")
    return -_per_particle(b, v, "b") * (v - _validate.real_array("wind", wind))


def quadratic_drag_force(v, c, wind=0.0) -> np.ndarray:
    """Air drag ``-c |v - w| (v - w)``: ``c`` in kg/m (``½ ρ C_d A``), wind ``w`` in m/s."""
    v, c = _validate.real_array("v", v), _validate.nonnegative("c", c)
    return _quadratic(v, c, _validate.real_array("wind", wind))


def _quadratic(v, c, wind):
    rel = v - wind
    speed = np.linalg.norm(rel, axis=-1, keepdims=True)
    return -float(c) * speed * rel


def drag(b: float = 0.0, c: float = 0.0, wind=0.0):
    """Force factory: linear drag ``b`` (kg/s) plus quadratic drag ``c`` (kg/m) in a wind.

    Terminal velocity of a falling mass with linear drag only is ``m g / b``.
    """
    b, c = _validate.nonnegative("b", b), _validate.nonnegative("c", c)
    w = _validate.real_array("wind", wind)

    def F(t, x, v):
        out = -b * (v - w)
        if c:
            out = out + _quadratic(np.asarray(v), c, w)
        return out

    return F


def viscous_damping(c: float):
    """Force factory ``-c v``: damping against absolute motion (kg/s), e.g. to calm a strand."""
    c = _validate.nonnegative("c", c)

    def F(t, x, v):
        return -c * v

    return F


def lorentz_force(v, q, B, E=None) -> np.ndarray:
    """Electromagnetic force ``q (E + v × B)`` on charges ``q`` (C), 3D only."""
    v = _validate.real_array("v", v)
    if v.shape[-1] != 3:
        raise ValueError(f"lorentz_force needs 3D velocities, got shape {v.shape}")
    q, B, E = _fields(q, B, E)
    return _lorentz(v, _per_particle(q, v, "q"), B, E)


def _fields(q, B, E):
    """Charges, ``B`` and ``E`` checked: finite, the fields 3-vectors."""
    B = _validate.real_array("B", B, (3,))
    return _validate.real_array("q", q), B, None if E is None else _validate.real_array("E", E, (3,))


def _lorentz(v, q, B, E):
    out = np.cross(v, B)
    return q * (out if E is None else out + E)


def magnetic(q, B, E=None):
    """Force factory for :func:`lorentz_force`. A charge in a uniform ``B`` moves on a helix
    of radius ``m |v⊥| / (|q| |B|)`` with angular frequency ``|q| |B| / m``."""
    q, B, E = _fields(q, B, E)

    def F(t, x, v):
        v = np.asarray(v, dtype=float)
        return _lorentz(v, _per_particle(q, v, "q"), B, E)

    return F


def attractor(center, strength: float, softening: float = 0.1):
    """Force factory pulling every particle toward ``center`` with ``strength / (r² + ε²)``
    (a user-steerable "magnet"); ``center`` may be a callable ``center(t)``."""
    center = center if callable(center) else _validate.vector("center", center)
    strength = _validate.finite_real("strength", strength)
    softening = _validate.nonnegative("softening", softening)

    def F(t, x, v):
        c = np.asarray(center(t) if callable(center) else center, dtype=float)
        r = c - x
        d2 = np.sum(r * r, axis=-1, keepdims=True) + softening**2
        return strength * r / d2**1.5

    return F


def angular_momentum(y, mass) -> np.ndarray:
    """Total angular momentum about the origin (kg m²/s) of a state or trajectory.

    2D: ``Σ m (x v_y - y v_x)``, a scalar per state. 3D: ``Σ m x × v``, shape ``(3,)`` per
    state. ``y`` is ``(2, N, d)``, ``(2, d)`` or a trajectory of them; ``mass`` scalar or ``(N,)``.
    """
    x, v = split_particles(_validate.numbers("y", y))
    m = _nbody("mass", mass, x.shape[-2:-1], 1.0, 0.0, "y")[0]
    if x.shape[-1] == 2:
        return np.sum(m * (x[..., 0] * v[..., 1] - x[..., 1] * v[..., 0]), axis=-1)
    if x.shape[-1] == 3:
        return np.sum(m[:, None] * np.cross(x, v), axis=-2)
    raise ValueError(f"angular_momentum needs 2D or 3D particles, got d = {x.shape[-1]}")


def nbody_energy(y, mass, G: float = 1.0, softening: float = 0.0) -> np.ndarray:
    """Kinetic plus (softened) gravitational potential energy (J) of a state or trajectory."""
    x, v = split_particles(_validate.numbers("y", y))
    m, G, softening = _nbody("mass", mass, x.shape[-2:-1], G, softening, "y")
    kinetic = 0.5 * np.sum(m * np.sum(v * v, axis=-1), axis=-1)
    return kinetic + nbody_potential_energy(x, m, G, softening)

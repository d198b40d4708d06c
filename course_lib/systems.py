"""Newtonian particle systems as first-order systems ``dy/dt = f(t, y)``.

Newton's second law ``m x'' = F(t, x, v)`` becomes two first-order equations,
``x' = v`` and ``v' = F / m``. We stack position and velocity along the first axis,
``y = (x, v)`` of shape ``(2, N, d)`` for ``N`` particles in ``d`` dimensions, so that
every integrator applies, and the symplectic ones can tell ``x`` from ``v``. A single
particle may also be stored without the particle axis: ``x`` of shape ``(d,)``, ``y`` of
shape ``(2, d)``. Imports: numpy and ``_validate`` (core layer).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from . import _validate

Force = Callable[[float, np.ndarray, np.ndarray], np.ndarray]


def stack_state(x, v) -> np.ndarray:
    """Stack positions and velocities, both ``(N, d)`` (or ``(d,)``), into ``y = (x, v)``."""
    x = _validate.state_array("x", x)
    v = _validate.state_array("v", v)
    if x.shape != v.shape:
        raise ValueError(f"x and v must have the same shape, got {x.shape} and {v.shape}")
    return np.stack((x, v))


def split_state(y) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`stack_state`: ``(x, v)`` views of ``y`` (or of a trajectory's ``y``).

    Accepts one state ``(2, ...)`` or a trajectory ``(n+1, 2, ...)``.
    """
    y = np.asarray(y)
    if y.ndim >= 1 and y.shape[0] == 2:
        return y[0], y[1]
    if y.ndim >= 2 and y.shape[1] == 2:
        return y[:, 0], y[:, 1]
    raise ValueError(f"y must be a stacked state (2, ...) or trajectory (n, 2, ...), got {y.shape}")


def split_particles(y) -> tuple[np.ndarray, np.ndarray]:
    """``(x, v)`` of a state or trajectory with the particle axis always present.

    Accepts a state ``(2, N, d)`` or ``(2, d)`` (one particle) and a trajectory
    ``(n, 2, N, d)`` or ``(n, 2, d)``; returns views of shape ``(..., N, d)`` (``N = 1``
    for one particle). A ``(2, 2, d)`` array is read as a state of two particles.
    """
    y = np.asarray(y)
    if y.ndim == 2 and y.shape[0] == 2:
        return y[0][None], y[1][None]
    if y.ndim == 3 and y.shape[0] == 2:
        return y[0], y[1]
    if y.ndim == 3 and y.shape[1] == 2:
        return y[:, 0, None], y[:, 1, None]
    if y.ndim == 4 and y.shape[1] == 2:
        return y[:, 0], y[:, 1]
    raise ValueError("y must be a particle state (2, N, d) or (2, d), or a trajectory of "
                     f"them (n, 2, N, d) or (n, 2, d); got shape {y.shape}")


def sum_forces(*forces: Force) -> Force:
    """The net force: ``F(t, x, v) = Σ forces_i(t, x, v)``."""
    for i, fn in enumerate(forces):
        _validate.callable_arg(f"forces[{i}]", fn, "(t, x, v)")

    def net(t: float, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        total = np.zeros(np.shape(x), dtype=np.result_type(x, float))
        for fn in forces:
            total += fn(t, x, v)
        return total

    return net


class NewtonianSystem:
    """``f(t, y)`` for particles with masses ``m`` under a net force ``F(t, x, v)``.

    Parameters
    ----------
    force : callable
        ``force(t, x, v) -> F`` with ``x``, ``v``, ``F`` of shape ``(N, d)`` (N), or
        ``(d,)`` for a single particle.
    mass : float or array_like, shape (N,)
        Masses (kg), > 0.
    pinned : sequence of int, optional
        Indices of particles held fixed, e.g. the root of a hair strand: their
        acceleration is zero, so they stay put as long as they start at rest.

    Notes
    -----
    Calling the system returns a new array ``dy/dt = (v, F/m)`` with ``y = (x, v)``. For
    a single particle, states of shape ``(2, d)`` work too.
    """

    def __init__(self, force: Force, mass, pinned: Sequence[int] | None = None):
        self.force = _validate.callable_arg("force", force, "(t, x, v)")
        m = _validate.state_array("mass", mass)
        if np.iscomplexobj(m) or m.ndim > 1 or np.any(m <= 0):
            raise ValueError(f"mass must be a real number > 0 or an (N,) array of them, got {m}")
        self.mass = m
        p = np.asarray([] if pinned is None else pinned)
        if p.size and (p.ndim != 1 or not np.issubdtype(p.dtype, np.integer)):
            raise TypeError(f"pinned must be a sequence of particle indices (ints), got {pinned!r}")
        p = p.astype(int)
        if p.size and (p.min() < 0 or (m.ndim == 1 and p.max() >= m.size)):
            raise ValueError(f"pinned indices must lie in [0, N) with N = {m.size if m.ndim else 'N'}"
                             f", got {p.tolist()}")
        self.pinned = p

    def _mass_column(self, x: np.ndarray) -> np.ndarray | float:
        if self.mass.ndim == 0:
            return self.mass
        n = x.shape[0] if x.ndim >= 2 else 1
        if self.mass.size != n:
            raise ValueError(f"mass has {self.mass.size} entries but the state has {n} "
                             "particle(s)")
        return self.mass.reshape(-1, *([1] * (x.ndim - 1))) if x.ndim >= 2 else self.mass[0]

    def acceleration(self, t: float, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``F / m`` (m/s²), zero for pinned particles; shape of ``x``."""
        F = np.asarray(self.force(t, x, v))
        if F.shape != x.shape:
            raise ValueError(f"force must return the shape of x, {x.shape}, got {F.shape}")
        a = F / self._mass_column(x)          # a new array, even if force reuses a buffer
        if self.pinned.size:
            if x.ndim == 1:
                a[...] = 0.0
            else:
                a[self.pinned] = 0.0
        return a

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        out = np.empty(y.shape, dtype=np.result_type(y, float))
        out[0] = y[1]
        out[1] = self.acceleration(t, y[0], y[1])
        return out

    def kinetic_energy(self, y) -> np.ndarray:
        """``½ Σ m |v|²`` (J) of a state (scalar) or a trajectory (``(n,)``)."""
        _, v = split_particles(y)
        m = np.broadcast_to(self.mass, v.shape[-2:-1])
        return 0.5 * np.sum(m * np.sum(v * v, axis=-1), axis=-1)

    def momentum(self, y) -> np.ndarray:
        """Total linear momentum ``Σ m v`` (kg m/s), shape ``(d,)`` or ``(n, d)``."""
        _, v = split_particles(y)
        m = np.broadcast_to(self.mass, v.shape[-2:-1])
        return np.sum(m[:, None] * v, axis=-2)


def newtonian(force: Force, mass, pinned: Sequence[int] | None = None) -> NewtonianSystem:
    """Shorthand for :class:`NewtonianSystem`."""
    return NewtonianSystem(force, mass, pinned)


def oscillator(omega: float = 1.0, damping: float = 0.0) -> Callable:
    """``f(t, y)`` of the 1D oscillator ``x'' = -ω² x - c x'`` with ``y = (x, v)``, shape (2,)."""
    omega = _validate.positive_finite("omega", omega)
    damping = _validate.finite_real("damping", damping)

    def f(t: float, y: np.ndarray) -> np.ndarray:
        return np.array([y[1], -(omega**2) * y[0] - damping * y[1]])

    return f


def oscillator_energy(y, omega: float = 1.0) -> np.ndarray:
    """``½ v² + ½ ω² x²`` per unit mass for states ``(..., 2)`` in the layout ``(x, v)``."""
    y = _validate.numbers("y", y)  # NaN rows allowed: a trajectory after a blow-up
    if y.ndim < 1 or y.shape[-1] != 2:
        raise ValueError(f"y must have shape (..., 2) in the layout (x, v), got {y.shape}")
    omega = _validate.positive_finite("omega", omega)
    return 0.5 * y[..., 1] ** 2 + 0.5 * omega**2 * y[..., 0] ** 2

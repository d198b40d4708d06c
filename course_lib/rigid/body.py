"""Rigid bodies as a structure of arrays: Baraff's state (x, q, P, L) and its time step.

After Baraff (2001), "Physically Based Modeling: Rigid Body Simulation" (SIGGRAPH course
notes), a body's state is its centre of mass ``x`` (m), orientation ``q`` (unit
quaternion, body to world), linear momentum ``P = m v`` (kg m/s) and angular momentum
``L`` (kg m²/s, world frame). Everything else is derived: ``v = P/m``, the rotation ``R``
of ``q``, the inverse world inertia ``I⁻¹ = R I_body⁻¹ Rᵀ`` and ``ω = I⁻¹ L``. The state
moves as

    dx/dt = v,   dq/dt = ½ (0, ω) ⊗ q,   dP/dt = F,   dL/dt = τ.

:class:`Bodies` holds ``N`` bodies of one shape (boxes or spheres) in ``(N, …)`` arrays.
:func:`step` kicks the momenta with the forces, lets a contact rule change them by
impulses, drifts the positions, and turns each body by a torque-free rotation step of
:mod:`course_lib.rigid.free` (implicit midpoint by default: it keeps ``|L|`` and the
rotational energy). :func:`simulate` repeats it and records frames.
Imports NumPy and the core.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from .. import _validate
from ..integrators import BlowUpError
from . import free, inertia
from . import quaternion as quat

SHAPES = ("box", "sphere")


@dataclass
class Bodies:
    """``N`` rigid bodies of one shape (all arrays have ``N`` rows).

    Attributes
    ----------
    mass : ndarray, shape (N,)
        Masses (kg).
    moments : ndarray, shape (N, 3)
        Principal moments of inertia (kg m²) about the body axes.
    x, q, P, L : ndarray, shapes (N, 3), (N, 4), (N, 3), (N, 3)
        Baraff's state: centre of mass (m), orientation, momentum (kg m/s), world angular
        momentum (kg m²/s).
    shape : str
        ``"box"`` (``size`` holds the side lengths, (N, 3), m) or ``"sphere"`` (``size``
        holds the radii, (N,), m).
    size : ndarray
    dipole : ndarray, shape (N, 3)
        Magnetic moment of each body in its body frame (A m²); zero if not a magnet.
    """

    mass: np.ndarray
    moments: np.ndarray
    x: np.ndarray
    q: np.ndarray
    P: np.ndarray
    L: np.ndarray
    shape: str
    size: np.ndarray
    dipole: np.ndarray = field(default=None)

    def __post_init__(self):
        if self.dipole is None:
            self.dipole = np.zeros_like(self.x)

    @property
    def n(self) -> int:
        return len(self.mass)

    @property
    def v(self) -> np.ndarray:
        """Velocities ``P/m`` (m/s), (N, 3)."""
        return self.P / self.mass[:, None]

    @property
    def R(self) -> np.ndarray:
        """Rotation matrices (body to world), (N, 3, 3)."""
        return quat.to_matrix(self.q)

    @property
    def inv_inertia(self) -> np.ndarray:
        """Inverse world inertia tensors ``R I_body⁻¹ Rᵀ`` (1/(kg m²)), (N, 3, 3)."""
        return inertia.world_inverse(self.R, self.moments)

    @property
    def omega(self) -> np.ndarray:
        """World angular velocities ``I⁻¹ L`` (rad/s), (N, 3)."""
        body = quat.rotate(quat.conjugate(self.q), self.L) / self.moments
        return quat.rotate(self.q, body)

    @property
    def magnetic_moment(self) -> np.ndarray:
        """World-frame dipole moments ``R m_body`` (A m²), (N, 3)."""
        return quat.rotate(self.q, self.dipole)

    def kinetic_energy(self) -> np.ndarray:
        """Translational plus rotational kinetic energy of each body (J), (N,)."""
        body_L = quat.rotate(quat.conjugate(self.q), self.L)
        return 0.5 * np.sum(self.P**2, axis=1) / self.mass + free.energy(body_L, self.moments)

    def copy(self) -> Bodies:
        return replace(self, **{k: np.array(getattr(self, k)) for k in
                                ("mass", "moments", "x", "q", "P", "L", "size", "dipole")})


def _rows(name, value, n, width):
    arr = _validate.state_array(name, value)
    arr = np.broadcast_to(arr, (n, width)) if arr.ndim == 1 else arr
    return _validate.shape_of(name, np.array(arr, dtype=float), (n, width))


def make(shape: str, mass, size, x, q=None, v=None, omega=None, dipole=None) -> Bodies:
    """Bodies of one ``shape`` (``"box"``: ``size`` the sides (3,) or (N, 3) in m;
    ``"sphere"``: the radius, scalar or (N,), m), solid and uniform, at centres ``x``
    (N, 3) with orientations ``q`` (default identity), velocities ``v`` (m/s) and world
    angular velocities ``omega`` (rad/s), default at rest; ``dipole`` (A m², body frame)."""
    _validate.choice("shape", shape, SHAPES)
    x = _validate.state_array("x", x)
    x = _validate.shape_of("x", x[None] if x.ndim == 1 else x, (None, 3))
    n = len(x)
    mass = np.broadcast_to(_validate.state_array("mass", mass), (n,)).astype(float)
    if np.any(mass <= 0):
        raise ValueError(f"mass must be > 0 (kg), got {mass.tolist()}")
    if shape == "box":
        size = _rows("size", size, n, 3)
        moments = np.array([inertia.box_moments(m, s) for m, s in zip(mass, size, strict=True)])
    else:
        size = np.broadcast_to(_validate.state_array("size", size), (n,)).astype(float)
        moments = np.array([inertia.sphere_moments(m, r) for m, r in zip(mass, size, strict=True)])
    q = quat.normalize(_rows("q", quat.IDENTITY if q is None else q, n, 4))
    v = _rows("v", np.zeros(3) if v is None else v, n, 3)
    omega = _rows("omega", np.zeros(3) if omega is None else omega, n, 3)
    body_omega = quat.rotate(quat.conjugate(q), omega)
    L = quat.rotate(q, moments * body_omega)
    dip = _rows("dipole", np.zeros(3) if dipole is None else dipole, n, 3)
    return Bodies(mass, moments, x.astype(float), q, mass[:, None] * v, L, shape, size, dip)


def derivative(b: Bodies, force, torque) -> tuple[np.ndarray, ...]:
    """Baraff's ``d/dt (x, q, P, L) = (v, ½ (0, ω) ⊗ q, F, τ)`` for forces and torques (N, 3)."""
    omega = b.omega
    pure = np.concatenate((np.zeros((b.n, 1)), omega), axis=1)
    return b.v, 0.5 * quat.multiply(pure, b.q), np.asarray(force, float), np.asarray(torque, float)


def step(b: Bodies, dt: float, forces: Callable | None = None, contact: Callable | None = None,
         method: str = "implicit_midpoint") -> Bodies:
    """Advance ``b`` by ``dt`` (s) in place and return it.

    ``forces(b) -> (F, τ)`` gives forces (N) and torques (N m), each (N, 3), at the start
    of the step; ``contact(b, dt, before)`` changes ``b.P`` and ``b.L`` by impulses
    (velocity level; ``before`` holds the momenta before the forces acted) and may define
    ``contact.project(b)``, called after the drift to undo deep penetration. The rotation
    uses ``method`` of :data:`course_lib.rigid.free.METHODS`.
    """
    dt = _validate.positive_finite("dt", dt)
    _validate.choice("method", method, free.METHODS)
    before = (b.P, b.L)
    if forces is not None:
        F, tau = forces(b)
        b.P = b.P + dt * F
        b.L = b.L + dt * tau
    if contact is not None:
        contact(b, dt, before)
    b.x = b.x + dt * b.v
    body_L = quat.rotate(quat.conjugate(b.q), b.L)
    b.q, body_L = free.rotate(b.q, body_L, b.moments, dt, method)
    b.L = quat.rotate(b.q, body_L)
    if contact is not None and hasattr(contact, "project"):
        contact.project(b)
    return b


@dataclass
class Run:
    """Recorded frames of :func:`simulate`: times ``t`` (F,), and ``x``, ``q``, ``P``, ``L``
    of shapes (F, N, 3), (F, N, 4), (F, N, 3), (F, N, 3); ``bodies`` the final state."""

    t: np.ndarray
    x: np.ndarray
    q: np.ndarray
    P: np.ndarray
    L: np.ndarray
    bodies: Bodies


def simulate(b: Bodies, dt: float, steps: int, forces=None, contact=None, every: int = 1,
             method: str = "implicit_midpoint") -> Run:
    """Run :func:`step` ``steps`` times on a copy of ``b``, recording every ``every`` steps
    (and the start). Raises ``BlowUpError`` when the state stops being finite."""
    dt = _validate.positive_finite("dt", dt)
    steps = _validate.positive_int("steps", steps)
    every = _validate.positive_int("every", every)
    _validate.choice("method", method, free.METHODS)
    b = b.copy()
    frames = {k: [np.array(getattr(b, k))] for k in ("x", "q", "P", "L")}
    for k in range(1, steps + 1):
        step(b, dt, forces, contact, method)
        if k % every == 0:
            if not (np.all(np.isfinite(b.x)) and np.all(np.isfinite(b.L))):
                raise BlowUpError(f"the bodies' state is not finite at step {k}, t = {k * dt:g} s")
            for name, rows in frames.items():
                rows.append(np.array(getattr(b, name)))
    t = dt * every * np.arange(len(frames["x"]))
    return Run(t, *(np.array(frames[k]) for k in ("x", "q", "P", "L")), bodies=b)

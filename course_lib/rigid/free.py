"""Torque-free rotation: Euler's equations and six ways to step them.

With no torque, the angular momentum ``L`` is constant in the world frame; in the body
frame (principal axes, moments ``I``) it obeys Euler's equations

    dL/dt = L × Ω,   Ω = L / I  (the body angular velocity, rad/s),

and the orientation follows ``dq/dt = ½ q ⊗ (0, Ω)``. Two quantities are invariant: the
length ``|L|`` and the kinetic energy ``E = ½ L·Ω``. The gyroscopic term ``L × Ω`` is
what a method must treat with care. Methods (:data:`METHODS`), each one step of
``(q, L_body)`` in :func:`rotate`:

- ``"forward_euler"``: explicit Euler on ``L`` and the Cayley step of ``q`` with ``Ω``
  at the start; ``|L|²`` and ``E`` grow every step (by ``Δt²|L×Ω|²`` and
  ``½Δt²(L×Ω)·I⁻¹(L×Ω)``);
- ``"baraff_euler"``: Baraff's (2001) explicit Euler in the world frame: ``L_world`` stays
  constant, the orientation takes the renormalised quaternion step with ``Ω`` at the
  start; ``|L|`` is exact, ``E`` still grows every step;
- ``"rk4"``: classical Runge–Kutta on ``(L, q)``, ``q`` renormalised; small drifts;
- ``"backward_euler"``: implicit Euler on ``L`` (the "implicit gyroscopic" step of game
  engines); ``|L|`` and ``E`` decay every step;
- ``"implicit_midpoint"``: the midpoint rule on ``L`` (solved by Newton's method), with
  the orientation turned by the Cayley rotation of ``Δt Ω_mid``; it conserves both
  quadratic invariants and, with that rotation, ``L_world`` exactly (Hairer, Lubich &
  Wanner 2006, *Geometric Numerical Integration*, IV.1 and VII.5);
- ``"splitting"``: the symplectic Lie–Poisson splitting of ``E = Σ L_i²/2I_i`` into three
  exact rotations about the body axes, composed 1, 2, 3, 2, 1 (Dullweber, Leimkuhler &
  McLachlan 1997; McLachlan 1993): ``|L|`` and ``L_world`` exact, ``E`` within ``O(Δt²)``
  for all time, without drift.

Imports NumPy and the core (:mod:`course_lib._validate`, the quaternion module).
"""

from __future__ import annotations

import math

import numpy as np

from .. import _validate
from ..integrators import BlowUpError
from . import _spin
from . import quaternion as quat
from .inertia import check_moments

METHODS = ("forward_euler", "baraff_euler", "rk4", "backward_euler", "implicit_midpoint", "splitting")
#: Newton's method stops when the update is this many units of round-off of |L|.
NEWTON_TOL_ULPS = 4.0
NEWTON_MAX_ITER = 40


def gyroscopic(L, moments) -> np.ndarray:
    """The right side of Euler's equations, ``L × (L / I)`` (body frame), shape ``(..., 3)``."""
    return quat.cross(L, L / moments)


def energy(L, moments) -> np.ndarray:
    """Kinetic energy ``½ Σ L_i² / I_i`` (J) of body angular momenta ``L`` (..., 3)."""
    return 0.5 * np.sum(L * L / moments, axis=-1)


def implicit_solve(L, moments, dt: float, theta: float) -> np.ndarray:
    """Solve ``L1 = L + Δt g(Lθ)``, ``Lθ = (1 − θ) L + θ L1``, ``g`` :func:`gyroscopic`, by
    Newton's method (vectorized over bodies); ``θ = ½`` is the midpoint rule, ``θ = 1``
    backward Euler. Raises ``BlowUpError`` if Newton's method does not converge (a step
    far too long for the spin)."""
    L1 = L + dt * gyroscopic(L, moments)
    scale = NEWTON_TOL_ULPS * np.finfo(float).eps * np.linalg.norm(L, axis=-1)
    for _ in range(NEWTON_MAX_ITER):
        Lt = (1.0 - theta) * L + theta * L1
        residual = L1 - L - dt * gyroscopic(Lt, moments)
        jac = np.eye(3) - dt * theta * (quat.hat(Lt) / moments[..., None, :] - quat.hat(Lt / moments))
        delta = np.linalg.solve(jac, residual[..., None])[..., 0]
        L1 = L1 - delta
        if np.all(np.linalg.norm(delta, axis=-1) <= scale):
            return L1
    raise BlowUpError(f"Newton's method did not converge in {NEWTON_MAX_ITER} iterations: "
                      f"the step dt = {dt:g} s is too long for this spin")


def _axis_rotation(angle, axis: int) -> np.ndarray:
    """Quaternions of rotations by ``angle`` (...,) about the body axis ``axis``."""
    q = np.zeros((*np.shape(angle), 4))
    q[..., 0] = np.cos(0.5 * angle)
    q[..., 1 + axis] = np.sin(0.5 * angle)
    return q


def _split_flow(q, L, moments, h: float, axis: int):
    """Exact flow of ``L_i² / 2I_i`` for a time ``h``: the body turns about its axis ``i`` at
    ``Ω_i``, and ``L`` (body frame) turns the other way."""
    turn = _axis_rotation(h * L[..., axis] / moments[..., axis], axis)
    return quat.multiply(q, turn), quat.rotate(quat.conjugate(turn), L)


def _rk4(q, L, moments, dt):
    def f(q, L):
        omega = L / moments
        pure = np.concatenate((np.zeros((*omega.shape[:-1], 1)), omega), axis=-1)
        return 0.5 * quat.multiply(q, pure), quat.cross(L, omega)

    k1 = f(q, L)
    k2 = f(q + 0.5 * dt * k1[0], L + 0.5 * dt * k1[1])
    k3 = f(q + 0.5 * dt * k2[0], L + 0.5 * dt * k2[1])
    k4 = f(q + dt * k3[0], L + dt * k3[1])
    q1 = q + dt / 6.0 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
    L1 = L + dt / 6.0 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    return quat.normalize(q1), L1


def rotate(q, L, moments, dt: float, method: str = "implicit_midpoint"):
    """One torque-free step of orientations ``q`` (..., 4) and body angular momenta ``L``
    (..., 3) (kg m²/s) of bodies with principal ``moments`` (..., 3) (kg m²) by ``dt`` (s).

    Returns the new ``(q, L)``. The methods are listed in the module's docstring.
    """
    if method == "forward_euler":
        omega = L / moments
        return quat.body_step(q, omega, dt), L + dt * quat.cross(L, omega)
    if method == "baraff_euler":
        # L_world is constant: the body-frame L turns back by the body's own rotation.
        half = np.concatenate((np.ones((*L.shape[:-1], 1)), 0.5 * dt * L / moments), axis=-1)
        turn = quat.normalize(half)
        return quat.multiply(q, turn), quat.rotate(quat.conjugate(turn), L)
    if method == "rk4":
        return _rk4(q, L, moments, dt)
    if method == "backward_euler":
        L1 = implicit_solve(L, moments, dt, 1.0)
        return quat.body_step(q, L1 / moments, dt), L1
    if method == "implicit_midpoint":
        L1 = implicit_solve(L, moments, dt, 0.5)
        return quat.body_step(q, 0.5 * (L + L1) / moments, dt), L1
    if method == "splitting":
        for axis, h in ((0, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5)):
            q, L = _split_flow(q, L, moments, h * dt, axis)
        return q, L
    raise ValueError(f"unknown method {method!r}; valid choices are: {', '.join(METHODS)}")


def free_body(inertia, omega0, dt: float, steps: int, method: str = "implicit_midpoint",
              q0=None):
    """Torque-free motion of a rigid body from body angular velocity ``omega0``.

    Parameters
    ----------
    inertia : array_like, shape (3,)
        Principal moments of inertia (kg m²), > 0.
    omega0 : array_like, shape (3,)
        Initial angular velocity in the body frame (rad/s).
    dt : float
        Step (s), > 0.
    steps : int
        Number of steps, ≥ 1.
    method : str
        One of :data:`METHODS` (see the module's docstring).
    q0 : array_like, shape (4,), optional
        Initial orientation (unit quaternion, scalar first); default the identity.

    Returns
    -------
    t : ndarray, shape (steps+1,)
        Times ``k dt`` (s).
    omega : ndarray, shape (steps+1, 3)
        Body angular velocity (rad/s) after each step.
    q : ndarray, shape (steps+1, 4)
        Orientation (body to world) after each step.

    Raises
    ------
    BlowUpError
        If the run stops being finite or its spin grows a millionfold (an explicit
        method with far too long a step).
    """
    moments = check_moments("inertia", inertia)
    if moments.shape != (3,):
        raise ValueError(f"inertia must have shape (3,), got {moments.shape}")
    omega0 = _validate.shape_of("omega0", _validate.state_array("omega0", omega0), (3,))
    if np.iscomplexobj(omega0):
        raise TypeError("omega0 must be real (rad/s)")
    dt = _validate.positive_finite("dt", dt)
    steps = _validate.positive_int("steps", steps)
    _validate.choice("method", method, METHODS)
    q = quat.IDENTITY.copy() if q0 is None else _validate.shape_of(
        "q0", _validate.state_array("q0", q0), (4,))
    q = tuple(quat.normalize(q).tolist())
    mom = tuple(moments.tolist())
    L = tuple((moments * omega0).tolist())
    bound = 1e6 * max(math.sqrt(sum(x * x for x in L)), np.finfo(float).tiny)
    Ls, qs = np.empty((steps + 1, 3)), np.empty((steps + 1, 4))
    Ls[0], qs[0] = L, q
    # One body: the step is plain float arithmetic (see _spin); the arrays fill row by row.
    for k in range(1, steps + 1):
        try:
            q, L = _spin.step(q, L, mom, dt, method, NEWTON_TOL_ULPS, NEWTON_MAX_ITER)
        except (OverflowError, ZeroDivisionError):
            L = (math.nan,) * 3
        if not math.sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]) <= bound:
            raise BlowUpError(f"free_body with {method} blew up at step {k}, t = {k * dt:g} s: "
                              f"|L| passed a million times its start; take a smaller dt")
        Ls[k], qs[k] = L, q
    return dt * np.arange(steps + 1), Ls / moments, qs

"""Checks for notebook 04, beyond Euler.

Exercises:

- :func:`midpoint_step`: one explicit midpoint (RK2) step ``(f, t, y, dt) -> y_next``,
  compared with :func:`course_lib.midpoint`.
- :func:`backward_euler_decay`: backward Euler on ``dx/dt = -k x`` in closed form,
  ``x_n = x0 / (1 + k dt)^n``, compared with both the formula and the general implicit
  solver (``course_lib.integrate(..., method="backward_euler")``, Newton's method).
"""

from __future__ import annotations

import numpy as np

from .. import fields
from ..integrators import integrate, midpoint
from . import Checker, exercise

_START_TWICE = (
    "you used the start slope f(t, y) for the whole step (that is forward Euler): take "
    "the slope AGAIN at the midpoint, f(t + dt/2, y_mid), and step with that one"
)
_TIME_AT_START = (
    "the second slope belongs to the middle of the step: evaluate f at time t + dt/2, "
    "not at t"
)
_TIME_AT_END = "the second slope belongs to the middle of the step: time t + dt/2, not t + dt"
_FULL_PREDICTOR = (
    "the midpoint is half a step away: y_mid = y + (dt/2) f(t, y), not y + dt f(t, y)"
)
_HEUN = (
    "that is Heun's method (average of the start and end slopes); the midpoint method "
    "uses ONE slope, taken at the midpoint"
)
_RETURNED_MID = (
    "you returned the half-step prediction y_mid; the step is y + dt * f(t + dt/2, y_mid)"
)


def pulsing_vortex(t, X):
    """The vortex ``V = ω(t) (-y, x)`` whose rate ``ω(t) = 1 + cos(t)/2`` pulses in time.

    Exact solution from ``(r, φ0)``: radius ``r``, angle ``φ0 + t + sin(t)/2``.
    """
    return (1.0 + 0.5 * np.cos(t)) * fields.vortex(t, X)


def _decay(t, y):
    return -2.0 * y


_MIDPOINT_CASES = [
    ("vortex from (0, 1), dt = 0.5", fields.vortex, 0.0, [0.0, 1.0], 0.5),
    ("vortex, three particles at once, dt = 0.1", fields.vortex, 0.0,
     [[1.0, 0.0], [0.0, 2.0], [-1.5, 0.5]], 0.1),
    ("decay dy/dt = -2y, dt = 0.25", _decay, 0.0, [1.5], 0.25),
    ("pulsing vortex at t = 0.7, dt = 0.4", pulsing_vortex, 0.7, [0.8, -0.6], 0.4),
]


@exercise
def midpoint_step(ck: Checker, student) -> None:
    """Compare ``student(f, t, y, dt)`` with :func:`course_lib.midpoint`."""
    def mistakes(f, t, y, dt):
        k1 = f(t, y)
        y_mid = y + 0.5 * dt * k1
        return {
            _START_TWICE: y + dt * k1,
            _TIME_AT_START: y + dt * f(t, y_mid),
            _TIME_AT_END: y + dt * f(t + dt, y_mid),
            _FULL_PREDICTOR: y + dt * f(t + 0.5 * dt, y + dt * k1),
            _HEUN: y + 0.5 * dt * (k1 + f(t + dt, y + dt * k1)),
            _RETURNED_MID: y_mid,
        }

    ck.one_step_cases(student, _MIDPOINT_CASES, midpoint, mistakes,
                      hint="y_mid = y + (dt/2) f(t, y); y_next = y + dt f(t + dt/2, y_mid)")


_DECAY_CASES = [(1.0, 1.0, 0.1, 10), (2.0, 5.0, 0.5, 6), (1.0, 100.0, 0.1, 5), (3.0, 0.5, 2.0, 0)]


def decay_closed_form(x0: float, k: float, dt: float, n: int) -> np.ndarray:
    """Backward Euler on ``dx/dt = -k x``: ``x_j = x0 / (1 + k dt)^j`` for ``j = 0..n``."""
    return x0 / (1.0 + k * dt) ** np.arange(n + 1)


def decay_newton(x0: float, k: float, dt: float, n: int) -> np.ndarray:
    """The same run by course_lib's general implicit solver (Newton's method)."""
    if n == 0:
        return np.array([float(x0)])
    traj = integrate(lambda t, x: -k * x, [x0], (0.0, n * dt), dt, method="backward_euler")
    return traj.y[:, 0]


@exercise
def backward_euler_decay(ck: Checker, student) -> None:
    """``student(x0, k, dt, n)`` must return ``[x_0, ..., x_n]`` of backward Euler on decay."""
    for x0, k, dt, n in _DECAY_CASES:
        what = f"x0 = {x0:g}, k = {k:g}/s, dt = {dt:g} s (k dt = {k * dt:g}), n = {n}"
        formula = decay_closed_form(x0, k, dt, n)
        newton = decay_newton(x0, k, dt, n)
        # The two references must agree, or the comparison below would mean nothing.
        assert np.allclose(formula, newton, rtol=1e-12, atol=1e-15)
        got = np.asarray(student(x0, k, dt, n), dtype=float)
        if got.shape == (n,) and n > 0:
            ck.expect(False, what, f"expected {n + 1} values x_0 ... x_n, got {n}",
                      "include the initial value x_0 = x0 as the first entry")
            continue
        j = np.arange(n + 1)
        mistakes = {
            "x0 (1 - k dt)^n is FORWARD Euler; backward Euler solves x_next = x + dt (-k x_next) "
            "for x_next": x0 * (1.0 - k * dt) ** j,
            "sign: x_next = x - k dt x_next gives x_next (1 + k dt) = x, so divide by "
            "(1 + k dt)": x0 / (1.0 - k * dt) ** j if k * dt != 1 else np.full(n + 1, np.nan),
            "x0 e^(-k t) is the exact solution, not what backward Euler computes":
                x0 * np.exp(-k * dt * j),
            "the factor is 1/(1 + k dt): you left out dt": x0 / (1.0 + k) ** j,
        }
        ok = ck.close(got, formula, what, rtol=1e-10, atol=1e-15,
                      hint="x_n = x0 / (1 + k dt)^n", mistakes=mistakes)
        if ok:
            ck.passed[-1] += " (matches the closed form and course_lib's Newton solver)"

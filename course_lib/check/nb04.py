"""Checks for notebook 04, beyond Euler.

Exercises:

- :func:`midpoint_step`: one explicit midpoint (RK2) step ``(f, t, y, dt) -> y_next``,
  compared with :func:`course_lib.midpoint`.
- :func:`backward_euler_decay`: backward Euler on ``dx/dt = -k x`` in closed form,
  ``x_n = x0 / (1 + k dt)^n``, compared with both the formula and the general implicit
  solver (``course_lib.integrate(..., method="backward_euler")``, Newton's method).
- :func:`implicit_midpoint_step`: one step of the implicit midpoint rule, solved to
  round-off, checked on nonlinear, time-dependent, many-particle and stiff problems (where
  fixed-point iteration diverges) against an independent solve, and for keeping ``|X|``
  exactly on a nonlinear swirl.
"""

from __future__ import annotations

import numpy as np

from .. import fields
from ..integrators import integrate, midpoint
from . import Checker, exercise
from ._answers import as_array, call, close, pure_call, rtol_for, step_cases

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
_FROZEN_T = (
    "pass the step's time to f: this field changes with time, and you evaluated it as if "
    "the step started at t = 0"
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


@exercise(allow=())
def midpoint_step(ck: Checker, student) -> None:
    """Compare ``student(f, t, y, dt)`` with :func:`course_lib.midpoint`."""
    def mistakes(f, t, y, dt):
        k1 = f(t, y)
        y_mid = y + 0.5 * dt * k1
        return {
            _FROZEN_T: y + dt * f(0.5 * dt, y + 0.5 * dt * f(0.0, y)),
            _START_TWICE: y + dt * k1,
            _TIME_AT_START: y + dt * f(t, y_mid),
            _TIME_AT_END: y + dt * f(t + dt, y_mid),
            _FULL_PREDICTOR: y + dt * f(t + 0.5 * dt, y + dt * k1),
            _HEUN: y + 0.5 * dt * (k1 + f(t + dt, y + dt * k1)),
            _RETURNED_MID: y_mid,
            "step the whole dt with the midpoint slope, not dt/2":
                y + 0.5 * dt * f(t + 0.5 * dt, y_mid),
        }

    step_cases(ck, student, _MIDPOINT_CASES, midpoint, mistakes,
               hint=("predict the state half a step ahead, then step the whole dt with the slope "
                     "there", "y_mid = y + (dt/2) f(t, y); y_next = y + dt f(t + dt/2, y_mid)"))


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


@exercise(allow=(), forbid=("scipy.optimize",))
def backward_euler_decay(ck: Checker, student) -> None:
    """``student(x0, k, dt, n)`` must return ``[x_0, ..., x_n]`` of backward Euler on decay."""
    for x0, k, dt, n in _DECAY_CASES:
        what = f"x0 = {x0:g}, k = {k:g}/s, dt = {dt:g} s (k dt = {k * dt:g}), n = {n}"
        formula = decay_closed_form(x0, k, dt, n)
        newton = decay_newton(x0, k, dt, n)
        # The two references must agree, or the comparison below would mean nothing.
        assert np.allclose(formula, newton, rtol=1e-12, atol=1e-15)
        ok, got = call(ck, what, student, x0, k, dt, n)
        if not ok:
            continue
        answer = as_array(got)
        if answer is not None and answer.shape == (n,) and n > 0:
            # One value short: which end is missing?
            if np.allclose(answer, formula[1:], rtol=rtol_for(answer, 1e-10)):
                hint = "include the initial value x_0 = x0 as the first entry"
            elif np.allclose(answer, formula[:-1], rtol=rtol_for(answer, 1e-10)):
                hint = ("your array stops at x_(n-1): the last value x_n is missing (n steps "
                        "give n + 1 values)")
            else:
                hint = "return the n + 1 values x_0, x_1, ..., x_n"
            ck.expect(False, what, f"expected {n + 1} values x_0 ... x_n, got {n}", hint)
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
            "start from the initial value: multiply by x0": 1.0 / (1.0 + k * dt) ** j,
        }
        ok = close(ck, got, formula, what, rtol=1e-10, atol=1e-15, mistakes=mistakes,
                   hint=("solve x_next = x + dt (-k x_next) for x_next: each step multiplies by "
                         "the same factor", "x_n = x0 / (1 + k dt)^n"))
        if ok:
            ck.passed[-1] += " (matches the closed form and course_lib's Newton solver)"


# --- the implicit midpoint rule ----------------------------------------------------------

_J = np.array([[0.0, -1.0], [1.0, 0.0]])


def swirl(t, X):
    """A nonlinear vortex, ``V = (1 + x) (-y, x)``: ``|X|`` is invariant, the speed is not."""
    X = np.asarray(X, dtype=float)
    return (1.0 + X[..., :1]) * np.stack((-X[..., 1], X[..., 0]), axis=-1)


def _pendulum(t, y):
    return np.array([y[1], -np.sin(y[0])])


def _stiff(t, y):
    return -50.0 * y


#: (description, f, t, y, dt, keeps |y|).
MIDPOINT_RULE_CASES = [
    ("the swirl V = (1 + x)(-y, x) from (1, 0.5), dt = 0.4", swirl, 0.0, [1.0, 0.5], 0.4, True),
    ("a pendulum θ'' = -sin θ from (2, 0), dt = 0.3", _pendulum, 0.0, [2.0, 0.0], 0.3, False),
    ("the pulsing vortex at t = 0.7, dt = 0.4 (time-dependent)", pulsing_vortex, 0.7,
     [0.8, -0.6], 0.4, True),
    ("5 particles in the swirl, y of shape (5, 2), dt = 0.2", swirl, 0.0,
     [[0.3, 0.1], [0.5, -0.4], [-0.2, 0.6], [0.1, 0.1], [-0.5, -0.3]], 0.2, False),
    ("a stiff decay dy/dt = -50 y, dt = 0.5 (dt |∂f/∂y| / 2 = 12.5)", _stiff, 0.0, [1.0], 0.5,
     False),
]


def implicit_midpoint_reference(f, t, y, dt):
    """``Y = y + dt f(t + dt/2, (y + Y)/2)``, solved by ``scipy.optimize.root`` to 1e-14."""
    from scipy.optimize import root

    y = np.asarray(y, dtype=float)

    def residual(flat):
        Y = flat.reshape(y.shape)
        return (Y - y - dt * f(t + 0.5 * dt, 0.5 * (y + Y))).ravel()

    guess = (y + dt * f(t, y)).ravel()
    sol = root(residual, guess, tol=1e-14)
    return sol.x.reshape(y.shape)


@exercise(allow=(), forbid=("scipy.optimize",))
def implicit_midpoint_step(ck: Checker, student) -> None:
    """``student(f, t, y, dt)``: the implicit midpoint rule, solved to round-off.

    Newton's method is the exercise: a solver that does it (``scipy.optimize``) or a library
    step that does (``2 * backward_euler(f, t, y, dt/2) - y``) is refused."""
    for what, f, t, y, dt, keeps_norm in MIDPOINT_RULE_CASES:
        y = np.asarray(y, dtype=float)
        expected = implicit_midpoint_reference(f, t, y, dt)
        mid = y + 0.5 * dt * f(t, y)
        with np.errstate(all="ignore"):
            mistakes = {
                "that is the trapezoid: the implicit midpoint evaluates f once, at the average "
                "state (y + Y)/2 and time t + dt/2": _trapezoid_reference(f, t, y, dt),
                "that is the EXPLICIT midpoint: here the midpoint state is (y + Y)/2, with the "
                "unknown end Y; solve for Y": y + dt * f(t + 0.5 * dt, mid),
                "evaluate f at the middle of the step, time t + dt/2, not at t":
                    implicit_midpoint_reference(lambda s, u, f=f, t=t: f(t, u), t, y, dt),
                _FROZEN_T: implicit_midpoint_reference(lambda s, u, f=f, t=t: f(s - t, u),
                                                       t, y, dt),
            }
        ok, got = pure_call(ck, what, student, f, t, y, dt)
        if not ok:
            continue
        answer = as_array(got)
        if answer is not None and answer.shape == y.shape and not np.all(np.isfinite(answer)):
            stiff = f is _stiff  # the one case where an iteration that diverges is likely
            ck.expect(False, what, "your step returned NaN or inf",
                      ("fixed-point iteration Y <- y + dt f(t + dt/2, (y + Y)/2) diverges when "
                       "dt |∂f/∂y| / 2 > 1, as here: use Newton's method on the residual, with a "
                       "finite-difference Jacobian") if stiff else
                      "look for a division by zero or an overflow in your iteration")
            continue
        # The residual names the failure for a float64 answer; a float32 one is judged on
        # its value alone (its rounding alone leaves a residual of ~1e-7).
        if answer is not None and answer.shape == y.shape and rtol_for(answer, 1e-9) == 1e-9:
            res = answer - y - dt * f(t + 0.5 * dt, 0.5 * (y + answer))
            scale = max(1.0, float(np.max(np.abs(y))))
            if np.max(np.abs(res)) > 1e-8 * scale and not np.allclose(answer, expected, rtol=1e-9):
                hint = None
                if np.max(np.abs(answer)) > 10 * scale:
                    hint = ("your iteration diverged: fixed-point iteration Y <- y + dt f(t + dt/2, "
                            "(y + Y)/2) only converges when dt |∂f/∂y| / 2 < 1. Use Newton's "
                            "method on the residual, with a finite-difference Jacobian")
                for mistake, wrong in ({} if hint else mistakes).items():
                    if np.allclose(answer, wrong, rtol=rtol_for(answer, 1e-9), atol=1e-12):
                        hint = mistake
                        break
                ck.expect(False, what, f"your Y leaves a residual of {np.max(np.abs(res)):.2g} in "
                          "Y - y - dt f(t + dt/2, (y + Y)/2) = 0",
                          hint or "iterate until the residual is at round-off (a few Newton "
                          "steps; fixed-point iteration converges slowly or not at all)")
                continue
        if close(ck, got, expected, what, rtol=1e-9, atol=1e-12,
                 hint="Y = y + dt f(t + dt/2, (y + Y)/2), solved for Y", mistakes=mistakes) \
                and keeps_norm and answer.ndim == 1:
            ck.passed[-1] += " (and |Y| = |y|)"


def _trapezoid_reference(f, t, y, dt):
    from scipy.optimize import root

    f0 = f(t, y)

    def residual(flat):
        Y = flat.reshape(y.shape)
        return (Y - y - 0.5 * dt * (f0 + f(t + dt, Y))).ravel()

    return root(residual, (y + dt * f0).ravel(), tol=1e-14).x.reshape(y.shape)

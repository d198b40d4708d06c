"""Checks for notebook 04, beyond Euler.

Exercises:

- :func:`midpoint_step`: one explicit midpoint (RK2) step ``(f, t, y, dt) -> y_next``,
  compared with :func:`course_lib.midpoint`.
- :func:`backward_euler_linear`: backward Euler on a linear system ``dx/dt = A x``, one
  linear solve ``(I - dt A) x_next = x`` per step, compared with the general implicit
  solver (``course_lib.integrate(..., method="backward_euler")``, Newton's method), on
  coupled, non-symmetric and stiff matrices that a diagonal shortcut or a transposed solve
  gets wrong.
- :func:`implicit_midpoint_step`: one step of the implicit midpoint rule, solved to
  round-off, checked on nonlinear, time-dependent, many-particle and stiff problems (where
  fixed-point iteration diverges) against an independent solve, and for keeping ``|X|``
  exactly on a nonlinear swirl.
"""

from __future__ import annotations

import numpy as np

from .. import fields
from ..integrators import midpoint
from . import Checker, exercise
from ._answers import as_array, call, close, pure_call, rtol_for, step_cases
from ._nb04_cases import LINEAR_CASES, backward_euler_linear_reference, linear_newton
from ._nb04_cases import linear_mistakes as _linear_mistakes

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
            ("you averaged the start slope with the midpoint slope: the midpoint method steps "
             "with the midpoint slope alone"): y + 0.5 * dt * (k1 + f(t + 0.5 * dt, y_mid)),
        }

    step_cases(ck, student, _MIDPOINT_CASES, midpoint, mistakes,
               hint=("predict the state half a step ahead, then step the whole dt with the slope "
                     "there", "y_mid = y + (dt/2) f(t, y); y_next = y + dt f(t + dt/2, y_mid)"))


@exercise(allow=(), forbid=("scipy.optimize", "scipy.integrate"))
def backward_euler_linear(ck: Checker, student) -> None:
    """``student(A, x0, dt, n)`` must return backward Euler's ``[x_0, ..., x_n]`` on
    ``dx/dt = A x``, shape ``(n + 1, d)``, checked against Newton's method in course_lib."""
    for what, A, x0, dt, n in LINEAR_CASES:
        expected = backward_euler_linear_reference(A, x0, dt, n)
        # The two references must agree, or the comparison below would mean nothing.
        assert np.allclose(expected, linear_newton(A, x0, dt, n), rtol=1e-10, atol=1e-13)
        d = len(x0)
        ok, got = call(ck, what, student, np.array(A, dtype=float), np.array(x0), dt, n)
        if not ok:
            continue
        answer = as_array(got)
        if answer is not None and answer.shape != expected.shape:
            if answer.shape == (n, d) and n > 0:
                if np.allclose(answer, expected[1:], rtol=rtol_for(answer, 1e-10)):
                    hint = "include the initial state x_0 = x0 as the first row"
                elif np.allclose(answer, expected[:-1], rtol=rtol_for(answer, 1e-10)):
                    hint = ("your array stops at x_(n-1): the last state x_n is missing (n steps "
                            "give n + 1 states)")
                else:
                    hint = "return the n + 1 states x_0, x_1, ..., x_n, one per row"
            elif answer.size == d and n > 0:
                hint = "return every state x_0, ..., x_n as rows, not only the last one"
            elif answer.size == expected.size:
                hint = "one row per state: shape (n + 1, d), not (d, n + 1) or flat"
            else:
                hint = "return the n + 1 states x_0, ..., x_n as an array of shape (n + 1, d)"
            ck.expect(False, what, f"expected shape {expected.shape}, got {answer.shape}", hint)
            continue
        ok = close(ck, got, expected, what, rtol=1e-10, atol=1e-13,
                   mistakes=_linear_mistakes(A, x0, dt, n),
                   hint=("how is x_next related to x? Write backward Euler's equation for "
                         "dx/dt = A x and solve it for x_next, once per step",
                         "each step solves (I - dt A) x_next = x for x_next (np.linalg.solve); "
                         "collect x_0 ... x_n as rows"))
        if ok:
            ck.passed[-1] += " (matches course_lib's Newton solver)"


# --- the implicit midpoint rule ----------------------------------------------------------


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
                      ("fixed-point iteration Y <- y + dt f(t + dt/2, (y + Y)/2) is only sure to "
                       "converge when dt |∂f/∂y| / 2 < 1, and here it is 12.5: use Newton's method "
                       "on the residual, with a finite-difference Jacobian") if stiff else
                      "look for a division by zero or an overflow in your iteration")
            continue
        # The residual names the failure for a float64 answer; a float32 one is judged on
        # its value alone (its rounding alone leaves a residual of ~1e-7).
        if answer is not None and answer.shape == y.shape and rtol_for(answer, 1e-9) == 1e-9 \
                and not np.allclose(answer, expected, rtol=1e-9, atol=1e-12):
            with np.errstate(all="ignore"):
                res = float(np.max(np.abs(answer - y - dt * f(t + 0.5 * dt, 0.5 * (y + answer)))))
            scale = max(1.0, float(np.max(np.abs(y))))
            hint = None
            if np.max(np.abs(answer)) > 10 * scale:
                hint = ("your iteration diverged: fixed-point iteration Y <- y + dt f(t + dt/2, "
                        "(y + Y)/2) is only sure to converge when dt |∂f/∂y| / 2 < 1 (then it is "
                        "a contraction). Use Newton's method on the residual, with a "
                        "finite-difference Jacobian")
            for mistake, wrong in ({} if hint else mistakes).items():
                if np.allclose(answer, wrong, rtol=rtol_for(answer, 1e-9), atol=1e-12):
                    hint = mistake
                    break
            if hint is None and res <= 1e-10 * scale:
                hint = ("your Y solves the equation but is not the step's answer: another root. "
                        "Start the iteration close to y (a forward Euler guess)")
            ck.expect(False, what, f"your Y leaves a residual of {res:.2g} in "
                      f"Y - y - dt f(t + dt/2, (y + Y)/2) = 0; the check wants round-off, below "
                      f"1e-10 × {scale:g}", hint or "iterate until the residual is at round-off "
                      "(a few Newton steps; fixed-point iteration converges slowly or not at all)")
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

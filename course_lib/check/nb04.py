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
from ._nb04_cases import (
    FROZEN_T,
    LINEAR_CASES,
    MIDPOINT_RULE_CASES,
    _stiff,
    backward_euler_linear_reference,
    implicit_midpoint_reference,
    linear_newton,
    midpoint_rule_mistakes,
    pulsing_vortex,
    shape_hint,
)
from ._nb04_cases import linear_mistakes as _linear_mistakes
from ._nb04_cases import swirl as swirl  # the fields the checks use, as check.swirl
from .tolerance import escalate

_START_TWICE = (
    "you used the start slope f(t, y) for the whole step (that is forward Euler): take "
    "the slope AGAIN at the midpoint, f(t + dt/2, y_mid), and step with that one"
)
_TIME_AT_START = escalate(
    "the second slope belongs to the middle of the step: evaluate f at time t + dt/2, "
    "not at t",
    "on a field that changes in time the slope at y_mid must also be taken at the time of "
    "y_mid, half a step after t: f(t + dt/2, y_mid)")
_TIME_AT_END = "the second slope belongs to the middle of the step: time t + dt/2, not t + dt"
_FULL_PREDICTOR = escalate(
    "the midpoint is half a step away: y_mid = y + (dt/2) f(t, y), not y + dt f(t, y)",
    "the predictor goes half way, the final step the whole way: y_mid uses dt/2, the "
    "step from y with the slope at y_mid uses dt")
_HEUN = escalate(
    "that is Heun's method (average of the start and end slopes); the midpoint method "
    "uses ONE slope, taken at the midpoint",
    "predict only half a step, y_mid = y + (dt/2) f(t, y), and step the whole dt with the "
    "single slope f(t + dt/2, y_mid); no average")
_RETURNED_MID = (
    "you returned the half-step prediction y_mid; the step is y + dt * f(t + dt/2, y_mid)"
)
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
            FROZEN_T: y + dt * f(0.5 * dt, y + 0.5 * dt * f(0.0, y)),
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


@exercise(allow=(), forbid=("scipy.optimize",))
def implicit_midpoint_step(ck: Checker, student) -> None:
    """``student(f, t, y, dt)``: the implicit midpoint rule, solved to round-off.

    Newton's method is the exercise: a solver that does it (``scipy.optimize``) or a library
    step that does (``2 * backward_euler(f, t, y, dt/2) - y``) is refused. A known mistake is
    named only if every case the answer misses shows it: on the stiff decay, linear and
    autonomous, Heun's method and the explicit midpoint give the same value."""
    runs = []
    for what, f, t, y, dt, keeps_norm in MIDPOINT_RULE_CASES:
        y = np.asarray(y, dtype=float)
        calls: list = []  # the answer's evaluations of f: an iteration makes many

        def counted(s, u, f=f, calls=calls):
            calls.append(1)
            return f(s, u)

        one_axis = shape_hint(y)
        ok, got = pure_call(ck, what, student, counted, t, y, dt,
                            error_hint=lambda exc, hint=one_axis: hint if isinstance(
                                exc, ValueError | IndexError | np.linalg.LinAlgError) else None)
        if ok:
            runs.append((what, f, t, y, dt, keeps_norm, got, len(calls)))
    missed = [(got, midpoint_rule_mistakes(f, t, y, dt)) for _, f, t, y, dt, _, got, _ in runs
              if _float64_miss(got, y, implicit_midpoint_reference(f, t, y, dt))]
    named = next((h for h in (missed[0][1] if missed else ()) if all(
        _alike(got, m[h]) for got, m in missed)), None)
    for what, f, t, y, dt, keeps_norm, got, calls in runs:
        _judge_midpoint_rule(ck, what, f, t, y, dt, keeps_norm, got, calls, named)


def _alike(got, wrong) -> bool:
    answer = as_array(got)
    return answer is not None and answer.shape == np.shape(wrong) and bool(
        np.allclose(answer, wrong, rtol=rtol_for(answer, 1e-9), atol=1e-12))


def _float64_miss(got, y, expected) -> bool:
    """A finite float64 answer of y's shape that misses the step (the cases a known mistake
    may be named on; NaN, shapes and float32 answers are told their own way)."""
    answer = as_array(got)
    return (answer is not None and answer.shape == y.shape and bool(np.all(np.isfinite(answer)))
            and rtol_for(answer, 1e-9) == 1e-9
            and not np.allclose(answer, expected, rtol=1e-9, atol=1e-12))


def _judge_midpoint_rule(ck, what, f, t, y, dt, keeps_norm, got, calls, named) -> None:
    """Report one case of :func:`implicit_midpoint_step`; ``named`` is the mistake every
    missed case shows (or None), ``calls`` how often the answer evaluated f here."""
    expected = implicit_midpoint_reference(f, t, y, dt)
    iterated, one_axis = calls > 4, shape_hint(y)
    answer = as_array(got)
    if answer is not None and answer.shape != y.shape:
        ck.expect(False, what, f"expected shape {y.shape}, got shape {answer.shape}",
                  one_axis or "return Y with y's shape")
        return
    if answer is not None and not np.all(np.isfinite(answer)):
        stiff = f is _stiff  # the one case where an iteration that diverges is likely
        ck.expect(False, what, "your step returned NaN or inf",
                  _fixed_point_hint(f, t, y, dt, float("nan"), here=True) if stiff and iterated
                  else "look for a division by zero or an overflow in your step")
        return
    # The residual names the failure for a float64 answer; a float32 one is judged on its
    # value alone (its rounding alone leaves a residual of ~1e-7).
    if _float64_miss(got, y, expected):
        with np.errstate(all="ignore"):
            res = float(np.max(np.abs(answer - y - dt * f(t + 0.5 * dt, 0.5 * (y + answer)))))
        scale = max(1.0, float(np.max(np.abs(y))))
        hint = named
        if hint is None and res <= 1e-10 * scale:
            hint = ("your Y solves the equation but is not the step's answer: another root. "
                    "Start the iteration close to y (a forward Euler guess)")
        if hint is None:
            hint = _one_newton_step(res, float(np.max(np.abs(dt * f(t + 0.5 * dt, y)))),
                                    calls, y.size)
        if hint is None and not iterated:
            hint = (f"your step evaluated f only {calls} time(s): no formula of known values "
                    "gives Y, which appears on both sides of the equation. Solve for it, e.g. "
                    "with Newton's method on the residual")
        if hint is None and np.max(np.abs(answer)) > 10 * scale:
            hint = _fixed_point_hint(f, t, y, dt, res)
        ck.expect(False, what, f"your Y leaves a residual of {res:.2g} in "
                  f"Y - y - dt f(t + dt/2, (y + Y)/2) = 0; the check wants round-off, below "
                  f"1e-10 × {scale:g}", hint or "iterate until the residual is at round-off "
                  "(a few Newton steps; fixed-point iteration converges slowly or not at all)")
        return
    if close(ck, got, expected, what, rtol=1e-9, atol=1e-12, mistakes=midpoint_rule_mistakes(f, t, y, dt),
             hint="Y = y + dt f(t + dt/2, (y + Y)/2), solved for Y") \
            and keeps_norm and answer.ndim == 1:
        ck.passed[-1] += " (and |Y| = |y|)"


def fixed_point_factor(f, t, y, dt) -> complex:
    """What one pass of fixed-point iteration multiplies the error of Y by, near y: the
    eigenvalue of largest modulus of dt J / 2, J = ∂f/∂y at (t + dt/2, y) by differences."""
    shape, y = np.shape(y), np.asarray(y, dtype=float).ravel()
    g = lambda u: np.ravel(f(t + 0.5 * dt, u.reshape(shape)))  # noqa: E731
    h = 1e-7 * max(1.0, float(np.max(np.abs(y))))
    J = np.column_stack([(g(y + h * e) - g(y)) / h for e in np.eye(y.size)])
    mu = np.linalg.eigvals(0.5 * dt * J)
    return complex(mu[np.argmax(np.abs(mu))])


def _fixed_point_hint(f, t, y, dt, res: float, here: bool = False) -> tuple[str, str]:
    """The hint for a fixed-point iteration that diverged (escalates: the factor per pass,
    then Newton's method line by line)."""
    mu = fixed_point_factor(f, t, y, dt)
    factor = f"{mu.real:.3g}" if abs(mu.imag) < 1e-9 * abs(mu) else f"{abs(mu):.3g} in modulus"
    y = np.ravel(y)
    rate = (2 * mu.real / dt) if y.size == 1 else None
    where = f"on dy/dt = {rate:.3g} y with dt = {dt:g}" if rate is not None else f"here (dt = {dt:g})"
    reached = f", so your residual reached {res:.2g}" if np.isfinite(res) else ", until it overflowed"
    nudge = ("your iteration diverged: fixed-point iteration Y <- y + dt f(t + dt/2, (y + Y)/2) "
             "is only sure to converge when dt |∂f/∂y| / 2 < 1 (then it is a contraction)"
             + (f", and here it is {abs(mu):.3g}" if here else "")
             + ". Use Newton's method on the residual, with a finite-difference Jacobian")
    return escalate(nudge, (
        f"{where} each pass multiplies the error of Y by dt ∂f/∂y / 2 = {factor}{reached}. "
        "Newton: G(Y) = Y - y - dt f(t + dt/2, (y + Y)/2); build J_G column by column, "
        "(G(Y + h e_j) - G(Y)) / h with h = 1e-7 max(1, |Y|); then Y = Y - "
        "np.linalg.solve(J_G, G(Y)), repeated until the update is below 1e-12 max(1, |y|)"))


def _one_newton_step(res: float, res_at_y: float, calls: int, size: int) -> str | None:
    """The hint for an answer that stopped after one Newton update, or None.

    One update with a finite-difference Jacobian evaluates f ``size + 1`` to ``size + 3``
    times (the residual, one column per component, perhaps a guess and a final check); it
    cuts the residual ``res_at_y`` of ``Y = y`` by far more than 10, but not to round-off."""
    if not (size + 1 <= calls <= size + 3 and res < 0.1 * res_at_y):
        return None
    return (f"you took one Newton step; iterate until the residual is at round-off (it fell "
            f"from {res_at_y:.2g} at Y = y to only {res:.2g}, and your step evaluated f only "
            f"{calls} times: enough for one residual and one finite-difference Jacobian)")

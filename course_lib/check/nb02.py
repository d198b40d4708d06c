"""Checks for notebook 02, forward Euler.

Exercises:

- :func:`forward_euler_step`: one step ``(f, t, y, dt) -> y_next``, compared with
  :func:`course_lib.forward_euler`.
- :func:`radius_after`: the radius after ``n`` forward Euler steps on the vortex,
  ``r0 (1 + dt²)^(n/2)``, compared with the formula and with a run of
  :func:`course_lib.integrate`.
- :func:`drift_dt`: the largest step that keeps the radius drift over one revolution
  below a tolerance, ``(1 + dt²)^(π/dt) <= 1 + tol``: a root, which a root finder gives
  to ~1e-10, so the check wants it to 1e-6 (and meeting the bound), for a tolerance the
  notebook never quotes too.
- :func:`observed_order`: the three-grid order of a one-step method given as code, on a
  nonlinear pendulum and the double gyre, whose solutions have no formula.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from .. import fields
from ..integrators import forward_euler, integrate
from . import Checker, exercise
from ._answers import call, call_analysis, close, kutta3, one_number, step_cases

_SLOPE_AT_END = (
    "the slope must be taken at the START of the step, f(t, y); you used the end of "
    "the step (time t + dt or the predicted end state)"
)
_FROZEN_T = (
    "pass the step's time t to f: this field changes with time, and you evaluated it at "
    "t = 0"
)
_NO_DT = "multiply the slope by dt: the position changes by dt * f(t, y), not by f(t, y)"
_SIGN = "wrong sign: forward Euler moves ALONG the velocity, y + dt * f(t, y)"
_INCREMENT = "return the new state y + dt * f(t, y), not only the change dt * f(t, y)"


def _decay(t, y):
    return -2.0 * y


def _gust(t, y):
    """A non-autonomous field: a wind that turns with time, plus a little decay."""
    return np.stack((np.cos(t) - 0.5 * y[..., 0], np.sin(t) - 0.5 * y[..., 1]), axis=-1)


_STEP_CASES = [
    ("vortex from (0, 1), dt = 0.5 (the worked example)", fields.vortex, 0.0, [0.0, 1.0], 0.5),
    ("vortex, three particles at once, dt = 0.1", fields.vortex, 0.0,
     [[1.0, 0.0], [0.0, 2.0], [-1.5, 0.5]], 0.1),
    ("decay dy/dt = -2y, dt = 0.1", _decay, 0.0, [1.5], 0.1),
    ("time-dependent wind at t = 0.3, dt = 0.25", _gust, 0.3, [0.5, -1.0], 0.25),
]


@exercise(allow=())
def forward_euler_step(ck: Checker, student) -> None:
    """Compare ``student(f, t, y, dt)`` with :func:`course_lib.forward_euler`."""
    def mistakes(f, t, y, dt):
        k1 = f(t, y)
        return {
            (_SLOPE_AT_END,): y + dt * f(t + dt, y),
            (_SLOPE_AT_END, _SLOPE_AT_END + " (here the predicted end state)"):
                y + dt * f(t + dt, y + dt * k1),
            _NO_DT: y + k1,
            _SIGN: y - dt * k1,
            _INCREMENT: dt * k1,
            _FROZEN_T: y + dt * f(0.0, y),
            "a step moves along the slope for the whole dt, not dt/2": y + 0.5 * dt * k1,
        }

    step_cases(ck, student, _STEP_CASES, forward_euler, mistakes,
               hint=("follow the slope at the start of the step for the whole step",
                     "forward Euler is y_next = y + dt * f(t, y)"))


def _power(base: float, n: int) -> float:
    """``base ** n``, or inf where it overflows (a wrong answer's value, for comparison)."""
    try:
        return base**n
    except OverflowError:
        return math.inf


def radius_formula(r0: float, dt: float, n: int) -> float:
    """Radius after ``n`` forward Euler steps on the unit-rate vortex: ``r0 (1+dt²)^(n/2)``."""
    return r0 * (1.0 + dt * dt) ** (n / 2)


#: (r0, dt, n); the last case, a million steps, is for the analysis only: a loop over the
#: steps runs a million lines of Python there, a formula a few.
_RADIUS_CASES = [(1.0, 0.5, 3), (2.0, 0.1, 63), (0.5, 0.25, 10), (1.5, 0.05, 0),
                 (0.8, 1e-3, 1_000_000)]
#: Lines of Python an answer may run on the million-step case.
RADIUS_LINE_BUDGET = 2000


@exercise(allow=(), forbid=("scipy.integrate",))
def radius_after(ck: Checker, student) -> None:
    """Compare ``student(r0, dt, n)`` with ``r0 (1 + dt²)^(n/2)`` and a simulated radius.

    The prompt asks for the analysis: a simulation (the library's, SciPy's or a loop of one's
    own over the steps) is refused."""
    for r0, dt, n in _RADIUS_CASES:
        what = f"r0 = {r0:g}, dt = {dt:g}, n = {n}"
        expected = radius_formula(r0, dt, n)
        if 0 < n <= 1000:  # the formula is what forward Euler really does
            traj = integrate(fields.vortex, [r0, 0.0], (0.0, n * dt), dt)
            assert math.isclose(float(np.linalg.norm(traj.y[-1])), expected, rel_tol=1e-12)
        mistakes = {
            "each step multiplies |X|² by (1 + dt²), so |X| grows by the square root "
            "√(1 + dt²) per step": r0 * (1 + dt * dt) ** n,
            "the per-step factor is √(1 + dt²), not 1 + dt": r0 * _power(1 + dt, n),
            "√(1 + dt²) ≈ 1 + dt²/2 is only an approximation; use the exact factor":
                r0 * (1 + dt * dt / 2) ** n,
            "the radius grows by a factor each step: compound it n times, (1 + dt²)^(n/2), "
            "instead of adding n·dt²": r0 * math.sqrt(1 + n * dt * dt),
            "multiply by the starting radius r0": (1 + dt * dt) ** (n / 2),
        }
        if n > 1000:
            ok, got = call_analysis(ck, what, RADIUS_LINE_BUDGET, (
                "the exercise asks for the analysis of Section 3, one formula for any n, not a "
                "simulation step by step"), student, r0, dt, n)
        else:
            ok, got = call(ck, what, student, r0, dt, n)
        if ok:
            close(ck, got, expected, what, rtol=1e-10, mistakes=mistakes,
                  hint=("each step multiplies the radius by the same factor (Section 3)",
                        "the radius after n steps is r0 (1 + dt²)^(n/2)"))


def revolution_drift(dt: float) -> float:
    """Relative radius growth over one revolution (n = 2π/dt steps): (1 + dt²)^(π/dt) - 1."""
    return math.expm1((math.pi / dt) * math.log1p(dt * dt))


def largest_drift_dt(tol: float, *, steps_per_factor: float = 0.5) -> float:
    """Largest ``dt`` with ``(1 + dt²)^(steps_per_factor · 2π/dt) <= 1 + tol``.

    ``steps_per_factor = 0.5`` is the true condition; ``1.0`` is what one gets by forgetting
    the square root (used to recognise that mistake).
    """
    def excess(dt: float) -> float:
        return steps_per_factor * (2 * math.pi / dt) * math.log1p(dt * dt) - math.log1p(tol)

    return brentq(excess, 1e-12, 1.0, xtol=1e-16, rtol=1e-14)


_DRIFT_TOLS = (0.01, 0.1, 0.037)
#: A root finder (brentq, bisection) gives the largest step to ~1e-10 relative; an answer
#: must be this close to it (the linearised estimates are off by 5e-6 and more).
DRIFT_RTOL = 1e-6


@exercise(allow=())
def drift_dt(ck: Checker, student) -> None:
    """``student(tol)`` must return the largest dt whose one-revolution drift is <= tol."""
    for tol in _DRIFT_TOLS:
        what = f"tol = {tol:g}"
        ok, got = call(ck, what, student, tol)
        if not ok:
            continue
        dt = one_number(ck, what, got, "a step in s")
        if dt is None:
            continue
        if dt <= 0:
            ck.expect(False, what, f"expected a step dt > 0, got {dt!r}")
            continue
        best = largest_drift_dt(tol)
        drift = revolution_drift(dt)
        detail = (f"expected dt = {best:.8g} s (to {DRIFT_RTOL:g} relative), got {dt:.8g} s: "
                  f"the radius grows by {100 * drift:.6g}% per revolution")
        if abs(dt / best - 1) <= DRIFT_RTOL and drift <= tol * (1 + 10 * DRIFT_RTOL):
            ck.expect(True, f"{what}: dt = {dt:.8g} s keeps the drift at {100 * drift:.6g}%")
            continue
        hint = ("write the growth over one revolution as a function of dt and find where it "
                "equals 1 + tol with a root finder (scipy.optimize.brentq)",
                "find the dt where (1 + dt²)^(π/dt) = 1 + tol, e.g. with scipy.optimize.brentq")
        if math.isclose(dt, tol / math.pi, rel_tol=1e-6):
            hint = ("tol/π comes from linearising the growth as 1 + π dt, which understates it: "
                    "solve the exact condition instead",
                    "the drift per revolution is (1 + dt²)^(π/dt) ≈ e^(π dt), a bit MORE than "
                    "1 + π dt: solve the exact condition instead of linearising")
        elif math.isclose(dt, math.log1p(tol) / math.pi, rel_tol=1e-6):
            hint = ("ln(1 + tol)/π comes from the estimate e^(π dt), which slightly overstates "
                    "the growth: solve the exact condition with a root finder")
        elif math.isclose(dt, largest_drift_dt(tol, steps_per_factor=1.0), rel_tol=1e-4):
            hint = ("you compounded the factor 1 + dt² per step; it is |X|² that grows by it",
                    "the radius grows by √(1 + dt²) per step, so over n = 2π/dt steps by "
                    "(1 + dt²)^(n/2), not (1 + dt²)^n")
        elif drift <= tol:
            hint = ("your step meets the bound but is not the LARGEST that does: solve "
                    "growth = 1 + tol to full precision (a root finder, not a guess)")
        ck.expect(False, what, detail, hint)


# --- the observed order without an exact solution --------------------------------------


def _ralston(f, t, y, dt):
    """Ralston's second-order method."""
    k1 = f(t, y)
    k2 = f(t + 2 * dt / 3, y + 2 * dt / 3 * k1)
    return y + dt * (0.25 * k1 + 0.75 * k2)


def _euler(f, t, y, dt):
    return y + dt * f(t, y)


def _pendulum(t, y):
    """θ'' = -sin θ as y = (θ, ω)."""
    return np.array([y[1], -np.sin(y[0])])


def _gyre(t, X):
    from ..lessons.nb02_forward_euler import double_gyre

    return double_gyre(t, X)


def _forced(t, y):
    """A decay driven by a force that changes in time: dy/dt = cos 3t - y."""
    return np.cos(3.0 * t) - y


#: (description, step, theory order, f, y0, T, n).
ORDER_CASES = [
    ("forward Euler on a pendulum swinging to 115°", _euler, 1, _pendulum, (2.0, 0.0), 3.0, 200),
    ("Ralston's method on the pendulum", _ralston, 2, _pendulum, (2.0, 0.0), 3.0, 40),
    ("Kutta's third-order method on the pendulum", kutta3, 3, _pendulum, (2.0, 0.0), 3.0, 40),
    ("Ralston's method on the double gyre (time-dependent)", _ralston, 2, _gyre, (0.6, 0.3),
     10.0, 200),
    ("forward Euler on a forced decay dy/dt = cos 3t - y (time-dependent)", _euler, 1, _forced,
     (0.5,), 4.0, 100),
]


def order_reference(step, f, y0, T: float, n: int, *, clock=None, same_dt: bool = False
                    ) -> float:
    """``log2(|X_n - X_2n| / |X_2n - X_4n|)`` from runs of ``n``, ``2n``, ``4n`` steps.

    ``clock(k, dt)`` gives the time passed to the k-th step (default ``k dt``); ``same_dt``
    runs all three with ``dt = T/n`` (to ``T``, ``2T``, ``4T``). Both exist to recognise
    mistakes: a clock frozen at 0, one a step ahead, runs that do not end at ``T``.
    """
    ends = []
    for m in (n, 2 * n, 4 * n):
        y, dt = np.array(y0, dtype=float), T / (n if same_dt else m)
        for k in range(m):
            y = step(f, k * dt if clock is None else clock(k, dt), y, dt)
        ends.append(y)
    return math.log2(np.linalg.norm(ends[0] - ends[1]) / np.linalg.norm(ends[1] - ends[2]))


def _order_mistakes(step, f, y0, T, n, expected) -> dict:
    return {
        ("pass the time of each step to step(f, t, y, dt): f depends on t here, and your t "
         "stayed at 0"): order_reference(step, f, y0, T, n, clock=lambda k, dt: 0.0),
        ("the k-th step starts at t = k dt: the first step starts at t = 0, not at dt"):
            order_reference(step, f, y0, T, n, clock=lambda k, dt: (k + 1) * dt),
        ("all three runs must end at the same time T: use steps of T/n, T/(2n) and T/(4n), "
         "not the same dt"): order_reference(step, f, y0, T, n, same_dt=True),
        "the ratio is upside down: the coarse difference |X_n - X_2n| goes on top": -expected,
        "use log base 2 (each grid halves the step), not the natural log":
            expected * math.log(2),
        "use log base 2 (each grid halves the step), not log10": expected * math.log10(2),
        ("return the measured p itself, not rounded to a whole order: the point is to see how "
         "close the measurement comes"): float(round(expected)),
    }


@exercise(allow=())
def observed_order(ck: Checker, student) -> None:
    """``student(step, f, y0, T, n)``: the three-grid order, compared with the same formula."""
    for what, step, order, f, y0, T, n in ORDER_CASES:
        what = f"{what}, n = {n} (theory: order {order})"
        expected = order_reference(step, f, y0, T, n)
        ok, got = call(ck, what, student, step, f, np.array(y0), T, n)
        if not ok:
            continue
        p = one_number(ck, what, got)
        if p is None:
            continue
        if math.isclose(p, expected, rel_tol=1e-6, abs_tol=1e-9):
            ck.expect(True, f"{what}: p = {p:.4f}")
            continue
        hint = ("run the method to the same end time T with three step sizes and compare the "
                "differences of the end states",
                "run n, 2n and 4n steps of size T/n, T/(2n), T/(4n) to the same end time T, "
                "then p = log2(|X_n - X_2n| / |X_2n - X_4n|)")
        for mistake, wrong in _order_mistakes(step, f, y0, T, n, expected).items():
            if math.isclose(p, wrong, rel_tol=1e-6, abs_tol=1e-9):
                hint = mistake
                break
        ck.expect(False, what, f"expected p = {expected:.6f}, got {p:.6f}", hint)

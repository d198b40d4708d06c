"""Checks for notebook 02, forward Euler.

Exercises:

- :func:`forward_euler_step`: one step ``(f, t, y, dt) -> y_next``, compared with
  :func:`course_lib.forward_euler`.
- :func:`radius_after`: the radius after ``n`` forward Euler steps on the vortex,
  ``r0 (1 + dt²)^(n/2)``, compared with the formula and with a run of
  :func:`course_lib.integrate`.
- :func:`drift_dt`: the largest step that keeps the radius drift over one revolution
  below a tolerance, ``(1 + dt²)^(π/dt) <= 1 + tol``.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from .. import fields
from ..integrators import forward_euler, integrate
from . import Checker, exercise

_SLOPE_AT_END = (
    "the slope must be taken at the START of the step, f(t, y); you used the end of "
    "the step (time t + dt or the predicted end state)"
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


@exercise
def forward_euler_step(ck: Checker, student) -> None:
    """Compare ``student(f, t, y, dt)`` with :func:`course_lib.forward_euler`."""
    def mistakes(f, t, y, dt):
        k1 = f(t, y)
        return {
            _SLOPE_AT_END: y + dt * f(t + dt, y),
            _SLOPE_AT_END + " ": y + dt * f(t + dt, y + dt * k1),
            _NO_DT: y + k1,
            _SIGN: y - dt * k1,
            _INCREMENT: dt * k1,
        }

    ck.one_step_cases(student, _STEP_CASES, forward_euler, mistakes,
                      hint="forward Euler is y_next = y + dt * f(t, y)")


def radius_formula(r0: float, dt: float, n: int) -> float:
    """Radius after ``n`` forward Euler steps on the unit-rate vortex: ``r0 (1+dt²)^(n/2)``."""
    return r0 * (1.0 + dt * dt) ** (n / 2)


_RADIUS_CASES = [(1.0, 0.5, 3), (2.0, 0.1, 63), (0.5, 0.25, 10), (1.5, 0.05, 0)]


@exercise
def radius_after(ck: Checker, student) -> None:
    """Compare ``student(r0, dt, n)`` with ``r0 (1 + dt²)^(n/2)`` and a simulated radius."""
    for r0, dt, n in _RADIUS_CASES:
        what = f"r0 = {r0:g}, dt = {dt:g}, n = {n}"
        expected = radius_formula(r0, dt, n)
        if n > 0:  # the formula is what forward Euler really does
            traj = integrate(fields.vortex, [r0, 0.0], (0.0, n * dt), dt)
            assert math.isclose(float(np.linalg.norm(traj.y[-1])), expected, rel_tol=1e-12)
        mistakes = {
            "each step multiplies |X|² by (1 + dt²), so |X| grows by the square root "
            "√(1 + dt²) per step": r0 * (1 + dt * dt) ** n,
            "the per-step factor is √(1 + dt²), not 1 + dt": r0 * (1 + dt) ** n,
            "√(1 + dt²) ≈ 1 + dt²/2 is only an approximation; use the exact factor":
                r0 * (1 + dt * dt / 2) ** n,
            "the radius grows by a factor each step: compound it n times, (1 + dt²)^(n/2), "
            "instead of adding n·dt²": r0 * math.sqrt(1 + n * dt * dt),
            "multiply by the starting radius r0": (1 + dt * dt) ** (n / 2),
        }
        ck.close(student(r0, dt, n), expected, what, rtol=1e-10,
                 hint="the radius after n steps is r0 (1 + dt²)^(n/2)", mistakes=mistakes)


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


_DRIFT_TOLS = (0.01, 0.1)
#: The accepted range is [dt_max / _FACTOR, dt_max].
_FACTOR = 1.25


@exercise
def drift_dt(ck: Checker, student) -> None:
    """``student(tol)`` must return a dt with one-revolution drift <= tol, near the largest."""
    for tol in _DRIFT_TOLS:
        what = f"tol = {tol:g}"
        dt = student(tol)
        try:
            dt = float(dt)
        except (TypeError, ValueError):
            ck.expect(False, what, f"expected a number, got {type(dt).__name__}")
            continue
        if not (math.isfinite(dt) and dt > 0):
            ck.expect(False, what, f"expected a step dt > 0, got {dt!r}")
            continue
        best = largest_drift_dt(tol)
        drift = revolution_drift(dt)
        if drift > tol * (1 + 1e-6):
            hint = "find the dt where (1 + dt²)^(π/dt) = 1 + tol, e.g. with scipy.optimize.brentq"
            if math.isclose(dt, tol / math.pi, rel_tol=1e-6):
                hint = ("the drift per revolution is (1 + dt²)^(π/dt) ≈ e^(π dt), which is a bit "
                        "MORE than 1 + π dt: solve the exact condition instead of linearising")
            ck.expect(False, what, f"with dt = {dt:.6g} the radius grows by {100 * drift:.4g}% "
                      f"per revolution, more than {100 * tol:g}%", hint)
        elif dt < best / _FACTOR:
            hint = "look for the LARGEST step that still meets the bound (it is near tol/π)"
            if math.isclose(dt, largest_drift_dt(tol, steps_per_factor=1.0), rel_tol=1e-4):
                hint = ("the radius grows by √(1 + dt²) per step, so over n = 2π/dt steps by "
                        "(1 + dt²)^(n/2), not (1 + dt²)^n")
            ck.expect(False, what, f"dt = {dt:.6g} meets the bound but wastes steps: the "
                      f"largest allowed step is {best:.6g}", hint)
        else:
            ck.expect(True, f"{what}: dt = {dt:.6g} keeps the drift at {100 * drift:.4g}% "
                      f"(largest allowed dt {best:.6g})")

"""Checks for notebook 02, forward Euler.

Exercises:

- :func:`forward_euler_step`: one step ``(f, t, y, dt) -> y_next``, compared with
  :func:`course_lib.forward_euler`.
- :func:`radius_after`: the radius after ``n`` forward Euler steps on the whirlpool
  ``(-y, x) - k (x, y)``, ``r0 ((1 - k dt)² + dt²)^(n/2)``, an extension of Section 3's
  analysis, compared with the formula and with a run of :func:`course_lib.integrate`; a
  loop over a million steps is stopped.
- :func:`drift_dt`: the largest step that keeps the radius drift over one revolution
  below a tolerance, ``(1 + dt²)^(π/dt) <= 1 + tol``: a root, which a root finder gives
  to ~1e-10, so the check wants it to 1e-6 (and meeting the bound), for the tolerances the
  notebook quotes and one the check draws from the answers, whose step it never prints.
- :func:`observed_order`: the three-grid order of a one-step method given as code, on a
  nonlinear pendulum and the double gyre, whose solutions have no formula.
"""

from __future__ import annotations

import hashlib
import inspect
import math
import types

import numpy as np
import scipy.linalg
from scipy.optimize import brentq

from .. import fields
from ..integrators import forward_euler, integrate
from . import Checker, exercise
from . import _nb02_hints as hints
from ._answers import call, call_analysis, close, one_number, step_cases
from ._nb02_cases import (
    ORDER_CASES,
    _radius_mistakes,
    order_mistakes,
    order_reference,
    radius_formula,
)
from .policy import name_chains
from .tolerance import case_table, escalate


def _decay(t, y):
    return -2.0 * y


_STEP_CASES = [
    ("vortex from (0, 1), dt = 0.5 (the worked example)", fields.vortex, 0.0, [0.0, 1.0], 0.5),
    ("vortex, three particles at once, dt = 0.1", fields.vortex, 0.0,
     [[1.0, 0.0], [0.0, 2.0], [-1.5, 0.5]], 0.1),
    ("decay dy/dt = -2y, dt = 0.1", _decay, 0.0, [1.5], 0.1),
    ("time-dependent wind at t = 0.3, dt = 0.25", hints.gust, 0.3, [0.5, -1.0], 0.25),
]


@exercise(allow=())
def forward_euler_step(ck: Checker, student) -> None:
    """Compare ``student(f, t, y, dt)`` with :func:`course_lib.forward_euler`."""
    def mistakes(f, t, y, dt):
        k1 = f(t, y)
        return {
            hints.TIME_END_HINT: y + dt * f(t + dt, y),
            hints.END_STATE_HINT: y + dt * f(t + dt, y + dt * k1),
            hints.NO_DT_HINT: y + k1,
            hints.SIGN_HINT: y - dt * k1,
            hints.INCREMENT_HINT: dt * k1,
            hints.FROZEN_T_HINT: y + dt * f(0.0, y),
            hints.HALF_HINT: y + 0.5 * dt * k1,
        }

    step_cases(ck, student, _STEP_CASES, forward_euler, mistakes,
               hint=("follow the slope at the start of the step for the whole step",
                     "forward Euler is y_next = y + dt * f(t, y)"))


def whirlpool(k: float):
    """The whirlpool field ``V = (-y, x) - k (x, y)`` (m/s), built from course_lib's fields."""
    return fields.compose(fields.vortex, fields.scaled(fields.radial, -k))


#: (r0, dt, n, k); the last case, a million steps, is for the analysis only: a loop over the
#: steps runs a million lines of Python there, a formula a few.
_RADIUS_CASES = [(1.0, 0.5, 3, 0.0), (2.0, 0.1, 63, 0.25), (0.5, 0.25, 10, 1.0),
                 (1.5, 0.5, 6, 3.0), (1.5, 0.05, 0, 0.5), (0.8, 1e-3, 1_000_000, 0.01)]
#: Lines of Python an answer may run on the million-step case.
RADIUS_LINE_BUDGET = 2000


@exercise(allow=(), forbid=("scipy.integrate", np.linalg.matrix_power,
                            scipy.linalg.fractional_matrix_power))
def radius_after(ck: Checker, student) -> None:
    """Compare ``student(r0, dt, n, k)`` with ``r0 ((1 - k dt)² + dt²)^(n/2)`` and a simulated
    radius on the whirlpool.

    The prompt asks for the analysis: a simulation (the library's, SciPy's, a loop of one's
    own over the steps, or the step matrix raised to the n-th power, which is all n steps in
    one call) is refused."""
    for r0, dt, n, k in _RADIUS_CASES:
        what = f"r0 = {r0:g}, dt = {dt:g}, n = {n}, k = {k:g}"
        expected = radius_formula(r0, dt, n, k)
        if 0 < n <= 1000:  # the formula is what forward Euler really does
            traj = integrate(whirlpool(k), [r0, 0.0], (0.0, n * dt), dt)
            assert math.isclose(float(np.linalg.norm(traj.y[-1])), expected, rel_tol=1e-12)
        if n > 1000:
            ok, got = call_analysis(ck, what, RADIUS_LINE_BUDGET, escalate(
                "the exercise asks for the analysis, one formula for any n, not a simulation "
                "step by step",
                "here n = 1 000 000: your loop runs a million steps. One step multiplies |X| by "
                "the same factor whatever X is (Section 3), so n steps multiply it by that "
                "factor ** n: one line, however large n is"), student, r0, dt, n, k)
        else:
            ok, got = call(ck, what, student, r0, dt, n, k)
        if ok:
            close(ck, got, expected, what, rtol=1e-10, mistakes=_radius_mistakes(r0, dt, n, k),
                  hint=("what does one step do to |X|? Split the step into its part along X and "
                        "its part perpendicular to X, as in Section 3, then apply it n times",
                        "one step is X + dt (J X - k X) = (1 - k dt) X + dt J X: two "
                        "perpendicular parts. Square and add their lengths, then apply the "
                        "factor n times"))


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


#: The tolerances the text quotes; the check adds one of its own (:func:`hidden_tol`).
_DRIFT_TOLS = (0.01, 0.1)
#: A root finder (brentq, bisection) gives the largest step to ~1e-10 relative; an answer
#: must be this close to it (the linearised estimates are off by 5e-6 and more).
DRIFT_RTOL = 1e-6


def hidden_tol(answers) -> float:
    """A tolerance between 2 % and 8 % that the text never quotes, drawn from the answers to
    the quoted ones (each rounded to 9 digits, so that a last-bit difference between machines
    changes nothing).

    Why from the answers and not from a random generator: the grader replays a submission's
    recorded answers into this check and needs the same arguments as the student's kernel
    gave; and a table of printed answers cannot anticipate a tolerance its own answers pick.
    The check never prints the step it expects for this tolerance.
    """
    key = ";".join(f"{a:.9e}" if isinstance(a, float) else "?" for a in answers)
    frac = int(hashlib.sha256(key.encode()).hexdigest()[:12], 16) / 16**12
    return round(0.02 + 0.06 * frac, 4)


#: Names of root finders (SciPy's): an answer whose code names none of them did not use one.
_ROOT_FINDERS = frozenset({"brentq", "brenth", "bisect", "ridder", "toms748", "newton",
                           "root_scalar", "root", "fsolve"})


def _names(student, names: frozenset) -> set[str]:
    """Which of ``names`` the answer's code (nested functions included) loads; empty when its
    code cannot be read (e.g. the grader's replay of recorded answers)."""
    code = getattr(inspect.unwrap(student), "__code__", None)  # under the library watch's wrapper
    if not isinstance(code, types.CodeType):
        return set()
    return {n for _, head, attrs in name_chains(code)
            for n in (head.rsplit(".", 1)[-1], *attrs) if n in names}


def _drift_hint(dt: float, tol: float, best: float, drift: float, brentq_named: bool = False):
    """The hint for a step ``dt`` that is not the largest one keeping the drift within ``tol``."""
    def near(x, rel=1e-6):
        return x is not None and math.isclose(dt, x, rel_tol=rel)

    def root(t, steps_per_factor=0.5):
        try:
            return largest_drift_dt(t, steps_per_factor=steps_per_factor)
        except ValueError:  # no root in the bracket: this reading of tol is impossible here
            return None

    if near(tol / math.pi):
        return escalate(
            "tol/π comes from linearising the growth as 1 + π dt, which understates it: "
            "solve the exact condition instead",
            "the drift per revolution is (1 + dt²)^(π/dt) ≈ e^(π dt), a bit MORE than 1 + π dt: "
            f"your dt = {dt:.4g} s lets the radius grow {100 * drift:.4g} % per revolution, more "
            f"than the {100 * tol:g} % allowed. Write g(dt) = (π/dt) ln(1 + dt²) - ln(1 + tol) "
            "and return scipy.optimize.brentq(g, 1e-6, 1.0)")
    if near(math.log1p(tol) / math.pi):
        return escalate(
            "ln(1 + tol)/π comes from the estimate e^(π dt), which slightly overstates "
            "the growth: solve the exact condition with a root finder",
            "the exact growth is (1 + dt²)^(π/dt) = e^((π/dt) ln(1 + dt²)), and ln(1 + dt²) "
            "< dt², so the largest step is a little LARGER than ln(1 + tol)/π (by about "
            "dt²/2 relative, more than the check's 1e-6): solve (π/dt) ln(1 + dt²) = "
            "ln(1 + tol) for dt with scipy.optimize.brentq")
    if near(root(tol, steps_per_factor=1.0), 1e-4):
        return escalate(
            "you compounded the factor 1 + dt² per step; it is |X|² that grows by it",
            "the radius grows by √(1 + dt²) per step, so over n = 2π/dt steps by "
            f"(1 + dt²)^(n/2), not (1 + dt²)^n: with tol = {tol:g} your dt = {dt:.4g} s is "
            f"{dt / best:.2f} times the largest step. The exponent is π/dt, not 2π/dt: "
            "solve (π/dt) ln(1 + dt²) = ln(1 + tol)")
    if near(root(tol / 100), 1e-4) or near(root(tol * 100), 1e-4):
        return escalate("tol is a fraction: 0.01 means 1 %, not 0.01 % (and not 100 %)",
                        f"with tol = {tol:g} the radius may grow by {100 * tol:g} % per "
                        f"revolution: solve (1 + dt²)^(π/dt) = {1 + tol:g} as it stands, "
                        "without multiplying or dividing tol by 100")
    gap = f"your dt is off by {abs(dt / best - 1):.1e} relative"
    if abs(dt / best - 1) < 1e-3 and brentq_named:
        return escalate(
            "your step is close to the largest one, but not within 1e-6: is your root finder "
            "converged? brentq's xtol is an absolute tolerance, and dt is only a few thousandths "
            "here: ask for far less (or keep the default)",
            f"{gap}, where 1e-6 is asked; at tol = 0.01 the step is about 0.0032 s, so an xtol "
            "of 1e-5 already allows 0.3 %: call brentq(g, a, b) with its default xtol (2e-12)")
    if abs(dt / best - 1) < 1e-3:
        return escalate(
            "your step is close to the largest one, but not within 1e-6 relative: whatever finds "
            "it (a scan over steps, a bisection of your own) stops too far from the root. A root "
            "finder such as scipy.optimize.brentq gives it to ten digits",
            f"{gap}, where 1e-6 is asked: a scan in steps of 1e-5 s can miss a root near "
            "0.0032 s by 0.3 %. Write g(dt) = (π/dt) ln(1 + dt²) - ln(1 + tol) and return "
            "scipy.optimize.brentq(g, 1e-6, 1.0)")
    if drift <= tol:
        return escalate(
            "your step meets the bound but is not the LARGEST that does: solve "
            "growth = 1 + tol to full precision (a root finder, not a guess)",
            f"your dt = {dt:.4g} s lets the radius grow {100 * drift:.3g} % per revolution, "
            f"less than the {100 * tol:g} % allowed: a larger step would do. The largest one "
            "makes the growth exactly 1 + tol: find that root with scipy.optimize.brentq")
    return ("write the growth over one revolution as a function of dt and find where it "
            "equals 1 + tol with a root finder (scipy.optimize.brentq)",
            "find the dt where (1 + dt²)^(π/dt) = 1 + tol, e.g. with scipy.optimize.brentq")


@exercise(allow=())
def drift_dt(ck: Checker, student) -> None:
    """``student(tol)`` must return the largest dt whose one-revolution drift is <= tol: for
    the quoted tolerances, then for one drawn from the answers (:func:`hidden_tol`), whose
    expected step is never printed."""
    answers, brentq_named = [], "brentq" in _names(student, _ROOT_FINDERS)
    for tol in (*_DRIFT_TOLS, None):
        hidden = tol is None
        if hidden:
            tol = hidden_tol(answers)
        what = f"tol = {tol:g}" + (" (a tolerance the check draws)" if hidden else "")
        ok, got = call(ck, what, student, tol)
        dt = one_number(ck, what, got, "a step in s") if ok else None
        answers.append(dt)
        if dt is None:
            continue
        if dt <= 0:
            ck.expect(False, what, f"expected a step dt > 0, got {dt!r}")
            continue
        best = largest_drift_dt(tol)
        drift = revolution_drift(dt)
        grows = f"your dt = {dt:.8g} s lets the radius grow by {100 * drift:.6g}% per revolution"
        if abs(dt / best - 1) <= DRIFT_RTOL and drift <= tol * (1 + 10 * DRIFT_RTOL):
            ck.expect(True, f"{what}: dt = {dt:.8g} s keeps the drift at {100 * drift:.6g}%")
            continue
        if hidden:  # say what the step does, never which step was wanted
            budget = f"the budget of {100 * tol:g}%"
            detail = (f"{grows}, more than {budget}" if drift > tol else
                      f"{grows}, within {budget}, but a larger step would be too")
        else:
            detail = (f"expected dt = {best:.8g} s (to {DRIFT_RTOL:g} relative), got "
                      f"{dt:.8g} s: the radius grows by {100 * drift:.6g}% per revolution")
        ck.expect(False, what, detail, _drift_hint(dt, tol, best, drift, brentq_named))


# --- the observed order without an exact solution --------------------------------------


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
        slips = case_table("observed_order", what, order_mistakes, step, f, y0, T, n, expected)
        for mistake, wrong in slips.items():
            if math.isclose(p, wrong, rel_tol=1e-6, abs_tol=1e-9):
                hint = mistake
                break
        ck.expect(False, what, f"expected p = {expected:.6f}, got {p:.6f}", hint)

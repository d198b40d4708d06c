"""Checks for notebook 03, stability.

Exercises (each is checked on problems whose answers no formula in the notebook gives):

- :func:`stability_function`: ``R(z)`` of any one-step method, measured by one step of the
  test equation; checked on methods the notebook never shows.
- :func:`largest_stable_dt`: the stability limit of a black-box linear system by
  experiment; checked against linear stability theory (the eigenvalues and
  :func:`course_lib.max_stable_dt`) to 2 %.
- :func:`powers_stay_bounded`: whether ``M^n`` stays bounded for a 2×2 step matrix,
  including the Jordan block of the symplectic methods at ``ω dt = 2``.
"""

from __future__ import annotations

import numpy as np

from ..stability import amplification_factor, max_stable_dt
from . import Checker, exercise
from ._answers import as_array, call, call_analysis, kutta3, one_number, rtol_for

# --- exercise 1: R(z) of a method, from one step ---------------------------------------


def _two_half_steps(f, t, y, dt):
    """Two forward Euler steps of dt/2: R = (1 + z/2)²."""
    y_half = y + 0.5 * dt * f(t, y)
    return y_half + 0.5 * dt * f(t + 0.5 * dt, y_half)


def _theta_quarter(f, t, y, dt):
    """The implicit θ-method, θ = 1/4: R = (1 + 3z/4) / (1 - z/4).

    Solves ``u = y + dt (3/4 f(t, y) + 1/4 f(t + dt, u))`` exactly for an ``f`` linear in
    ``u`` (elementwise), from the residual at ``u = 0`` and ``u = 1``.
    """
    known = y + 0.75 * dt * f(t, y)

    def residual(u):
        return u - known - 0.25 * dt * f(t + dt, u)

    r0 = residual(np.zeros_like(known))
    r1 = residual(np.ones_like(known))
    return -r0 / (r1 - r0)


#: (name, stepper, exact R) of the methods the check measures.
HIDDEN_METHODS = [
    ("two forward Euler half steps", _two_half_steps, lambda z: (1 + z / 2) ** 2),
    ("Kutta's third-order method", kutta3, lambda z: 1 + z + z**2 / 2 + z**3 / 6),
    ("the implicit θ-method, θ = 1/4", _theta_quarter, lambda z: (1 + 0.75 * z) / (1 - 0.25 * z)),
]
#: The points z (any shape) where R is measured.
Z_GRID = np.array([[-2.5, -1.0 + 1.0j, 0.3j], [2.0j, -0.5 - 2.0j, 0.8]])
Z_SCALAR = -1.5 + 0.5j


@exercise(allow=())
def stability_function(ck: Checker, student) -> None:
    """``student(step, z) -> R(z)`` for hidden methods, on a grid and at a scalar ``z``."""
    for name, stepper, R in HIDDEN_METHODS:
        for z in (Z_GRID, Z_SCALAR):
            what = (f"{name}, z of shape {np.shape(z)}" if np.ndim(z)
                    else f"{name}, z = {z}")
            ok, got = call(ck, what, student, stepper, z)
            if not ok:
                continue
            expected = np.asarray(R(np.asarray(z, dtype=complex)))
            answer = as_array(got, complex_ok=True)
            if answer is None:
                ck.expect(False, what, f"expected complex numbers, got {type(got).__name__}")
                continue
            if answer.size == expected.size == 1:
                answer = answer.reshape(expected.shape)
            if answer.shape != expected.shape:
                ck.expect(False, what, f"expected shape {expected.shape}, got {answer.shape}",
                          ("return one R per z, in z's shape",
                           "return one R per z, in z's shape: take the step with an array y "
                           "of ones shaped like z and f(t, y) = z * y"))
                continue
            rtol = rtol_for(answer, 1e-12)
            if np.allclose(answer, expected, rtol=rtol, atol=rtol):
                ck.expect(True, what)
                continue
            hint = "R(z) is the state after ONE step of dy/dt = z y with dt = 1 from y = 1"
            mistakes = {
                "you returned the change R - 1; return the new state y_1 = R(z) y_0":
                    expected - 1,
                "that is R(z)²: take one step, not two": expected**2,
                "the imaginary part is lost: start from a complex y "
                "(np.ones_like(z, dtype=complex)), not a float array": expected.real,
                "you returned forward Euler's 1 + z; measure the method you are given by "
                "calling step": 1 + np.asarray(z, dtype=complex),
            }
            for mistake, wrong in mistakes.items():
                if np.allclose(answer, wrong, rtol=rtol, atol=rtol):
                    hint = mistake
                    break
            ck.expect(False, what, f"expected {np.round(expected, 6)}, got {np.round(answer, 6)}",
                      hint)


# --- exercise 2: the stability limit by experiment -------------------------------------

#: Black-box linear systems dy/dt = A y: (description, A, y0, method, dt_hi).
LIMIT_CASES = [
    ("forward Euler on a damped spring x'' = -4x - 2x'",
     np.array([[0.0, 1.0], [-4.0, -2.0]]), (1.0, 0.0), "forward_euler", 2.0),
    ("RK4 on a decay and an oscillation together (3 components)",
     np.array([[-3.0, 0.0, 0.0], [0.0, 0.0, 2.0], [0.0, -2.0, 0.0]]), (1.0, 1.0, 0.0), "rk4", 3.0),
    ("midpoint on a lightly damped spring x'' = -9.25x - x'",
     np.array([[0.0, 1.0], [-9.25, -1.0]]), (1.0, 0.0), "midpoint", 2.0),
]
#: Accepted relative error of the measured limit.
LIMIT_RTOL = 0.02
#: Where a method's first evaluation after the start, and its last evaluation in a step,
#: fall (in steps): how a recorded run gives its step and its number of steps.
_FIRST_STAGE = {"forward_euler": 1.0, "midpoint": 0.5, "rk4": 0.5}
_LAST_STAGE = {"forward_euler": 0.0, "midpoint": 0.5, "rk4": 1.0}


def theory_limit(A, method: str) -> float:
    """Largest stable step of ``method`` on ``dy/dt = A y``: the smallest over A's modes."""
    return min(max_stable_dt(method, lam) for lam in np.linalg.eigvals(A))


class Probe:
    """``f(t, y) = A y`` as handed to the student, recording every evaluation, so that the
    check sees the runs a search made: each run starts at ``y0``; its step follows from the
    first time offset after the start, its length from the last, and the largest state it
    reached is recorded."""

    def __init__(self, A, y0, method: str):
        self.A, self.y0, self.method = A, np.asarray(y0, dtype=float), method
        self.calls: list[tuple[float, np.ndarray]] = []  # (t, y): read only when needed

    def __call__(self, t, y):
        y = np.asarray(y)
        self.calls.append((t, y.copy()))
        with np.errstate(all="ignore"):
            return self.A @ y

    def runs(self, first: bool = False) -> list[tuple[float, int, float]]:
        """``(dt, steps, largest |y| / |y0|)`` of every run of at least two steps (with
        ``first``, of the first one only: enough to know that a search ran)."""
        out, run = [], None
        y0, scale = self.y0, float(np.max(np.abs(self.y0)))
        for t, y in [*self.calls, (0.0, y0)]:
            t = float(t)
            if y.shape == y0.shape and bool(np.array_equal(y, y0)):   # a run starts
                if run and run[1]:
                    dt = run[1] / _FIRST_STAGE[self.method]
                    steps = round(run[2] / dt - _LAST_STAGE[self.method]) + 1
                    if steps >= 2:
                        out.append((dt, steps, run[3] / scale))
                        if first:
                            break
                run = [t, 0.0, 0.0, 0.0]  # t0, first offset, last offset, largest size
                continue
            if run is not None and t > run[0]:
                with np.errstate(all="ignore"):
                    size = float(np.max(np.abs(y))) if y.size else 0.0
                run[1] = t - run[0] if not run[1] else min(run[1], t - run[0])
                run[2], run[3] = max(run[2], t - run[0]), max(run[3], size)
        return out


def _growth(A, method: str, dt: float) -> float:
    """|R| per step of the fastest-growing mode at step ``dt``."""
    return float(max(abs(amplification_factor(method, lam * dt)) for lam in np.linalg.eigvals(A)))


def _limit_hint(probe: Probe, A, method: str, dt: float, limit: float):
    """The mistake the recorded runs point to, for a measured limit ``dt`` off by > 2 %."""
    runs = probe.runs()
    if not runs:
        return ("find the limit by experiment: your function ran no simulation of "
                "dy/dt = f(t, y) from y0")
    if dt > limit:  # a run above the limit passed as stable: which one, and why?
        step, n, size = min(runs, key=lambda r: abs(r[0] / dt - 1))
        if abs(step / dt - 1) > 0.05:  # no run near the answer to read (e.g. not recorded)
            return ("a run just above the limit grows slowly: check how many steps your runs "
                    "take, and that your blow-up bound is not far above a stable run's size")
        grew = _growth(A, method, step) ** n
        if size > 1e6:
            return (f"your run at dt = {step:.4g} s grew {size:.1e}-fold and still counted as "
                    "stable: the blow-up bound is too high",
                    f"your run at dt = {step:.4g} s grew {size:.1e}-fold and still counted as "
                    "stable: the blow-up bound is too high (without one, only overflow stops "
                    "a run). No stable run of these systems grows more than a few times "
                    "|y0|: a bound of 1000 max|y0| is far enough")
        return (f"your run at dt = {step:.4g} s took {n} steps: just above the limit a run "
                "grows slowly, too slowly to reach the bound in so few steps",
                f"your run at dt = {step:.4g} s took {n} steps: there |R| = "
                f"{_growth(A, method, step):.4f} per step, {grew:.3g}-fold in {n} steps. Run "
                "thousands of steps, so that a slow growth reaches the bound")
    below = [r for r in runs if dt * (1 + 1e-9) < r[0] < limit]
    if not below:
        return None
    step, n, size = min(below)
    return (f"your run at dt = {step:.4g} s is stable (|R| = {_growth(A, method, step):.5f} ≤ 1) "
            "but counted as unstable: a stable run may grow for a while before it decays",
            f"your run at dt = {step:.4g} s is stable (|R| = {_growth(A, method, step):.5f} ≤ 1) "
            f"but counted as unstable; it reached {size:.3g}·|y0| on the way, since a stable "
            "run of a damped spring can swing above its start before it decays. Put the bound "
            "far above that, e.g. 1000 max|y0|")


@exercise(allow=("course_lib.integrate",))
def largest_stable_dt(ck: Checker, student) -> None:
    """``student(f, y0, method, dt_hi)``: the limit by experiment, within 2 % of theory."""
    for what, A, y0, method, dt_hi in LIMIT_CASES:
        probe = Probe(A, y0, method)
        limit = theory_limit(A, method)
        ok, got = call(ck, what, student, probe, np.array(y0), method, dt_hi)
        if not ok:
            continue
        dt = one_number(ck, what, got, "a step in s")
        if dt is None:
            continue
        error = dt / limit - 1.0
        detail = f"expected {limit:.5g} s within {LIMIT_RTOL:.0%}, got {dt:.5g} s ({error:+.1%})"
        if abs(error) <= LIMIT_RTOL and probe.runs(first=True):
            ck.expect(True, f"{what}: limit {limit:.4g} s, measured {dt:.4g} s ({error:+.1%})")
        elif abs(error) <= LIMIT_RTOL:
            ck.expect(False, what, "right, but found without a single run: the exercise asks "
                      "for the limit by experiment", "run the method from y0 with cl.integrate "
                      "and judge each run by its verdict, traj.stable")
        else:
            ck.expect(False, what, detail, _limit_hint(probe, A, method, dt, limit))


# --- exercise 3: do the powers of a step matrix stay bounded? --------------------------

#: (description, M, bounded, why).
MATRIX_CASES = [
    ("rotation by 0.3 rad", [[np.cos(0.3), -np.sin(0.3)], [np.sin(0.3), np.cos(0.3)]], True,
     "|μ| = 1, two distinct eigenvalues"),
    ("symplectic Euler at ω dt = 2, [[-3, 2], [-2, 1]]", [[-3.0, 2.0], [-2.0, 1.0]], False,
     "double eigenvalue -1 with one eigenvector: a Jordan block, M^n grows like n"),
    ("-I", [[-1.0, 0.0], [0.0, -1.0]], True, "double eigenvalue -1, but two eigenvectors"),
    ("shear [[1, 1], [0, 1]]", [[1.0, 1.0], [0.0, 1.0]], False, "Jordan block at +1"),
    ("[[0.5, 100], [0, 0.5]]", [[0.5, 100.0], [0.0, 0.5]], True,
     "spectral radius 0.5: a large transient, then decay"),
    ("diag(1.01, 0.2)", [[1.01, 0.0], [0.0, 0.2]], False, "an eigenvalue 1.01 > 1"),
    ("forward Euler on the vortex, dt = 0.5", [[1.0, -0.5], [0.5, 1.0]], False,
     "|μ| = √1.25 > 1"),
    ("diag(1, -1)", [[1.0, 0.0], [0.0, -1.0]], True, "|μ| = 1, distinct"),
    ("[[0.9, 0.9], [-0.9, 0.9]]", [[0.9, 0.9], [-0.9, 0.9]], False, "|μ| = 0.9 √2 > 1"),
    ("[[1, 0.5], [0, 0.5]]", [[1.0, 0.5], [0.0, 0.5]], True, "eigenvalues 1 and 0.5, distinct"),
    ("diag(1.00001, 0.5)", [[1.00001, 0.0], [0.0, 0.5]], False,
     "an eigenvalue 1.00001 > 1: M^n grows 10-fold only after 230 000 steps, but it grows"),
    ("[[0.99999, 1], [0, 0.99999]]", [[0.99999, 1.0], [0.0, 0.99999]], True,
     "a Jordan block inside the circle: M^n rises to 37 000 (near n = 100 000), then decays"),
]
#: The two matrices above whose powers mislead any fixed number of steps one tries.
SLOW_CASES = ("diag(1.00001, 0.5)", "[[0.99999, 1], [0, 0.99999]]")
#: Lines of Python an answer may run per matrix: an analysis needs a few dozen.
POWERS_LINE_BUDGET = 500


def bounded_reference(M, tol: float = 1e-9) -> bool:
    """Do the powers ``M^n`` stay bounded? Spectral radius ≤ 1, and every eigenvalue on the
    unit circle has as many eigenvectors as its multiplicity."""
    M = np.asarray(M, dtype=float)
    mu = np.linalg.eigvals(M)
    if np.max(np.abs(mu)) > 1 + tol:
        return False
    n = M.shape[0]
    for m in mu[np.abs(np.abs(mu) - 1) <= tol]:
        multiplicity = int(np.sum(np.abs(mu - m) <= 1e-6))
        rank = np.linalg.matrix_rank(M - m * np.eye(n), tol=1e-6)
        if n - rank < multiplicity:
            return False
    return True


@exercise(allow=(), forbid=(np.linalg.matrix_power,))
def powers_stay_bounded(ck: Checker, student) -> None:
    """``student(M) -> bool`` on twelve 2×2 matrices; an analysis, not powers of M."""
    wrong = []
    answers = []
    for what, M, expected, why in MATRIX_CASES:
        ok, got = call_analysis(ck, what, POWERS_LINE_BUDGET, (
            "decide from the eigenvalues and eigenvectors of M, not by multiplying M many times",
            "decide from the eigenvalues and eigenvectors of M, not by multiplying M many "
            "times: no fixed number of steps tells a slow growth from a slow decay"),
            student, np.array(M, dtype=float))
        if not ok and ck.failed and "lines of Python" in ck.failed[-1]:
            break  # one such verdict says it all
        if not ok:
            continue
        if not isinstance(got, bool | np.bool_):
            ck.expect(False, what, f"expected True or False, got {got!r}"[:120])
            continue
        answers.append((what, expected, bool(got)))
        if bool(got) != expected:
            wrong.append(f"{what}: expected {expected} ({why}), got {bool(got)}")
    if not answers:
        return
    hint = None
    got_by_case = {w: g for w, _, g in answers}
    if got_by_case.get("symplectic Euler at ω dt = 2, [[-3, 2], [-2, 1]]") is True \
            or got_by_case.get("shear [[1, 1], [0, 1]]") is True:
        hint = ("spectral radius ≤ 1 is not enough: an eigenvalue on the unit circle with fewer "
                "eigenvectors than its multiplicity (a Jordan block) makes M^n grow like n")
    elif got_by_case.get("rotation by 0.3 rad") is False or got_by_case.get("-I") is False:
        hint = ("|μ| = 1 neither grows nor decays: on the unit circle the powers stay bounded "
                "when each eigenvalue there has a full set of eigenvectors")
    elif any(w in got_by_case and got_by_case[w] != e for w, _, e, _ in MATRIX_CASES
             if w in SLOW_CASES):
        hint = ("a slow growth (|μ| = 1.00001) or a long transient fooled your test: compare "
                "|μ| with 1 at round-off level",
                "M^n after a fixed number of steps cannot decide it: growth by 1.00001 per step, "
                "or a transient that rises for 100 000 steps, fool any count you pick. Decide "
                "from the eigenvalues, with a tolerance at round-off level (about 1e-7 for a "
                "Jordan block's split eigenvalues), not wider")
    elif got_by_case.get("[[0.5, 100], [0, 0.5]]") is False:
        hint = ("a large entry or norm is only a transient: what decides the long run is the "
                "spectral radius")
    ck.expect(not wrong, f"all {len(answers)} matrices judged",
              "".join(f"\n      {w}" for w in wrong), hint)

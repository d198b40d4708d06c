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

from ..integrators import integrate
from ..stability import max_stable_dt
from . import Checker, apart, exercise
from ._answers import as_array, call, call_analysis, one_number, rtol_for
from ._nb03_cases import (
    HIDDEN_METHODS,
    MATRIX_CASES,
    MATRIX_HINTS,
    POWERS_LINE_BUDGET,
    TABLE,
    WRONG_RULES,
    Z_GRID,
    Z_SCALAR,
    cast_hint,
    follows_rule,
    limit_hint,
)
from .tolerance import escalate

# --- exercise 1: R(z) of a method, from one step ---------------------------------------


@exercise(allow=())
def stability_function(ck: Checker, student) -> None:
    """``student(step, z) -> R(z)`` for hidden methods, on a grid and at a scalar ``z``."""
    for name, stepper, R in HIDDEN_METHODS:
        for z in (Z_GRID, Z_SCALAR):
            what = (f"{name}, z of shape {np.shape(z)}" if np.ndim(z)
                    else f"{name}, z = {z}")
            calls = []

            def counted(f, t, y, dt, stepper=stepper, calls=calls):
                calls.append(1)
                return stepper(f, t, y, dt)

            ok, got = call(ck, what, student, counted, z, error_hint=cast_hint)
            if not ok:
                continue
            if len(calls) > 1:
                values = f"{np.size(z)} value{'s' if np.size(z) > 1 else ''}"
                ck.expect(False, what, f"your function called step {len(calls)} times for "
                          f"{values} of z; the exercise asks for a single call", (
                              "hand step an array of states, one per z, and take ONE step",
                              "hand step an array of states shaped like z and an f that "
                              "multiplies each state by its own z: one call then steps every "
                              "state at once"))
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
                          ("return one value per z, in z's shape",
                           "return one value per z, in z's shape: one step of an array of "
                           "states shaped like z gives exactly that"))
                continue
            rtol = rtol_for(answer, 1e-12)
            if np.allclose(answer, expected, rtol=rtol, atol=rtol):
                ck.expect(True, what)
                continue
            hint = ("which test equation, which y0 and which dt make one step return R(z)?",
                    "R(z) is the state after ONE step of dy/dt = z y with dt = 1 from y = 1")
            zc = np.asarray(z, dtype=complex)
            mistakes = {
                escalate("you returned the change R - 1; return the new state y_1 = R(z) y_0",
                         "step returns the state after the step, y_1 = R(z) y_0; with y_0 = 1 "
                         "that IS R(z), nothing to subtract"): expected - 1,
                escalate("that is R(z)²: take one step, not two",
                         "for two forward Euler half steps R(-2.5) = (1 - 1.25)² = 0.0625; "
                         "two steps give 0.0625² = 0.0039. Call step once and return its "
                         "result, without feeding it back in"): expected**2,
                escalate("the imaginary part is lost: start from a complex y, not a float array",
                         "a float array cannot hold z y: make y0 complex, e.g. "
                         "np.ones_like(z, dtype=complex), so that the step keeps the "
                         "imaginary part"): expected.real,
                escalate("you returned |R(z)|, the modulus; return R(z) itself, a complex "
                         "number (its modulus decides stability)",
                         "forward Euler's R(-1 + 1j) is 1 + z = 1j, of modulus 1: the phase is "
                         "part of the answer. Drop np.abs and return the complex step result"):
                    np.abs(expected),
                **{escalate(f"you returned {name}, a method from the table; measure the method "
                            "you are given by calling step",
                            "the check hands you methods the table does not list (Kutta's "
                            "third-order one, two half steps, a θ-method): R(z) must come from "
                            "one call of step on dy/dt = z y from y = 1 with dt = 1"):
                   table(zc) for name, table in TABLE.items()},
            }
            for mistake, wrong in mistakes.items():
                if np.allclose(answer, wrong, rtol=rtol, atol=rtol):
                    hint = mistake
                    break
            ck.expect(False, what, "expected {}, got {}".format(*apart(expected, answer)),
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

    def state_growth(self, dt: float, steps: int) -> float:
        """``max_k max|y_k| / max|y0|`` over the states of a run of ``steps`` steps of ``dt``
        from ``y0``: what the answer's own trajectory shows (the recorded evaluations also
        hold the stages of a step, which may be larger)."""
        with np.errstate(all="ignore"):
            run = integrate(lambda t, y: self.A @ y, self.y0, (0.0, steps * dt), dt, self.method)
            return float(np.max(np.abs(run.y)) / np.max(np.abs(self.y0)))

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
                      "for the limit by experiment", escalate(
                          "run the method from y0 with cl.integrate and judge each run by its "
                          "verdict, traj.stable",
                          "f records every call and none started from y0, so the limit came "
                          "from theory: search over trial steps with traj = cl.integrate(f, y0, "
                          "(0.0, 2000 * dt), dt, method) and traj.stable"))
        else:
            ck.expect(False, what, detail, limit_hint(probe, A, method, dt, limit))


# --- exercise 3: do the powers of a step matrix stay bounded? --------------------------

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
    """``student(M) -> bool`` on fourteen 2×2 matrices; an analysis, not powers of M."""
    wrong, kinds, answers, student_verdicts = [], [], 0, {}
    for what, M, expected, why, kind in MATRIX_CASES:
        ok, got = call_analysis(ck, what, POWERS_LINE_BUDGET, (
            "decide from the eigenvalues and eigenvectors of M, not by multiplying M many times",
            "decide from the eigenvalues and eigenvectors of M, not by multiplying M many "
            "times: no number of steps you can afford tells a slow growth from a slow decay"),
            student, np.array(M, dtype=float))
        if not ok and ck.failed and "lines of Python" in ck.failed[-1]:
            break  # one such verdict says it all
        if not ok:
            continue
        if not isinstance(got, bool | np.bool_):
            ck.expect(False, what, f"expected True or False, got {got!r}"[:120])
            continue
        answers += 1
        student_verdicts[what] = bool(got)
        if bool(got) != expected:
            wrong.append(f"{what}: expected {expected} ({why}), got {bool(got)}")
            kinds.append(kind)
    if not answers:
        return
    hint = _powers_hint(student_verdicts, kinds) if wrong else None
    ck.expect(not wrong, f"all {answers} matrices judged",
              "".join(f"\n      {w}" for w in wrong), hint)


def _powers_hint(verdicts: dict, kinds: list):
    """The hint for wrong verdicts: a known wrong rule's own when the verdicts are exactly that
    rule's (a norm, the determinant), else those of the two kinds of matrix judged wrong most
    often (ties in :data:`MATRIX_HINTS`' order), nudge first, as sentences."""
    for quantity, rule_hint in WRONG_RULES:
        if follows_rule(quantity, verdicts):
            return rule_hint
    order = list(MATRIX_HINTS)
    found = sorted(set(kinds), key=lambda k: (-kinds.count(k), order.index(k)))[:2]
    hints = [[h] * 2 if isinstance(h, str) else list(h) for h in (MATRIX_HINTS[k] for k in found)]
    if len(hints) == 1:
        return tuple(hints[0])
    return tuple(f"{first.rstrip('.')}. Also: {second}" for first, second in zip(*hints, strict=True))

"""Every check of a one-step method ``step(f, t, y, dt)`` treats the same slips the same way.

Notebooks 02, 04 and 05 ask for one-step methods; their checks share
:func:`course_lib.check._answers.step_cases` / ``pure_call``. For each such check this test
feeds the right answer (float64 and float32) and the kinds of wrong answer every one of
them must name: a step that overwrites its input, one that returns NaN, one that raises,
one that returns the wrong shape and one that returns the start unchanged.
"""

from __future__ import annotations

import contextlib
import io

import numpy as np
import pytest

from course_lib.check import RESULTS, nb02, nb03, nb04, nb05

# Right answers written here from the formulas, not borrowed from course_lib: a check
# refuses an answer that calls the library (course_lib.check.watch), and an independent
# reference is the better test of the check anyway.


def _euler(f, t, y, dt):
    return y + dt * f(t, y)


def _midpoint(f, t, y, dt):
    return y + dt * f(t + dt / 2, y + dt / 2 * f(t, y))


def _implicit_midpoint(f, t, y, dt):
    # Newton with a finite-difference Jacobian, by hand: the exercise refuses scipy.optimize
    y = np.asarray(y, dtype=float)
    Y = _euler(f, t, y, dt)

    def residual(z):
        return z - y - dt * f(t + dt / 2, (y + z) / 2)

    for _ in range(30):
        r = residual(Y)
        if np.max(np.abs(r)) < 1e-14 * max(1.0, np.max(np.abs(Y))):
            break
        jac = np.empty((Y.size, Y.size))
        for j in range(Y.size):
            e = np.zeros(Y.size)
            e[j] = 1e-7
            jac[:, j] = (residual(Y + e.reshape(Y.shape)) - r).ravel() / 1e-7
        Y = Y - np.linalg.solve(jac, r.ravel()).reshape(Y.shape)
    return Y


def _symplectic_euler(f, t, y, dt):
    v = y[1] + dt * f(t, y)[1]
    return np.stack([y[0] + dt * v, v])


def _velocity_verlet(f, t, y, dt):
    v_half = y[1] + dt / 2 * f(t, y)[1]
    x = y[0] + dt * v_half
    return np.stack([x, v_half + dt / 2 * f(t + dt, np.stack([x, v_half]))[1]])


STEP_CHECKS = [
    (nb02.forward_euler_step, _euler),
    (nb04.midpoint_step, _midpoint),
    (nb04.implicit_midpoint_step, _implicit_midpoint),
    (nb05.symplectic_euler_step, _symplectic_euler),
    (nb05.velocity_verlet_step, _velocity_verlet),
]
IDS = [check.__name__ for check, _ in STEP_CHECKS]


def _run(check, answer):
    RESULTS.clear()
    with contextlib.redirect_stdout(io.StringIO()) as out:
        check(answer)
    (result,) = RESULTS.values()
    return result["status"], out.getvalue()


def _copy_of(reference):
    # A fresh function each time: the checks refuse an answer that *is* the reference.
    return lambda f, t, y, dt: np.array(reference(f, t, np.array(y), dt))


@pytest.mark.parametrize(("check", "reference"), STEP_CHECKS, ids=IDS)
def test_right_answer_passes_in_float64_and_float32(check, reference):
    assert _run(check, _copy_of(reference))[0] == "correct"
    as32 = _copy_of(reference)
    assert _run(check, lambda f, t, y, dt: as32(f, t, y, dt).astype(np.float32))[0] == "correct"


@pytest.mark.parametrize(("check", "reference"), STEP_CHECKS, ids=IDS)
def test_a_step_that_overwrites_y_is_told_so(check, reference):
    right = _copy_of(reference)

    def in_place(f, t, y, dt):
        y[...] = right(f, t, y, dt)
        return y

    status, out = _run(check, in_place)
    assert status == "incorrect" and "changed its input y" in out


@pytest.mark.parametrize(("check", "reference"), STEP_CHECKS, ids=IDS)
def test_nan_is_named_not_printed(check, reference):
    status, out = _run(check, lambda f, t, y, dt: np.full(np.shape(y), np.nan))
    assert status == "incorrect" and "NaN or inf" in out
    assert "nan" not in out.replace("NaN", "")


@pytest.mark.parametrize(("check", "reference"), STEP_CHECKS, ids=IDS)
def test_an_exception_is_the_students_failure(check, reference):
    def broken(f, t, y, dt):
        raise ZeroDivisionError("oops in my step")

    status, out = _run(check, broken)
    assert status == "incorrect" and "ZeroDivisionError: oops in my step" in out


@pytest.mark.parametrize(("check", "reference"), STEP_CHECKS, ids=IDS)
def test_wrong_shape_and_no_step_fail(check, reference):
    status, out = _run(check, lambda f, t, y, dt: np.ravel(reference(f, t, np.array(y), dt))[:1])
    assert status == "incorrect" and "shape" in out
    status, _ = _run(check, lambda f, t, y, dt: np.array(y, dtype=float))
    assert status == "incorrect"


ONE_NUMBER_CHECKS = [nb02.drift_dt, nb02.observed_order, nb03.largest_stable_dt]


@pytest.mark.parametrize("check", ONE_NUMBER_CHECKS, ids=lambda c: c.__name__)
@pytest.mark.parametrize("value", [np.nan, np.inf, "0.1", [0.1, 0.2], None],
                         ids=["nan", "inf", "text", "two", "none"])
def test_a_check_that_wants_one_number_says_so(check, value):
    # every such check reads the answer through check._answers.one_number
    status, out = _run(check, lambda *args: value)
    assert status == "incorrect" and "expected one number" in out

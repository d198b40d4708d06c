"""Hints of notebooks 01-04 that the fourth blind review (2026-11-28) found aimed at the wrong
half of a mistake: each planted answer is judged as the grader judges it and must get the
verdict and a hint that names the mistake it makes, on the reviewer's case and on one of our
own of the same class."""

from __future__ import annotations

import pytest

from course_lib.check import nb01, nb02, nb03, nb04
from tests.planted import Plant, judge

# --- 01, exercise 1 (and 2): components taken from axis 1 instead of the last axis --------

_GRID = "right for a cloud of shape (N, 2), wrong on a grid of shape (n, n, 2)"
AXIS_PLANTS = [
    Plant("vortex_field", "misconception", "X[:, 1] joined with np.array(...).T",
          "def vortex_field(t, X):\n    X = np.asarray(X, float)\n"
          "    return np.array([-X[:, 1], X[:, 0]]).T\n", "incorrect", _GRID,
          avoid="V = (-y, x): the x-component"),
    Plant("vortex_field", "misconception", "X[:, 1] with np.stack(axis=1), (2,) handled",
          "def vortex_field(t, X):\n    X = np.asarray(X, float)\n"
          "    if X.ndim == 1:\n        return np.array([-X[1], X[0]])\n"
          "    return np.stack((-X[:, 1], X[:, 0]), axis=1)\n", "incorrect",
          "X[..., 0] and X[..., 1]", avoid="V = (-y, x): the x-component"),
    Plant("whirlpool", "misconception", "whirlpool from X[:, 0], X[:, 1]",
          "def whirlpool(t, X, k=0.5):\n    X = np.asarray(X, float)\n"
          "    if X.ndim == 1:\n        return np.array([-X[1] - k * X[0], X[0] - k * X[1]])\n"
          "    return np.array([-X[:, 1] - k * X[:, 0], X[:, 0] - k * X[:, 1]]).T\n",
          "incorrect", _GRID),
    Plant("vortex_field", "misconception", "clockwise everywhere: not the axis hint",
          "def vortex_field(t, X):\n    X = np.asarray(X, float)\n"
          "    return np.stack((X[..., 1], -X[..., 0]), axis=-1)\n", "incorrect",
          "clockwise", avoid=_GRID),
]

# --- 01, exercise 4: newborns moved or aged -------------------------------------------------

_BORN = "the newborns were moved or aged: they appear exactly as born"
NEWBORN_PLANTS = [
    Plant("particle_frame", "misconception", "appends first, then moves and ages everyone",
          "def particle_frame(particles, V, dt, newborn):\n"
          "    out = {k: np.concatenate([particles[k], newborn[k]]) for k in particles}\n"
          "    Vx = np.concatenate([V, np.zeros((len(newborn['age']), 2))])\n"
          "    out['X'] = out['X'] + dt * Vx\n    out['age'] = out['age'] + dt\n"
          "    alive = out['age'] < out['lifetime']\n"
          "    return {k: v[alive] for k, v in out.items()}\n", "incorrect", _BORN),
    Plant("particle_frame", "misconception", "moves the newborns with the mean velocity",
          "def particle_frame(particles, V, dt, newborn):\n"
          "    X = particles['X'] + dt * V\n    age = particles['age'] + dt\n"
          "    alive = age < particles['lifetime']\n"
          "    born = newborn['X'] + dt * V.mean(axis=0)\n"
          "    out = {k: np.concatenate([particles[k][alive], newborn[k]]) for k in particles}\n"
          "    out['X'] = np.concatenate([X[alive], born])\n"
          "    out['age'] = np.concatenate([age[alive], newborn['age']])\n    return out\n",
          "incorrect", _BORN),
    Plant("particle_frame", "misconception", "survivors not moved: not the newborn hint",
          "def particle_frame(particles, V, dt, newborn):\n"
          "    age = particles['age'] + dt\n    alive = age < particles['lifetime']\n"
          "    out = {k: np.concatenate([particles[k][alive], newborn[k]]) for k in particles}\n"
          "    out['age'] = np.concatenate([age[alive], newborn['age']])\n    return out\n",
          "incorrect", "move every surviving particle", avoid=_BORN),
]


@pytest.mark.parametrize("plant", AXIS_PLANTS + NEWBORN_PLANTS, ids=lambda p: p.label)
def test_nb01_hints_name_the_mistake(plant):
    judge(nb01, plant)


# --- 03, exercise 2: runs too short, not a bound too high ------------------------------------

def _search(steps: int, bound: str) -> str:
    return ("def largest_stable_dt(f, y0, method, dt_hi):\n    lo, hi = 0.0, dt_hi\n"
            "    for _ in range(12):\n        mid = (lo + hi) / 2\n"
            f"        run = cl.integrate(f, y0, (0.0, {steps} * mid), mid, method, "
            f"blowup_bound={bound})\n"
            "        lo, hi = (mid, hi) if run.stable else (lo, mid)\n    return lo\n")


_SHORT = "steps: too few for a run above the limit to reach your blow-up bound"
LIMIT_PLANTS = [
    Plant("largest_stable_dt", "misconception", "20-step runs, bound 1e8 (the review's)",
          _search(20, "1e8"), "incorrect", "took only 20 steps: " + _SHORT[7:],
          avoid="bound is too high"),
    Plant("largest_stable_dt", "misconception", "50-step runs, bound 1e7 max|y0|",
          _search(50, "1e7 * np.max(np.abs(y0))"), "incorrect", "took only 50 steps",
          avoid="bound is too high"),
    Plant("largest_stable_dt", "misconception", "60-step runs, bound 1e8: the fuller hint",
          _search(60, "1e8"), "incorrect", "steps to grow 1e+08-fold and pass your bound",
          avoid="lower the bound", attempt=1),
    Plant("largest_stable_dt", "misconception", "30-step runs, bound 1e300: both, steps first",
          _search(30, "1e300"), "incorrect", "and lower the bound", attempt=1),
    # 300 steps is long enough for the check (over its SHORT_RUN of 200): the bound is named
    Plant("largest_stable_dt", "misconception", "long runs, bound 1e300: the bound",
          _search(300, "1e300"), "incorrect", "the blow-up bound is too high",
          avoid="took only"),
    Plant("largest_stable_dt", "other", "long runs, bound 1e8: right", _search(2000, "1e8"),
          "correct", ""),
]


@pytest.mark.parametrize("plant", LIMIT_PLANTS, ids=lambda p: p.label)
def test_nb03_short_runs_are_named_before_the_bound(plant):
    judge(nb03, plant)


def test_the_steps_a_run_needs_follow_from_R_two_per_cent_above_the_limit():
    """The fuller hint's step count is ln(growth) / ln|R| with R at 1.02 times the limit: for
    forward Euler on x'' = -4x - 2x' (eigenvalues -1 ± i√3, limit 0.5 s), |R|² at dt = 0.51 is
    (1 - 0.51)² + 3 · 0.51² = 1.0204, so |R| = 1.0101 and 1e8 needs ln(1e8)/ln(1.0101) ≈ 1832."""
    from course_lib.check._nb03_cases import short_run_hint

    r = ((1 - 0.51) ** 2 + 3 * 0.51**2) ** 0.5
    nudge, more = short_run_hint(1.4, 20, 1e8, r)
    assert "took only 20 steps" in nudge and more.startswith(nudge)
    import math
    assert f"about {math.log(1e8) / math.log(r):.0f} steps" in more
    assert 1800 < math.log(1e8) / math.log(r) < 1850


# --- notebook sentences the review found loose (01 cells 25 and 27, 04 cells 4 and 17) -------

def _sources(name: str) -> list[str]:
    from pathlib import Path

    import nbformat

    root = Path(__file__).resolve().parents[1]
    return [c.source for c in nbformat.read(root / "solutions" / name, as_version=4).cells]


def test_nb01_the_nudge_is_about_a_hundred_last_digits_of_a_5_m_coordinate():
    """Cell 25: the 1e-13 m nudge is "about a hundred times the last digit that another
    computer's rounding can change", that digit worth 2^-50 m ≈ 8.9e-16 m at 5 m (the box is
    10 m wide, so 5 m is a typical coordinate; from 4 to 8 m the ratio is 113)."""
    import numpy as np

    from course_lib.lessons import nb01_vector_fields as lesson

    assert np.spacing(5.0) == 2.0**-50 and f"{np.spacing(5.0):.1e}" == "8.9e-16"
    assert 50 < 1e-13 / np.spacing(5.0) < 200 and round(1e-13 / np.spacing(5.0)) == 113
    assert lesson.run_flock.__defaults__[3] == 10.0          # box (m): coordinates in [0, 10)
    text = "\n".join(_sources("01_vector_fields.ipynb"))
    assert "about a hundred times the last digit" in text and "a little above" not in text
    assert "agree to within about two standard errors" in text
    assert "agree within their standard errors" not in text


def test_nb04_newton_starts_from_the_current_state_and_1_ms_is_a_time_constant():
    """Cell 4: course_lib's Newton iteration starts from X_n (steppers pass y as the guess);
    cell 17: 1 ms is the catch-up's time constant 1/κ (κ = 1000 1/s), not its duration."""
    import numpy as np

    import course_lib as cl
    from course_lib.lessons import nb04_beyond_euler as lesson

    seen = []

    def f(t, y):
        seen.append(np.array(y, copy=True))
        return -1000.0 * y

    y = np.array([1.0, -2.0])
    for method, first_newton in (("backward_euler", 0), ("trapezoidal", 1)):
        seen.clear()
        cl.step(method, f, 0.0, y, 0.1, jac=lambda t, y: -1000.0 * np.eye(2))
        # the iteration's first evaluation is at its guess: X_n, not X_n + dt f = -99 X_n
        np.testing.assert_array_equal(seen[first_newton], y)
    assert lesson.KAPPA == 1000.0 and 1 / lesson.KAPPA == 1e-3
    text = "\n".join(_sources("04_beyond_euler.ipynb"))
    assert "starting from the current state $X_n$" in text
    assert "forward Euler guess and using" not in text
    assert "catch-up takes 1 ms" not in text and "time constant 1/κ = 1 ms" in text


# --- escalation: the most common first hints of 01-04 give a fuller second hint ---------------

def _pair(module, exercise, label, source, nudge, more):
    """The same wrong answer on a first attempt (the nudge only) and after one failure (the
    nudge followed by the fuller hint)."""
    return [(module, Plant(exercise, "misconception", f"{label} (first)", source, "incorrect",
                           nudge, avoid=more)),
            (module, Plant(exercise, "misconception", f"{label} (again)", source, "incorrect",
                           f"{nudge}", attempt=1)),
            (module, Plant(exercise, "misconception", f"{label} (again, more)", source,
                           "incorrect", more, attempt=1))]


ESCALATING = [
    *_pair(nb01, "vortex_field", "clockwise vortex",
           "def vortex_field(t, X):\n    X = np.asarray(X, float)\n"
           "    return np.stack((X[..., 1], -X[..., 0]), axis=-1)\n",
           "that is the clockwise vortex", "check one point by hand"),
    *_pair(nb02, "radius_after", "ignores the pull k",
           "def radius_after(r0, dt, n, k=0.0):\n    return r0 * (1 + dt * dt) ** (n / 2)\n",
           "your answer ignores the pull k", "the part along X shrinks by 1 - k dt"),
    *_pair(nb02, "radius_after", "no square root",
           "def radius_after(r0, dt, n, k=0.0):\n"
           "    return r0 * ((1 - k * dt) ** 2 + dt * dt) ** n\n",
           "grows by its square root", "to the power n/2, not n"),
    *_pair(nb03, "stability_function", "returns R - 1",
           "def stability_function(step, z):\n    z = np.asarray(z, dtype=complex)\n"
           "    return step(lambda t, y: z * y, 0.0, np.ones_like(z), 1.0) - 1\n",
           "you returned the change R - 1", "nothing to subtract"),
    *_pair(nb04, "midpoint_step", "Heun instead of the midpoint",
           "def midpoint_step(f, t, y, dt):\n    k1 = f(t, y)\n"
           "    return y + 0.5 * dt * (k1 + f(t + dt, y + dt * k1))\n",
           "that is Heun's method", "no average"),
    *_pair(nb04, "midpoint_step", "full-step predictor",
           "def midpoint_step(f, t, y, dt):\n"
           "    return y + dt * f(t + 0.5 * dt, y + dt * f(t, y))\n",
           "the midpoint is half a step away", "the predictor goes half way"),
]


@pytest.mark.parametrize("module, plant", ESCALATING, ids=lambda p: getattr(p, "label", ""))
def test_common_hints_escalate(module, plant):
    judge(module, plant)


# --- fifth review: the same mistake repeated gets a fuller second hint (01 Ex 2 and 6, 02 Ex 1
# and 3); each on the review's answer and on one of our own of the same class ---------------

_COHESION = ("def cohesion(X, radius):\n    X = np.asarray(X, float)\n"
             "    D = X[None, :, :] - X[:, None, :]\n"
             "    near = (D ** 2).sum(axis=-1) < radius ** 2\n"
             "    np.fill_diagonal(near, False)\n"
             "    return np.einsum('ij,ijk->ik', near, D) / {count}\n")
ESCALATING_5 = [
    *_pair(nb01, "whirlpool", "outward pull",
           "def whirlpool(t, X, k=0.5):\n    X = np.asarray(X, float)\n"
           "    return np.stack((-X[..., 1] + k * X[..., 0], X[..., 0] + k * X[..., 1]), axis=-1)\n",
           "the pull points outwards", "V = (-0.5, 1)"),
    *_pair(nb01, "whirlpool", "outward pull, written as vortex plus radial",
           "def whirlpool(t, X, k=0.5):\n"
           "    return cl.fields.vortex(t, X) + k * cl.fields.radial(t, X)\n",
           "the pull points outwards", "check one point by hand"),
    *_pair(nb01, "cohesion", "divides by N", _COHESION.format(count="len(X)"),
           "divide by their number, not by N", "near.sum(axis=1, keepdims=True)"),
    *_pair(nb01, "cohesion", "divides by X.shape[0] with a loop-free sum",
           _COHESION.format(count="X.shape[0]"), "divide by their number, not by N",
           "a boid with 2 neighbours averages 2 offsets"),
    *_pair(nb02, "forward_euler_step", "no dt", "def forward_euler_step(f, t, y, dt):\n"
           "    return y + f(t, y)\n", "multiply the slope by dt", "= (-0.5, 1)"),
    *_pair(nb02, "forward_euler_step", "no dt, slope in a variable",
           "def forward_euler_step(f, t, y, dt):\n    slope = np.asarray(f(t, y))\n"
           "    y_next = np.asarray(y, float) + slope\n    return y_next\n",
           "multiply the slope by dt", "f(t, y) is a velocity (m/s)"),
    *_pair(nb02, "drift_dt", "ln(1 + tol)/π", "def drift_dt(tol):\n"
           "    return np.log1p(tol) / np.pi\n", "ln(1 + tol)/π comes from the estimate",
           "a little LARGER than ln(1 + tol)/π"),
    *_pair(nb02, "drift_dt", "ln(1 + tol)/π, written as log(1 + tol)",
           "def drift_dt(tol):\n    return float(np.log(1.0 + tol) / np.pi)\n",
           "ln(1 + tol)/π comes from the estimate", "scipy.optimize.brentq"),
]


@pytest.mark.parametrize("module, plant", ESCALATING_5, ids=lambda p: getattr(p, "label", ""))
def test_repeated_mistakes_of_01_and_02_get_a_fuller_hint(module, plant):
    judge(module, plant)


def test_the_fuller_hints_numbers_are_right():
    """The numbers the fuller hints quote: the whirlpool at (1, 0) with k = 0.5 is (-0.5, 1)
    (the outward one (0.5, 1)); forward Euler's worked step from (0, 1) with dt = 0.5 is
    (-0.5, 1) (without dt (-1, 1)); the largest 1 % step exceeds ln(1.01)/π by about dt²/2
    relative, more than the check's 1e-6."""
    import math

    import numpy as np

    import course_lib as cl

    X = np.array([1.0, 0.0])
    np.testing.assert_allclose(nb01.whirlpool_reference(0.0, X, 0.5), [-0.5, 1.0])
    np.testing.assert_allclose(nb01.whirlpool_reference(0.0, X, -0.5), [0.5, 1.0])
    y = np.array([0.0, 1.0])
    np.testing.assert_allclose(cl.forward_euler(cl.fields.vortex, 0.0, y, 0.5), [-0.5, 1.0])
    np.testing.assert_allclose(y + cl.fields.vortex(0.0, y), [-1.0, 1.0])
    for tol in (0.01, 0.1):
        best, guess = nb02.largest_drift_dt(tol), math.log1p(tol) / math.pi
        assert best > guess and (best / guess - 1) > nb02.DRIFT_RTOL
        assert best / guess - 1 == pytest.approx(best**2 / 2, rel=0.1)


# --- 04, exercise 3: one Newton update is named as such (fifth review) ------------------------

def _newton(guess: str, updates: int, final_check: bool = False) -> str:
    """An implicit midpoint step by Newton's method with a forward-difference Jacobian on the
    flattened state, stopped after ``updates`` updates."""
    check = "    residual(Y)\n" if final_check else ""
    return ("def implicit_midpoint_step(f, t, y, dt):\n    y = np.asarray(y, float)\n"
            "    def residual(Y):\n        return (Y - y - dt * f(t + dt / 2, (y + Y) / 2)).ravel()\n"
            f"    Y = {guess}\n"
            f"    for _ in range({updates}):\n        r = residual(Y)\n"
            "        J = np.empty((y.size, y.size))\n"
            "        for j in range(y.size):\n            e = np.zeros(y.size)\n"
            "            e[j] = 1e-7\n"
            "            J[:, j] = (residual(Y + e.reshape(y.shape)) - r) / 1e-7\n"
            "        Y = Y - np.linalg.solve(J, r).reshape(y.shape)\n"
            f"{check}    return Y\n")


_ONE_NEWTON = "you took one Newton step"
NEWTON_PLANTS = [
    Plant("implicit_midpoint_step", "misconception", "one Newton update from y (the review's)",
          _newton("y.copy()", 1), "incorrect", _ONE_NEWTON,
          avoid="no formula of known values"),
    Plant("implicit_midpoint_step", "misconception", "one Newton update from a forward Euler guess",
          _newton("y + dt * f(t, y)", 1), "incorrect",
          "you took one Newton step; iterate until the residual is at round-off",
          avoid="no formula of known values"),
    Plant("implicit_midpoint_step", "misconception", "one update, then a residual it ignores",
          _newton("y.copy()", 1, final_check=True), "incorrect", _ONE_NEWTON,
          avoid="no formula of known values"),
    Plant("implicit_midpoint_step", "other", "six Newton updates: right",
          _newton("y.copy()", 6), "correct", ""),
    Plant("implicit_midpoint_step", "misconception", "forward Euler: still named as such",
          "def implicit_midpoint_step(f, t, y, dt):\n    return y + dt * f(t, y)\n", "incorrect",
          "that is forward Euler", avoid=_ONE_NEWTON),
    Plant("implicit_midpoint_step", "misconception", "two fixed-point updates: not one Newton step",
          "def implicit_midpoint_step(f, t, y, dt):\n    Y = np.asarray(y, float)\n"
          "    for _ in range(2):\n        Y = y + dt * f(t + dt / 2, (y + Y) / 2)\n    return Y\n",
          "incorrect", "", avoid=_ONE_NEWTON),
]


@pytest.mark.parametrize("plant", NEWTON_PLANTS, ids=lambda p: p.label)
def test_nb04_one_newton_update_is_named(plant):
    judge(nb04, plant)

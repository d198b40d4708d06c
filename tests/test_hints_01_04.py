"""Hints of notebooks 01-04 that the fourth blind review (2026-11-28) found aimed at the wrong
half of a mistake: each planted answer is judged as the grader judges it and must get the
verdict and a hint that names the mistake it makes, on the reviewer's case and on one of our
own of the same class."""

from __future__ import annotations

import pytest

from course_lib.check import nb01, nb03
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
    Plant("largest_stable_dt", "misconception", "long runs, bound 1e300: the bound",
          _search(2000, "1e300"), "incorrect", "the blow-up bound is too high",
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

"""Case data of notebook 02's checks (radius_after and observed_order in course_lib.check.nb02).

The radius exercise's formula and usual slips (:func:`radius_formula`,
:func:`_radius_mistakes`). The one-step methods the order check hands over (forward Euler,
Ralston's and Kutta's methods, none written out in the notebook), the problems (a
pendulum, the double gyre, a forced decay), the check's own three-grid estimate :func:`order_reference`, and
:func:`order_mistakes`, what the usual slips make of it, keyed by hint. Imports NumPy and
(lazily) the double gyre of notebook 02's lesson.
"""

from __future__ import annotations

import math

import numpy as np

from ._answers import kutta3
from .tolerance import escalate


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


def order_reference(step, f, y0, T: float, n: int, *, clock=None, same_dt: bool = False,
                    same_n: bool = False, norm=np.linalg.norm, extra: int = 0,
                    finest: bool = False) -> float:
    """``log2(|X_n - X_2n| / |X_2n - X_4n|)`` from runs of ``n``, ``2n``, ``4n`` steps.

    ``clock(k, dt)`` gives the time passed to the k-th step (default ``k dt``); ``same_dt``
    runs all three with ``dt = T/n`` (to ``T``, ``2T``, ``4T``); ``same_n`` runs ``n`` steps
    of each size (to ``T``, ``T/2``, ``T/4``); ``norm`` measures the differences; ``extra``
    adds steps to each run (-1: one short); ``finest`` compares the coarse run with the
    finest, ``|X_n - X_4n|``, as if it were exact. All exist to recognise mistakes: a clock
    frozen at 0 or a step ahead, runs that do not end at ``T``, a difference measured on one
    component or summed with its signs, the finest run taken for the exact answer.
    """
    ends = []
    for m in (n, 2 * n, 4 * n):
        y, dt = np.array(y0, dtype=float), T / (n if same_dt else m)
        for k in range((n if same_n else m) + extra):
            y = step(f, k * dt if clock is None else clock(k, dt), y, dt)
        ends.append(y)
    coarse = ends[0] - (ends[2] if finest else ends[1])
    with np.errstate(all="ignore"):
        return float(np.log2(norm(coarse) / norm(ends[1] - ends[2])))


def order_mistakes(step, f, y0, T, n, expected) -> dict:
    """What the usual slips make of the three-grid order, keyed by their (escalating) hints;
    the fuller hints work the pendulum's numbers (T = 3 s, n = 40) or name the line to write."""
    e = escalate
    return {
        e("pass the time of each step to step(f, t, y, dt): f depends on t here, and your t "
          "stayed at 0",
          "inside the run write y = step(f, k * dt, y, dt) for k in range(m): with t stuck at 0 "
          "the forced decay's force cos 3t stays 1 and the double gyre keeps its t = 0 shape, "
          "so your runs solve another problem"):
            order_reference(step, f, y0, T, n, clock=lambda k, dt: 0.0),
        e("the k-th step starts at t = k dt: the first step starts at t = 0, not at dt",
          "your clock runs one step ahead, (k + 1) dt, so every step sees the force of the next: "
          "in for k in range(m) pass t = k * dt (0, dt, 2 dt, ...), or add dt to t AFTER the "
          "step"): order_reference(step, f, y0, T, n, clock=lambda k, dt: (k + 1) * dt),
        e("all three runs must end at the same time T: use steps of T/n, T/(2n) and T/(4n), "
          "not the same dt",
          "with T = 3 s and n = 40 the steps are 0.075, 0.0375 and 0.01875 s; one dt for all "
          "three ends the runs at 3, 6 and 12 s. Write dt = T / m for m in (n, 2 * n, 4 * n)"):
            order_reference(step, f, y0, T, n, same_dt=True),
        e("all three runs must end at the same time T: take n, 2n and 4n steps, not n steps of "
          "each size",
          "with T = 3 s and n = 40 the runs take 40, 80 and 160 steps; 40 steps of each size end "
          "at 3, 1.5 and 0.75 s. Loop for k in range(m), with m the run's own count"):
            order_reference(step, f, y0, T, n, same_n=True),
        e("measure the distance between end states over all their components, with a norm "
          "(np.linalg.norm), not one component",
          "the pendulum's state is (θ, ω): d[0] alone drops the error in ω. Write "
          "np.linalg.norm(X_n - X_2n), which sums the squares of every component"):
            order_reference(step, f, y0, T, n, norm=lambda d: abs(np.ravel(d)[0])),
        e("measure the distances with the Euclidean norm |X| of Section 5 (np.linalg.norm), "
          "not the largest component",
          "for d = (3e-4, 4e-4) the norm is 5e-4 and the largest component 4e-4: the ratio of "
          "two differences, and so p, changes. Write np.linalg.norm(d)"):
            order_reference(step, f, y0, T, n, norm=lambda d: np.max(np.abs(d))),
        e("a distance is a norm, |X_n - X_2n| (np.linalg.norm): summing the components with "
          "their signs lets them cancel",
          "for d = (3e-4, -3e-4) np.sum(d) is 0 while np.linalg.norm(d) is 4.2e-4: write "
          "np.linalg.norm(X_n - X_2n)"):
            order_reference(step, f, y0, T, n, norm=lambda d: abs(np.sum(d))),
        e("your runs stop one step short of T: a run of m steps takes all m (range(m)), "
          "so that the three runs end at the same time",
          "with T = 3 s and n = 40 the coarse run then ends at 2.925 s and the finest at "
          "2.98125 s: three different times. Loop for k in range(m), not range(m - 1)"):
            order_reference(step, f, y0, T, n, extra=-1),
        e("your runs take one step too many and end past T: a run of m steps is range(m)",
          "with T = 3 s and n = 40 the coarse run then ends at 3.075 s and the finest at "
          "3.01875 s: three different times. Loop for k in range(m), not range(m + 1)"):
            order_reference(step, f, y0, T, n, extra=1),
        e("compare neighbouring runs, |X_n - X_2n| over |X_2n - X_4n|: the finest run is not "
          "the exact answer, and |X_n - X_4n| over |X_2n - X_4n| is not 2^p",
          "for a first-order method the errors are C h, C h/2 and C h/4: |X_n - X_4n| = 3/4 C h "
          "over |X_2n - X_4n| = 1/4 C h is 3, so p would read log2 3 = 1.58 instead of 1. "
          "Write np.linalg.norm(X_n - X_2n) / np.linalg.norm(X_2n - X_4n)"):
            order_reference(step, f, y0, T, n, finest=True),
        e("the ratio is upside down: the coarse difference |X_n - X_2n| goes on top",
          "for forward Euler |X_n - X_2n| is about twice |X_2n - X_4n|, so p = log2(2) = 1; "
          "the inverted ratio gives log2(1/2) = -1. Put the coarse difference in the "
          "numerator"): -expected,
        e("use log base 2 (each grid halves the step), not the natural log",
          "a ratio of 2 gives p = 1 with np.log2 and 0.693 with np.log: write np.log2(ratio)"):
            expected * math.log(2),
        e("use log base 2 (each grid halves the step), not log10",
          "a ratio of 2 gives p = 1 with np.log2 and 0.301 with np.log10: write "
          "np.log2(ratio)"): expected * math.log10(2),
        e("return the measured p itself, not rounded to a whole order: the point is to see how "
          "close the measurement comes",
          "a first-order method measures p near 1 but not exactly 1 (e.g. 0.98): return the "
          "float log2(ratio), without round() or int()"): float(round(expected)),
    }


# The radius exercise (radius_after): the exact answer and the usual slips.

def _power(base: float, n: int) -> float:
    """``base ** n``, or inf where it overflows (a wrong answer's value, for comparison)."""
    try:
        return base**n
    except OverflowError:
        return math.inf


def radius_formula(r0: float, dt: float, n: int, k: float = 0.0) -> float:
    """Radius after ``n`` forward Euler steps on the whirlpool ``(-y, x) - k (x, y)``:
    ``r0 ((1 - k dt)² + dt²)^(n/2)`` (k = 0: the vortex, ``r0 (1 + dt²)^(n/2)``)."""
    return r0 * ((1.0 - k * dt) ** 2 + dt * dt) ** (n / 2)


#: The fuller radius hints work the case k = 1, dt = 0.25 s (r0 = 0.5 m, n = 10).
_K1 = "with k = 1 and dt = 0.25"


def _radius_mistakes(r0, dt, n, k) -> dict:
    with np.errstate(all="ignore"):
        return {
            escalate("your answer ignores the pull k: each step also moves X by -k dt X, "
                     "towards the centre",
                     "one step maps X to (1 - k dt) X + dt J X: the part along X shrinks by "
                     "1 - k dt while the turn adds dt J X across it"): radius_formula(r0, dt, n),
            escalate("the two parts of a step do not multiply: (1 - k dt) X and dt J X are "
                     "perpendicular, so their lengths add in squares (Pythagoras)",
                     f"{_K1} the parts of a step are 0.75 X and 0.25 J X, so |X| is multiplied "
                     "by √(0.75² + 0.25²) = 0.7906 per step, not by 0.75 · √(1 + 0.25²) = 0.7731"):
                r0 * _power(1 - k * dt, n) * (1 + dt * dt) ** (n / 2),
            escalate("that is the exact whirlpool's radius r0 e^(-k t); forward Euler's "
                     "differs from it",
                     "find the factor by which ONE forward Euler step multiplies |X| (the "
                     "length of (1 - k dt) X + dt J X over |X|) and apply it n times"):
                r0 * np.exp(-k * n * dt),
            escalate("each step multiplies |X|² by that factor, so |X| grows by its square root",
                     "(1 - k dt)² + dt² is the factor of the SQUARED length; after n steps "
                     "|X| is r0 times that factor to the power n/2, not n"):
                r0 * _power((1 - k * dt) ** 2 + dt * dt, n),
            escalate("(k dt)² is missing: |(1 - k dt) X|² = (1 - 2 k dt + k² dt²) |X|²",
                     f"{_K1} (1 - k dt)² = 0.5625, not 1 - 2 k dt = 0.5, so the squared factor is "
                     "0.5625 + 0.0625 = 0.625: write ((1 - k * dt) ** 2 + dt ** 2)"):
                r0 * _power(max(1 - 2 * k * dt + dt * dt, 0.0), n / 2),
            escalate("the pull points inwards: a step multiplies the part along X by 1 - k dt, "
                     "not 1 + k dt",
                     "the whirlpool is (-y, x) - k (x, y): the step adds -k dt X, which "
                     "shortens X for k > 0"):
                r0 * _power((1 + k * dt) ** 2 + dt * dt, n / 2),
            escalate("the per-step factor is √((1 - k dt)² + dt²), not 1 - k dt + dt",
                     f"{_K1} the two parts have lengths 0.75 |X| and 0.25 |X| at right angles: "
                     "their sum has length √(0.75² + 0.25²) |X| = 0.7906 |X|, not "
                     "(0.75 + 0.25) |X| = |X|"):
                r0 * _power(abs(1 - k * dt + dt), n),
            escalate("the radius changes by a factor each step: compound it n times instead of "
                     "adding n times the change",
                     f"{_K1} every step multiplies |X|² by 0.625: after 10 steps by 0.625^10, "
                     "not by 1 + 10 (0.625 - 1), which is negative. Raise the factor to the "
                     "power, factor ** (n / 2)"):
                r0 * np.sqrt(max(1 + n * ((1 - k * dt) ** 2 + dt * dt - 1), 0)),
            escalate("multiply by the starting radius r0",
                     "with r0 = 0.5, k = 1, dt = 0.25 and n = 10 the radius is 0.5 · 0.625^5 = "
                     "0.0477; yours is 0.625^5 = 0.0954, the radius of a particle starting at "
                     "|X| = 1: return r0 * ..."): radius_formula(1.0, dt, n, k),
        }

"""Notebook 07 (springs), the computations: a mass on a damped spring, fast and exact.

Along its axis the anchored spring of notebook 07 is the linear oscillator
``m x'' = -k x - c x'`` (as long as the mass does not reach the anchor). One step of any
of our methods then multiplies ``(x, v)`` by a fixed 2×2 *step matrix* ``S``
(:mod:`course_lib.lessons.nb07_spring_limits`, which also says where it is stable), so a
run of ``n`` steps is the matrix powers ``S^k (x0, v0)``: the same numbers as
:func:`~course_lib.integrators.integrate` (to round-off), in a few vectorized products
whatever ``n`` is. That is what lets the widget answer within 100 ms.

Holds the widget's pure function (:func:`run_spring`), the step limit measured by
simulation (:func:`spring_dt_max`) and :func:`settling_time`; re-exports the step matrix
and its powers. The drawing and the widget live in
:mod:`course_lib.lessons.nb07_spring_view`, which imports this module (never the other
way); the notebook imports both through :mod:`course_lib.lessons.nb07_springs`. Built on
the core only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..integrators import integrate
from ..springs import anchored_spring, damped_oscillator
from ..stability import bisect_stable_dt
from .nb07_spring_limits import (
    damped_dt_limit,
    limit_text,
    matrix_powers,
    spectral_radius,
    stable_windows,
    step_matrix,
)

__all__ = ["SpringRun", "damped_dt_limit", "matrix_powers", "run_spring", "settling_time",
           "spectral_radius", "spring_dt_max", "step_matrix", "verdict_growth"]

#: :func:`spring_dt_max`'s runs: released this far from rest (m), unstable past this (m or m/s).
RELEASE, BLOWUP_BOUND = 1e-9, 1.5


@dataclass
class SpringRun:
    """Result of :func:`run_spring`: a mass on a damped spring, numerical and exact.

    Arrays hold every step ``k = 0 ... n`` (NaN after a blow-up).
    """

    t: np.ndarray             #: times (s)
    x: np.ndarray             #: stretch (m)
    v: np.ndarray             #: velocity (m/s)
    exact: np.ndarray         #: exact stretch (m)
    error: np.ndarray         #: |x - exact| (m)
    energy: np.ndarray        #: kinetic + elastic energy (J)
    exact_energy: np.ndarray  #: exact energy (J)
    stable: bool
    message: str
    blowup_step: int | None   #: first step past the bound, if any
    dt_limit: float           #: first instability of the method with this damping (s)
    params: dict
    t_fine: np.ndarray        #: a fine grid for drawing the exact solution (s)
    exact_fine: np.ndarray
    windows: tuple = ()       #: every stable step (s), as intervals (:func:`stable_windows`)

    @property
    def limit_text(self) -> str:
        return limit_text(self.windows)


def run_spring(k: float = 10.0, c: float = 0.0, dt: float = 0.05,
               method: str = "symplectic_euler", m: float = 1.0, t_end: float = 20.0,
               stretch: float = 0.1, bound: float = 1e3) -> SpringRun:
    """Run the mass on a spring (stiffness ``k`` N/m, damping ``c`` N s/m along it, mass
    ``m`` kg, released at rest stretched by ``stretch`` m) with ``method`` for
    ``round(t_end / dt)`` steps, from the method's step matrix.

    A run is declared blown up at the first step where ``|x|`` or ``|v|`` exceeds
    ``bound`` (m, m/s); later values are NaN. A run is stable when it did not blow up and
    the step matrix does not amplify (spectral radius at most 1): forward Euler's slow
    growth without damping counts as unstable before it reaches the bound. Pure: same
    arguments, same result.
    """
    n = max(1, round(t_end / dt))
    S = step_matrix(method, k, m, c, dt)
    windows = stable_windows(method, float(k), float(m), float(c))
    with np.errstate(over="ignore", invalid="ignore"):
        states = matrix_powers(S, n) @ np.array([stretch, 0.0])
        size = np.max(np.abs(states), axis=1)
    bad = np.flatnonzero(~(size <= bound))
    t = dt * np.arange(n + 1)
    blowup = int(bad[0]) if bad.size else None
    growth = spectral_radius(S)
    if blowup is not None:
        states[blowup:] = np.nan
        message = f"blew up: |x| or |v| passed {bound:g} at step {blowup}, t = {t[blowup]:.3g} s"
    elif growth > 1.0 + 1e-13:
        message = f"unstable: grows by a factor {growth:.6g} per step"
    else:
        message = "stable"
    x, v = states[:, 0], states[:, 1]
    exact = damped_oscillator(t, k, m, c, stretch)
    exact_v = damped_oscillator(t, k, m, c, stretch, velocity=True)
    t_fine = np.linspace(0.0, t[-1], 1501)
    return SpringRun(
        t, x, v, exact, np.abs(x - exact), 0.5 * m * v**2 + 0.5 * k * x**2,
        0.5 * m * exact_v**2 + 0.5 * k * exact**2, message == "stable", message, blowup,
        windows[0][1] if windows and windows[0][0] == 0.0 else 0.0,
        {"k": k, "c": c, "dt": dt, "method": method, "m": m, "t_end": t_end},
        t_fine, damped_oscillator(t_fine, k, m, c, stretch), windows)


def spring_dt_max(k: float, m: float = 1.0, method: str = "symplectic_euler",
                  n_steps: int = 1000, rtol: float = 1e-4) -> float:
    """Largest stable step (s) for a mass on an undamped spring, measured by simulation:
    bisection on the verdict of :func:`~course_lib.integrators.integrate` over
    ``n_steps`` steps of the 3D anchored spring.

    The spring (rest length 1 m) starts stretched by 1 nm; a run whose state grows past
    1.5 (m or m/s), i.e. a stretch of 0.5 m or a speed of 1.5 m/s, is declared unstable:
    a growth by :func:`verdict_growth` (about 10⁸), caught while the motion is still
    linear (the mass never reaches the anchor).
    """
    system, y0, _ = anchored_spring(k, m, stretch=RELEASE)
    scale = np.sqrt(m / k)

    def stable(dt):
        return integrate(system, y0, (0.0, n_steps * dt), dt, method=method,
                         blowup_bound=BLOWUP_BOUND).stable

    return bisect_stable_dt(stable, 0.5 * scale, 3.0 * scale, rtol)


def verdict_growth(k: float, m: float = 1.0, rest: float = 1.0) -> float:
    """Growth of the stretch, relative to the release, at which :func:`spring_dt_max`'s
    runs are declared unstable just past the limit 2/ω (dimensionless).

    There a step flips the stretch and keeps its size, so the speed is ω|x|: the state
    passes :data:`BLOWUP_BOUND` when the speed does (|x| = 1.5/ω m) or the position
    ``rest + x`` does (x = 0.5 m), whichever comes first.
    """
    omega = np.sqrt(k / m)
    return float(min(BLOWUP_BOUND - rest, BLOWUP_BOUND / omega) / RELEASE)


def settling_time(t, x, tol: float = 0.01) -> float:
    """First time (s) after which ``|x|`` stays below ``tol · |x[0]|`` for good."""
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    outside = np.nonzero(np.abs(x) > tol * abs(x[0]))[0]
    if outside.size == 0:
        return float(t[0])
    if outside[-1] + 1 >= t.size:
        return float("inf")
    return float(t[outside[-1] + 1])

"""Notebook 07 (springs), the computations: a mass on a damped spring, fast and exact.

Along its axis the anchored spring of notebook 07 is the linear oscillator
``m x'' = -k x - c x'`` (as long as the mass does not reach the anchor). One step of any
of our methods then multiplies ``(x, v)`` by a fixed 2×2 *step matrix* ``S``; this module
gets ``S`` from course_lib's own one-step functions (one step from each basis vector), so
a run of ``n`` steps is the matrix powers ``S^k (x0, v0)``: the same numbers as
:func:`~course_lib.integrators.integrate` (to round-off), in a few vectorized products
whatever ``n`` is. That is what lets the widget answer within 100 ms.

Holds the step matrix (:func:`step_matrix`), the method's stability limit with damping
(:func:`damped_dt_limit`, measured from ``S``, and :func:`symplectic_euler_limit`, its
closed form), the widget's pure function (:func:`run_spring`), the step limit measured by
simulation (:func:`spring_dt_max`) and :func:`settling_time`. The drawing and the widget
live in :mod:`course_lib.lessons.nb07_spring_view`, which imports this module (never the
other way); the notebook imports both through :mod:`course_lib.lessons.nb07_springs`.
Built on the core only.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..integrators import IMPLICIT_METHODS, METHODS, get_stepper, integrate
from ..springs import anchored_spring, damped_oscillator
from ..stability import bisect_stable_dt
from ..systems import oscillator


def step_matrix(method: str, k: float, m: float, c: float, dt: float) -> np.ndarray:
    """The 2×2 matrix ``S`` with ``(x, v)_{n+1} = S (x, v)_n`` for one step of ``method``
    on ``m x'' = -k x - c x'``.

    Explicit methods: one step of course_lib's own stepper from ``(1, 0)`` and from
    ``(0, 1)`` (a linear problem makes the step linear, so these two columns are all of
    it). Implicit methods: their defining linear solves, ``(I - dt A)^{-1}`` for backward
    Euler and ``(I - dt A/2)^{-1} (I + dt A/2)`` for the trapezoid, with ``A`` the
    system's matrix ``[[0, 1], [-k/m, -c/m]]``.
    """
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; choose one of {list(METHODS)}")
    A = np.array([[0.0, 1.0], [-k / m, -c / m]])
    eye = np.eye(2)
    if method == "backward_euler":
        return np.linalg.inv(eye - dt * A)
    if method == "trapezoidal":
        return np.linalg.solve(eye - 0.5 * dt * A, eye + 0.5 * dt * A)
    f = oscillator(np.sqrt(k / m), c / m)
    stepper = get_stepper(method)
    return np.column_stack([stepper(f, 0.0, e, dt) for e in eye])


def spectral_radius(S: np.ndarray) -> float:
    """Largest ``|μ|`` over the eigenvalues of a 2×2 matrix (from its trace and determinant)."""
    half_trace = 0.5 * (S[0, 0] + S[1, 1])
    det = S[0, 0] * S[1, 1] - S[0, 1] * S[1, 0]
    root = np.sqrt(complex(half_trace**2 - det))
    return float(max(abs(half_trace + root), abs(half_trace - root)))


@functools.lru_cache(maxsize=256)
def damped_dt_limit(method: str, k: float, m: float = 1.0, c: float = 0.0) -> float:
    """Largest step (s) for which ``method`` keeps the damped spring bounded, measured.

    The step is stable while the spectral radius of :func:`step_matrix` stays at most 1
    (to 1e-13). We scan ``dt`` on a log grid from ``0.01 τ`` to ``100 τ``, with
    ``τ = 1 / (ω + c/m)`` the system's fastest time scale, for the first unstable step and
    bisect to round-off. Returns ``inf`` for the A-stable implicit methods (no limit for
    any ``c >= 0``) and 0 when even ``0.01 τ`` is unstable (forward Euler without damping).
    """
    if method in IMPLICIT_METHODS:
        return float("inf")
    tau = 1.0 / (np.sqrt(k / m) + c / m)

    def unstable(dt):
        return spectral_radius(step_matrix(method, k, m, c, dt)) > 1.0 + 1e-13

    grid = np.geomspace(0.01, 100.0, 121) * tau
    bad = [unstable(dt) for dt in grid]
    if bad[0]:
        return 0.0
    if not any(bad):
        return float("inf")
    j = bad.index(True)
    lo, hi = grid[j - 1], grid[j]
    while hi - lo > 1e-14 * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if unstable(mid) else (mid, hi)
    return float(lo)


def symplectic_euler_limit(k: float, m: float = 1.0, c: float = 0.0) -> float:
    """Closed form of symplectic Euler's limit with damping: ``ω² dt² + 2 γ dt < 4`` with
    ``γ = c/m``, i.e. ``dt < 4 / (γ + √(γ² + 4ω²)) = (2/ω)(√(1 + ζ²) - ζ)``, ``ζ = γ/2ω``."""
    gamma = c / m
    return float(4.0 / (gamma + np.sqrt(gamma**2 + 4.0 * k / m)))


def limit_text(dt_limit: float) -> str:
    """How a limit reads in a title: ``"dt < 0.632 s"``, ``"none"`` or ``"every dt"``."""
    if np.isinf(dt_limit):
        return "no step limit (A-stable)"
    if dt_limit == 0.0:
        return "unstable at every dt"
    return f"stable for dt < {dt_limit:.3g} s"


def matrix_powers(S: np.ndarray, n: int) -> np.ndarray:
    """``S^0, S^1, ..., S^n`` of a 2×2 matrix, shape ``(n+1, 2, 2)``, by doubling: the
    block of powers found so far is multiplied by the next power of two at once."""
    P = np.empty((n + 1, 2, 2))
    P[0] = np.eye(2)
    filled, power = 1, np.array(S, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        while filled <= n:
            take = min(filled, n + 1 - filled)
            P[filled:filled + take] = power @ P[:take]
            filled += take
            power = power @ power
    return P


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
    dt_limit: float           #: stability limit of the method with this damping (s)
    params: dict
    t_fine: np.ndarray        #: a fine grid for drawing the exact solution (s)
    exact_fine: np.ndarray

    @property
    def limit_text(self) -> str:
        return limit_text(self.dt_limit)


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
        damped_dt_limit(method, float(k), float(m), float(c)),
        {"k": k, "c": c, "dt": dt, "method": method, "m": m, "t_end": t_end},
        t_fine, damped_oscillator(t_fine, k, m, c, stretch))


def spring_dt_max(k: float, m: float = 1.0, method: str = "symplectic_euler",
                  n_steps: int = 1000, rtol: float = 1e-4) -> float:
    """Largest stable step (s) for a mass on an undamped spring, measured by simulation:
    bisection on the verdict of :func:`~course_lib.integrators.integrate` over
    ``n_steps`` steps of the 3D anchored spring.

    The spring (rest length 1 m) starts stretched by 1 nm; a run whose state grows past
    1.5 (m or m/s), i.e. a stretch of 0.5 m or a speed of 1.5 m/s, is declared unstable.
    That is a growth by more than 10⁸, caught while the motion is still linear (the mass
    never reaches the anchor).
    """
    system, y0, _ = anchored_spring(k, m, stretch=1e-9)
    scale = np.sqrt(m / k)

    def stable(dt):
        return integrate(system, y0, (0.0, n_steps * dt), dt, method=method,
                         blowup_bound=1.5).stable

    return bisect_stable_dt(stable, 0.5 * scale, 3.0 * scale, rtol)


def settling_time(t, x, tol: float = 0.01) -> float:
    """First time (s) after which ``|x|`` stays below ``tol · |x[0]|`` for good."""
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    outside = np.nonzero(np.abs(x) > tol * abs(x[0]))[0]
    if outside.size == 0:
        return float(t[0])
    if outside[-1] + 1 >= t.size:
        return float("inf")
    return float(t[outside[-1] + 1])

"""Notebook 07 (springs): the step matrix of a damped spring and where it is stable.

Along its axis the anchored spring is the linear oscillator ``m x'' = -k x - c x'``, so one
step of any of our methods multiplies ``(x, v)`` by a fixed 2×2 *step matrix* ``S``
(:func:`step_matrix`, from course_lib's own one-step functions). Its eigenvalues decide
stability, and this module reads them several ways:

- :func:`damped_dt_limit`: the first step at which ``S`` amplifies, measured (scan and
  bisection on the spectral radius); :func:`symplectic_euler_limit`, its closed form for
  symplectic Euler;
- :func:`stable_windows`: *every* stable step, as intervals, from the Jury conditions
  (:func:`velocity_verlet_windows`: velocity Verlet's stable set is two intervals for
  light damping), and :func:`scan_windows`, the same measured on a grid of steps;
- :func:`growth`: how much a run grows over ``n`` steps (:func:`matrix_powers`), the
  verdict a simulation would give;
- :func:`limit_text`: a stable set in words, for titles.

Built on the core only; :mod:`course_lib.lessons.nb07_spring_runs` imports it.
"""

from __future__ import annotations

import functools
import itertools

import numpy as np

from ..integrators import IMPLICIT_METHODS, METHODS, get_stepper
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


def velocity_verlet_windows(k: float, m: float = 1.0, c: float = 0.0
                            ) -> tuple[tuple[float, float], ...]:
    """Velocity Verlet's stable steps (s) on the damped spring: disjoint ``(lo, hi)``
    intervals, from the Jury conditions on its step matrix.

    With ``w = ω dt``, ``ζ = c / (2√(km))`` and ``q = 1 - ζ w`` (one half kick's factor on
    ``v``): ``det S = q²`` and ``tr S = 1 + q² - w² (1 + q) / 2``. Both eigenvalues lie in
    the unit disc iff ``|q| < 1`` (``γ dt < 4``) and ``1 + det S + tr S > 0``, which is
    ``P(w) = ζ w³ + (4ζ² - 2) w² - 8 ζ w + 8 > 0``. Since ``P(0) = P(2/ζ) = 8``, the stable
    set is ``0 < w < 2/ζ`` less the stretch between ``P``'s two positive roots when it has
    them (``ζ`` below about 0.526): then it is two intervals. Without damping, ``w < 2``.
    """
    omega = np.sqrt(k / m)
    zeta = c / (2.0 * np.sqrt(k * m))
    if zeta == 0.0:
        return ((0.0, float(2.0 / omega)),)
    top = 2.0 / zeta

    def P(w):
        return zeta * w**3 + (4 * zeta**2 - 2) * w**2 - 8 * zeta * w + 8

    roots = np.roots([zeta, 4 * zeta**2 - 2, -8 * zeta, 8])
    real = np.sort(roots.real[(np.abs(roots.imag) <= 1e-9 * np.abs(roots)) & (roots.real > 0)])
    edges = np.r_[0.0, real[real < top], top]
    windows = [(lo, hi) for lo, hi in itertools.pairwise(edges)
               if hi > lo and P(0.5 * (lo + hi)) > 0]
    return tuple((float(lo / omega), float(hi / omega)) for lo, hi in windows)


def velocity_verlet_gap_end() -> tuple[float, float]:
    """``(ζ*, w*)``: the damping ratio above which velocity Verlet's stable set is one
    interval again, and ``ω dt`` where its gap closes. At ``ζ*`` the cubic ``P`` of
    :func:`velocity_verlet_windows` has a double root: its discriminant vanishes, which
    with ``u = ζ²`` reads ``16 u³ + 8 u² + 11 u = 4``; ``w*`` is the root of ``P'``."""
    u = np.roots([16.0, 8.0, 11.0, -4.0])
    zeta = float(np.sqrt(u[np.abs(u.imag) < 1e-12].real.max()))
    b, c = 2 * (4 * zeta**2 - 2), -8 * zeta          # P'(w) = 3ζ w² + b w + c
    return zeta, float((-b + np.sqrt(b * b - 12 * zeta * c)) / (6 * zeta))


def stable_windows(method: str, k: float, m: float = 1.0, c: float = 0.0
                   ) -> tuple[tuple[float, float], ...]:
    """Every stable step (s) of ``method`` on the damped spring, as disjoint ``(lo, hi)``
    intervals (``hi`` may be ``inf``; an empty tuple: unstable at every step).

    Velocity Verlet from its Jury conditions (:func:`velocity_verlet_windows`: two
    intervals for light damping); symplectic Euler from its closed form; the implicit
    methods have none; the Runge-Kutta methods' stable set on this problem is one interval
    ``dt <`` :func:`damped_dt_limit` (the tests scan it densely for damping ratios 0 to 10).
    """
    if method == "velocity_verlet":
        return velocity_verlet_windows(k, m, c)
    if method == "symplectic_euler":
        return ((0.0, symplectic_euler_limit(k, m, c)),)
    limit = damped_dt_limit(method, float(k), float(m), float(c))
    return ((0.0, limit),) if limit > 0 else ()


def scan_windows(method: str, k: float, m: float, c: float, dts) -> tuple[tuple[float, float], ...]:
    """The stable intervals of ``method`` measured on the grid ``dts`` (s, increasing): the
    spectral radius of :func:`step_matrix` at each step (stable: at most 1 + 1e-13), each
    change of verdict between neighbours bisected to round-off. An interval narrower
    than the grid's spacing can be missed."""
    dts = np.asarray(dts, dtype=float)

    def stable(dt):
        return spectral_radius(step_matrix(method, k, m, c, dt)) <= 1.0 + 1e-13

    def edge(lo, hi):   # stable(lo) != stable(hi): the step where the verdict changes
        side = stable(lo)
        while hi - lo > 1e-14 * hi:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if stable(mid) == side else (lo, mid)
        return 0.5 * (lo + hi)

    verdicts = [stable(dt) for dt in dts]
    windows, start = [], 0.0 if verdicts[0] else None
    for j in range(1, dts.size):
        if verdicts[j] != verdicts[j - 1]:
            at = edge(dts[j - 1], dts[j])
            if verdicts[j]:
                start = at
            else:
                windows.append((start, at))
                start = None
    if start is not None:
        windows.append((start, float("inf")))
    return tuple((float(lo), float(hi)) for lo, hi in windows)


def limit_text(windows) -> str:
    """How a stable set reads in a title: ``"stable for dt < 0.632 s"``, with a second
    window ``"... and for 0.894 s < dt < 1.26 s"``, ``"no step limit (A-stable)"`` or
    ``"unstable at every dt"``. ``windows`` as :func:`stable_windows` returns them, or one
    limit (s): ``dt < limit``."""
    if np.ndim(windows) == 0:
        windows = ((0.0, float(windows)),) if windows > 0 else ()
    if not windows:
        return "unstable at every dt"
    if np.isinf(windows[0][1]):
        return "no step limit (A-stable)"
    parts = [f"dt < {hi:.3g} s" if lo == 0.0 else f"{lo:.3g} s < dt < {hi:.3g} s"
             for lo, hi in windows]
    return "stable for " + " and for ".join(parts)


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


def growth(method: str, k: float, m: float, c: float, dts, n_steps: int = 1000,
           cap: float = 1e12) -> np.ndarray:
    """Largest ``|x|`` over ``n_steps`` steps of the spring released from rest, relative to
    the release stretch, for each step in ``dts`` (s): the verdict a run of that length
    would give. Values above ``cap`` are returned as ``cap`` (an overflow as well)."""
    out = np.empty(len(dts))
    for j, dt in enumerate(dts):
        with np.errstate(over="ignore", invalid="ignore"):
            x = matrix_powers(step_matrix(method, k, m, c, dt), n_steps)[:, 0, 0]
            top = np.max(np.abs(x))
        out[j] = min(top, cap) if np.isfinite(top) else cap
    return out

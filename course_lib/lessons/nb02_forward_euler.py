"""Notebook 02 (forward Euler): a flow without an exact solution, and the three-grid order.

- :func:`double_gyre` is the time-periodic double-gyre velocity field (Shadden, Lekien &
  Marsden 2005), a standard test of flow visualisation: two counter-rotating cells in
  ``[0, 2] × [0, 1]`` whose dividing line sways left and right. Its particle paths have
  no formula, which is the point: notebook 02 measures an order of accuracy on it without
  knowing the answer.
- :func:`euler_endpoints` runs forward Euler with ``n``, ``2n``, ``4n``, ... steps to the
  same end time and returns the end points;
- :func:`three_grid_order` turns three of them into the observed order,
  ``p = log2(|X_n - X_2n| / |X_2n - X_4n|)``;
- :func:`spiral_experiment` is the pure half of the spiral explorer (the view is in
  :mod:`course_lib.lessons.nb02_spiral_view`): one revolution of forward Euler on the vortex
  at a given step, its radius growth against the theory, and its global and local errors,
  placed on the convergence curves of Section 4 (:func:`convergence_curves`).

Imports the core only (:func:`course_lib.integrate`, :mod:`course_lib.fields`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..fields import vortex
from ..integrators import integrate


def double_gyre(t, X, A: float = 0.1, eps: float = 0.25, omega: float = 2 * np.pi / 10):
    """Velocity (m/s) of the double gyre at time ``t`` (s), positions ``X`` of shape (..., 2).

    ``V = (-π A sin(π f) cos(π y), π A cos(π f) sin(π y) ∂f/∂x)`` with
    ``f(x, t) = a x² + b x``, ``a = eps sin(ω t)``, ``b = 1 - 2 eps sin(ω t)``: the stream
    function ``ψ = A sin(π f) sin(π y)`` of two gyres whose border oscillates with period
    ``2π/ω`` (10 s by default). Divergence-free; the walls of the box are streamlines.
    """
    X = np.asarray(X, dtype=float)
    x, y = X[..., 0], X[..., 1]
    a = eps * np.sin(omega * t)
    b = 1.0 - 2.0 * a
    f = a * x * x + b * x
    dfdx = 2.0 * a * x + b
    u = -np.pi * A * np.sin(np.pi * f) * np.cos(np.pi * y)
    v = np.pi * A * np.cos(np.pi * f) * np.sin(np.pi * y) * dfdx
    return np.stack((u, v), axis=-1)


def euler_endpoints(f, y0, T: float, counts, method: str = "forward_euler") -> np.ndarray:
    """End states at ``T`` (s) of runs with ``n`` steps of ``T/n`` for each ``n`` in
    ``counts``; shape ``(len(counts), *y0.shape)``."""
    return np.array([integrate(f, y0, (0.0, T), T / n, method).y[-1] for n in counts])


def three_grid_order(coarse, middle, fine) -> float:
    """Observed order from end states with steps ``dt``, ``dt/2`` and ``dt/4``.

    If ``X_dt = X + C dt^p + ...``, successive differences shrink by ``2^p``:
    ``p = log2(|X_dt - X_dt/2| / |X_dt/2 - X_dt/4|)``; no exact solution needed.
    """
    d1 = np.linalg.norm(np.asarray(coarse) - np.asarray(middle))
    d2 = np.linalg.norm(np.asarray(middle) - np.asarray(fine))
    return float(np.log2(d1 / d2))


# --- the spiral explorer: dt against the spiral and the convergence plot ------------------

#: Range of the explorer's time step (s).
SPIRAL_DT_RANGE = (0.01, 1.0)


@dataclass
class SpiralResult:
    """One revolution of forward Euler on the vortex from ``(1, 0)`` with step ``dt`` (s).

    ``t`` ``(n+1,)`` (s) and ``X`` ``(n+1, 2)`` (m): the run to ``2π`` (its last step
    shortened to land there); ``growth``: ``|X|`` at ``2π``, and ``growth_theory``, the
    product of ``√(1 + h²)`` over the steps ``h`` taken; ``error``: ``|X(π) - (-1, 0)|`` (m)
    of a run to ``T = π``, the global error of Section 4; ``local``: the error of one step
    from the exact start, ``|X_1 - (cos dt, sin dt)|`` (m); ``verdict``: one line.
    """

    dt: float
    t: np.ndarray
    X: np.ndarray
    growth: float
    growth_theory: float
    error: float
    local: float
    verdict: str


def spiral_experiment(dt: float) -> SpiralResult:
    """Forward Euler on the vortex at step ``dt`` (s): one revolution, and the errors at
    ``T = π`` and after one step (pure; what the spiral explorer draws)."""
    # a log slider's ends come back as 10**log10(end), a rounding off the end itself
    lo, hi = SPIRAL_DT_RANGE
    if lo * (1 - 1e-9) <= dt <= hi * (1 + 1e-9):
        dt = min(max(dt, lo), hi)
    else:
        raise ValueError(f"dt must lie in {SPIRAL_DT_RANGE} s, got {dt!r}")
    run = integrate(vortex, [1.0, 0.0], (0.0, 2 * np.pi), dt)
    growth = float(np.linalg.norm(run.y[-1]))
    theory = float(np.prod(np.sqrt(1.0 + np.diff(run.t) ** 2)))
    half = integrate(vortex, [1.0, 0.0], (0.0, np.pi), min(dt, np.pi))
    error = float(np.linalg.norm(half.y[-1] - [-1.0, 0.0]))
    local = float(np.hypot(1.0 - np.cos(dt), dt - np.sin(dt)))
    verdict = (f"dt = {dt:.3g} s: {run.n_steps} steps per revolution; the radius grows "
               f"×{growth:.4f} in one revolution (theory ×{theory:.4f}); error at T = π: "
               f"{error:.2g} m")
    return SpiralResult(dt, run.t, run.y, growth, theory, error, local, verdict)


@functools.cache
def convergence_curves(n_max: int = 2048) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(dt, global, local)`` for ``dt = π/n``, ``n = 1 ... n_max``: forward Euler's error
    at ``T = π`` from ``(1, 0)``, in closed form ``|(1 + i dt)^n + 1|`` (notebook 02's
    Section 4 checks it against runs), and the error of one step."""
    n = np.arange(1, n_max + 1)
    dt = np.pi / n
    error = np.abs(np.exp(n * np.log1p(1j * dt)) + 1.0)
    local = np.hypot(1.0 - np.cos(dt), dt - np.sin(dt))
    return dt, error, local

"""Notebook 02 (forward Euler): a flow without an exact solution, and the three-grid order.

- :func:`double_gyre` is the time-periodic double-gyre velocity field (Shadden, Lekien &
  Marsden 2005), a standard test of flow visualisation: two counter-rotating cells in
  ``[0, 2] × [0, 1]`` whose dividing line sways left and right. Its particle paths have
  no formula, which is the point: notebook 02 measures an order of accuracy on it without
  knowing the answer.
- :func:`euler_endpoints` runs forward Euler with ``n``, ``2n``, ``4n``, ... steps to the
  same end time and returns the end points;
- :func:`three_grid_order` turns three of them into the observed order,
  ``p = log2(|X_n - X_2n| / |X_2n - X_4n|)``.

Imports the core only (:func:`course_lib.integrate`).
"""

from __future__ import annotations

import numpy as np

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

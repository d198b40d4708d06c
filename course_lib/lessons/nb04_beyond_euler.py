"""Notebook 04 (beyond Euler): a stiff problem on which the implicit methods win on cost.

The **stiff follower**: a particle tied by a stiff, heavily damped (massless) spring to a
target ``P(t) = (cos t, sin t)`` that circles the origin once every 2π s,

    dX/dt = -κ (X - P(t)),      κ = 1000 1/s by default.

It has two time scales: the particle catches up with the target within ``1/κ = 1 ms``,
then follows it around the circle, lagging by about ``1/κ`` rad. The exact solution, in
complex notation ``z = x + i y``, is ``z(t) = e^{it} κ/(κ + i) + (z0 - κ/(κ + i)) e^{-κt}``.
An explicit method must resolve the 1 ms scale to stay stable (``κ dt < 2`` for forward
Euler and midpoint, ``< 2.785`` for RK4) for as long as it runs; an implicit one may step
at the scale of the motion it is asked to draw.

- :func:`follower` returns ``f``, its (constant) Jacobian and the exact solution;
- :func:`cost_study` runs each method with a range of step counts and records the error at
  the end, the right-hand-side evaluations (``Trajectory.nfev``) and the wall-clock time.

Imports the core only.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..integrators import IMPLICIT_METHODS, integrate

#: Stiffness of the follower's spring (1/s).
KAPPA = 1000.0


def follower(kappa: float = KAPPA):
    """``(f, jac, exact)`` of ``dX/dt = -κ (X - P(t))``, ``P(t) = (cos t, sin t)`` (m).

    ``f(t, X)`` takes ``X`` of shape ``(2,)``; ``jac`` is the constant ``-κ I``;
    ``exact(t, X0)`` gives the exact state at times ``t`` (shape ``t.shape + (2,)``).
    """
    if not kappa > 0:
        raise ValueError(f"kappa must be > 0, got {kappa!r}")
    jac = -kappa * np.eye(2)

    def f(t, X):
        return -kappa * (X - np.array([np.cos(t), np.sin(t)]))

    def exact(t, X0):
        t = np.asarray(t, dtype=float)
        z0 = complex(X0[0], X0[1])
        lag = kappa / (kappa + 1j)
        z = np.exp(1j * t) * lag + (z0 - lag) * np.exp(-kappa * t)
        return np.stack((z.real, z.imag), axis=-1)

    return f, jac, exact


@dataclass
class CostRow:
    """One run of :func:`cost_study`: steps, f-evaluations, error at the end (m; ``inf``
    if the run blew up), wall-clock time (s)."""

    method: str
    steps: int
    nfev: int
    error: float
    seconds: float


def cost_study(methods, counts, T: float = 2 * np.pi, X0=(0.0, 0.0), kappa: float = KAPPA,
               blowup_bound: float = 1e3) -> list[CostRow]:
    """Run every method with ``n`` steps of ``T/n`` for each ``n`` in ``counts``.

    The implicit methods get the exact Jacobian (one Newton iteration then solves this
    linear problem; course_lib checks it with one more evaluation). A run counts as blown
    up when ``|X|`` passes ``blowup_bound`` (m), far above the unit circle it should follow.
    """
    f, jac, exact = follower(kappa)
    X0 = np.asarray(X0, dtype=float)
    end = exact(T, X0)
    rows = []
    for method in methods:
        kw = {"jac": jac} if method in IMPLICIT_METHODS else {}
        for n in counts:
            start = time.perf_counter()
            run = integrate(f, X0, (0.0, T), T / n, method, blowup_bound=blowup_bound, **kw)
            seconds = time.perf_counter() - start
            error = float(np.linalg.norm(run.y[-1] - end)) if run.stable else np.inf
            rows.append(CostRow(method, int(n), run.nfev, error, seconds))
    return rows


def cheapest(rows, method: str, target: float) -> CostRow | None:
    """The run of ``method`` with the fewest f-evaluations whose error is below ``target``."""
    good = [r for r in rows if r.method == method and r.error <= target]
    return min(good, key=lambda r: r.nfev) if good else None

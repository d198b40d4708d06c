"""Notebook 04 (beyond Euler): a stiff problem on which the implicit methods win on cost.

The **stiff follower**: a particle tied by a stiff, heavily damped (massless) spring to a
target ``P(t) = (cos t, sin t)`` that circles the origin once every 2π s,

    dX/dt = -κ (X - P(t)),      κ = 1000 1/s by default.

It has two time scales: the particle catches up with the target on the time scale ``1/κ = 1 ms``,
then follows it around the circle, lagging by about ``1/κ`` rad. The exact solution, in
complex notation ``z = x + i y``, is ``z(t) = e^{it} κ/(κ + i) + (z0 - κ/(κ + i)) e^{-κt}``.
An explicit method must resolve the 1 ms scale to stay stable (``κ dt < 2`` for forward
Euler and midpoint, ``< 2.785`` for RK4) for as long as it runs; an implicit one may step
at the scale of the motion it is asked to draw.

- :func:`follower` returns ``f``, its (constant) Jacobian and the exact solution;
- :func:`cost_study` runs each method with a range of step counts and records the error at
  the end and the right-hand-side evaluations (``Trajectory.nfev``);
- :func:`cpu_per_step` times runs in CPU time (``time.process_time``, the best of a few runs,
  so that other programs on a busy machine do not count), per step;
- :func:`fewest_steps` finds, by bisection on the step count, the smallest ``n`` whose run
  ends within a target error (the true minimum, not the nearest point of a grid);
- :func:`follower_experiment` is the pure half of the follower explorer (the view is in
  :mod:`course_lib.lessons.nb04_follower_view`): the first steps of every method at one
  ``κ dt``, beside the exact solution and each method's ``R(-κ dt)``.

Imports the core only.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..integrators import IMPLICIT_METHODS, integrate
from ..stability import amplification_factor

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
        # scalar arithmetic: the same numbers as -κ (X - (cos t, sin t)) in half the time
        x, y = X.tolist()
        return np.array((-kappa * (x - math.cos(t)), -kappa * (y - math.sin(t))))

    def exact(t, X0):
        t = np.asarray(t, dtype=float)
        z0 = complex(X0[0], X0[1])
        lag = kappa / (kappa + 1j)
        z = np.exp(1j * t) * lag + (z0 - lag) * np.exp(-kappa * t)
        return np.stack((z.real, z.imag), axis=-1)

    return f, jac, exact


@dataclass(frozen=True)
class CostRow:
    """One run of :func:`cost_study`: steps, f-evaluations, error at the end (m; ``inf``
    if the run blew up)."""

    method: str
    steps: int
    nfev: int
    error: float


def cost_study(methods, counts, T: float = 2 * np.pi, X0=(0.0, 0.0), kappa: float = KAPPA,
               blowup_bound: float = 1e3) -> list[CostRow]:
    """Run every method with ``n`` steps of ``T/n`` for each ``n`` in ``counts``.

    The implicit methods get the exact Jacobian (one Newton iteration then solves this
    linear problem; course_lib checks it with one more evaluation). A run counts as blown
    up when ``|X|`` passes ``blowup_bound`` (m), far above the unit circle it should follow.
    Runs are deterministic, so a run asked for again (by :func:`fewest_steps`, or for a
    second target) is taken from a cache of the rows already made. The study records no
    time: :func:`cpu_per_step` measures that.
    """
    key = (float(T), tuple(float(v) for v in np.ravel(X0)), float(kappa), float(blowup_bound))
    return [_run(method, int(n), key) for method in methods for n in counts]


_RUNS: dict[tuple, CostRow] = {}


def _run(method: str, n: int, key: tuple) -> CostRow:
    """One row of :func:`cost_study` (cached by method, ``n`` and the study's arguments)."""
    if (method, n, key) not in _RUNS:
        T, X0, kappa, blowup_bound = key
        f, jac, exact = follower(kappa)
        X0 = np.array(X0)
        kw = {"jac": jac} if method in IMPLICIT_METHODS else {}
        run = integrate(f, X0, (0.0, T), T / n, method, blowup_bound=blowup_bound, **kw)
        error = float(np.linalg.norm(run.y[-1] - exact(T, X0))) if run.stable else np.inf
        _RUNS[method, n, key] = CostRow(method, n, run.nfev, error)
    return _RUNS[method, n, key]


def cpu_per_step(steps: dict[str, int], repeats: int = 3, T: float = 2 * np.pi,
                 X0=(0.0, 0.0), kappa: float = KAPPA,
                 blowup_bound: float = 1e3) -> dict[str, float]:
    """CPU time (s) per step of each method over ``T`` with ``steps[method]`` steps.

    Each run is timed with ``time.process_time`` (the CPU time of this process, which other
    programs on the machine do not inflate), ``repeats`` times; the best run counts (the
    others include first-call and cache effects). The ratio of two methods' figures is the
    cost of one step of one in steps of the other on this machine; the figures themselves
    change from machine to machine and from run to run.
    """
    if int(repeats) != repeats or repeats < 1:
        raise ValueError(f"repeats must be a whole number >= 1, got {repeats!r}")
    f, jac, _ = follower(kappa)
    X0 = np.array(X0, dtype=float)
    out = {}
    for method, n in steps.items():
        if int(n) != n or n < 1:
            raise ValueError(f"steps[{method!r}] must be a whole number >= 1, got {n!r}")
        kw = {"jac": jac} if method in IMPLICIT_METHODS else {}
        best = np.inf
        for _ in range(int(repeats)):
            start = time.process_time()
            integrate(f, X0, (0.0, T), T / n, method, blowup_bound=blowup_bound, **kw)
            best = min(best, time.process_time() - start)
        out[method] = best / n
    return out


def cheapest(rows, method: str, target: float) -> CostRow | None:
    """The run of ``method`` with the fewest f-evaluations whose error is below ``target``."""
    good = [r for r in rows if r.method == method and r.error <= target]
    return min(good, key=lambda r: r.nfev) if good else None


def fewest_steps(method: str, target: float, lo: int, hi: int, **study) -> tuple[CostRow, CostRow]:
    """The smallest step count ``n`` in ``(lo, hi]`` whose run of ``method`` ends within
    ``target`` (m) of the exact state, by bisection on ``n``; returns the rows of ``n`` and
    of ``n - 1`` (which misses the target).

    ``lo`` must miss the target and ``hi`` meet it (checked), and the error must cross the
    target once in between: true here, where it falls steadily with ``n`` once a run is
    stable (the tests scan around each answer). ``study`` goes to :func:`cost_study`.
    """
    def run(n: int) -> CostRow:
        return cost_study([method], [n], **study)[0]

    below, above = run(hi), run(lo)
    if not (above.error > target >= below.error):
        raise ValueError(f"{method}: need error({lo}) > {target:g} >= error({hi}); got "
                         f"{above.error:.3g} and {below.error:.3g}")
    while hi - lo > 1:
        mid = (lo + hi) // 2
        row = run(mid)
        if row.error <= target:
            hi, below = mid, row
        else:
            lo, above = mid, row
    return below, above


# --- the follower explorer: κ dt against the first steps and R along the real axis -------

#: The methods the explorer compares, explicit first.
FOLLOWER_METHODS = ("forward_euler", "midpoint", "rk4", "backward_euler", "trapezoidal")
#: Range of the explorer's κ dt (dimensionless: the catch-up mode's z = -κ dt).
KAPPA_DT_RANGE = (0.05, 200.0)


@dataclass
class FollowerResult:
    """The first ``steps`` steps of each method on the stiff follower at one ``κ dt``.

    ``kappa_dt`` and ``dt = κ dt / κ`` (s); ``n`` ``(steps+1,)``, the step numbers;
    ``x[method]`` ``(steps+1,)`` (m): the x coordinate of each run, NaN after a run stopped
    (blew past ``|X| = 1000`` m); ``R[method]``: its amplification factor at
    ``z = -κ dt`` (real); ``stable[method]``: ``|R| <= 1``; ``n_exact``, ``x_exact``: the
    exact x on a fine grid, in steps; ``verdict``: one line.
    """

    kappa_dt: float
    dt: float
    n: np.ndarray
    x: dict
    R: dict
    stable: dict
    n_exact: np.ndarray
    x_exact: np.ndarray
    verdict: str


def follower_experiment(kappa_dt: float, steps: int = 40, kappa: float = KAPPA) -> FollowerResult:
    """Every method of :data:`FOLLOWER_METHODS` for ``steps`` steps of ``dt = κ dt / κ`` on
    the follower from the origin (pure; what the follower explorer draws)."""
    # a log slider's ends come back as 10**log10(end), a rounding off the end itself
    lo, hi = KAPPA_DT_RANGE
    if lo * (1 - 1e-9) <= kappa_dt <= hi * (1 + 1e-9):
        kappa_dt = min(max(kappa_dt, lo), hi)
    else:
        raise ValueError(f"kappa_dt must lie in {KAPPA_DT_RANGE}, got {kappa_dt!r}")
    f, jac, exact = follower(kappa)
    dt = kappa_dt / kappa
    n = np.arange(steps + 1)
    x, R, stable = {}, {}, {}
    for m in FOLLOWER_METHODS:
        kw = {"jac": jac} if m in IMPLICIT_METHODS else {}
        run = integrate(f, [0.0, 0.0], (0.0, steps * dt), dt, m, blowup_bound=1e3, **kw)
        x[m] = np.full(steps + 1, np.nan)
        x[m][: len(run.t)] = run.y[:, 0]
        R[m] = float(amplification_factor(m, -kappa_dt).real)
        stable[m] = abs(R[m]) <= 1.0
    n_exact = np.linspace(0.0, steps, 801)
    x_exact = exact(n_exact * dt, [0.0, 0.0])[:, 0]
    parts = [f"{_LABELS[m]} R = {R[m]:.4g}" for m in FOLLOWER_METHODS]
    blown = [_LABELS[m] for m in FOLLOWER_METHODS if not stable[m]]
    verdict = (f"κ dt = {kappa_dt:.3g} (dt = {1e3 * dt:.3g} ms): " + ", ".join(parts) + "; "
               + (f"unstable: {', '.join(blown)}" if blown else "all five stable"))
    return FollowerResult(kappa_dt, dt, n, x, R, stable, n_exact, x_exact, verdict)


_LABELS = {"forward_euler": "forward Euler", "midpoint": "midpoint", "rk4": "RK4",
           "backward_euler": "backward Euler", "trapezoidal": "trapezoid"}

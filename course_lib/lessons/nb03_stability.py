"""Notebook 03 (stability): the stability explorer's computation, one pure function.

:func:`run_experiment` runs one method with one time step on a test problem of
:mod:`~course_lib.lessons.nb03_problems` (the decay ``dx/dt = -k x`` or the oscillator
``x'' = -ω² x``), from the powers of its step matrix, and returns an
:class:`ExperimentResult`: the run, the point ``z = λ dt`` on the method's stability
region, and a verdict decided by theory (``|R(z)| <= 1``; for the symplectic methods the
open segment ``|ω dt| < 2``), plus what was observed (the step at which the run first grew
past the bound of :func:`blowup_bound`).

Imports the core (stability), the lesson's test problems and the method labels of
:mod:`course_lib.plotting`; the drawings and the widget live in
:mod:`~course_lib.lessons.nb03_explorer_view` and :mod:`~course_lib.lessons.nb03_regions`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..integrators import METHODS, NEWTONIAN_METHODS
from ..plotting import METHOD_LABELS
from ..stability import amplification_factor
from .nb03_problems import (
    PROBLEMS,
    _check_choice,
    default_t_end,
    eigenvalue,
    exact_solution,
    linear_run,
    state_size,
    step_matrix,
    theory_stable,
    unit_dt_max,
)

#: A run counts as blown up once its size exceeds this many times the largest size any
#: stable run of the same method could reach (see :func:`blowup_bound`).
GROWTH_FACTOR = 2.0
#: Longest run :func:`run_experiment` computes (steps).
MAX_STEPS = 1_000_000


@dataclass
class ExperimentResult:
    """Everything the explorer shows for one (problem, method, dt, rate).

    ``problem``, ``method``: the choices; ``dt`` (s); ``rate``: ``k`` (1/s) or ``ω``
    (rad/s); ``t_end`` (s), a whole number of steps; ``lam``: ``-k`` or ``iω`` (1/s);
    ``z = λ dt``; ``R = R(z)`` and ``abs_R = |R|`` (NaN where the method does not apply);
    ``stable``: the theory's verdict; ``applicable``: ``False`` for a symplectic method on
    the first-order decay; ``verdict``: one line for the reader; ``blowup_step``: first
    step whose size passed ``bound`` (``None`` if none did); ``dt_max`` (s): the stability
    limit for this ``λ`` (``inf``: none; ``0``: every step is unstable); ``t`` ``(n+1,)``
    and ``y`` (``(n+1,)`` for the decay, ``(n+1, 2)`` with columns ``x, v`` for the
    oscillator): the run, finite up to overflow and NaN after; ``t_exact``, ``y_exact``:
    the exact solution on a fine grid, same layout.
    """

    problem: str
    method: str
    dt: float
    rate: float
    t_end: float
    lam: complex
    z: complex
    R: complex
    abs_R: float
    stable: bool
    applicable: bool
    verdict: str
    blowup_step: int | None
    dt_max: float
    t: np.ndarray
    y: np.ndarray
    t_exact: np.ndarray
    y_exact: np.ndarray
    bound: float

    @property
    def x(self) -> np.ndarray:
        """Numerical position ``x`` at :attr:`t`."""
        return self.y if self.y.ndim == 1 else self.y[:, 0]

    @property
    def x_exact(self) -> np.ndarray:
        """Exact position at :attr:`t_exact`."""
        return self.y_exact if self.y_exact.ndim == 1 else self.y_exact[:, 0]

    @property
    def size(self) -> np.ndarray:
        """Size of every state of the run (see :func:`state_size`), shape ``(n+1,)``."""
        return state_size(self.problem, self.rate, self.y)

    @property
    def last_finite(self) -> int:
        """Index of the last finite state of the run."""
        finite = np.isfinite(self.size)
        return int(finite.size - 1 - np.argmax(finite[::-1]))

    @property
    def blowup_time(self) -> float | None:
        return None if self.blowup_step is None else float(self.t[self.blowup_step])


def blowup_bound(problem: str, method: str, rate: float, dt: float) -> float:
    """Size (see :func:`state_size`) past which a run from size 1 counts as blown up.

    A stable linear step need not shrink every state: it can stretch one by up to ``κ``,
    the condition number of its eigenvector basis (in the scaled variables), before turning
    it back. ``κ = 1`` for the decay and for the Runge-Kutta and implicit methods on the
    oscillator; for the symplectic methods ``κ`` grows as ``ω dt`` approaches 2. We flag a
    blow-up at ``GROWTH_FACTOR * κ``, so a stable run is never flagged, and an unstable
    one (``|R| > 1``) is flagged after about ``log(2 κ) / log|R|`` steps.
    """
    if problem == "decay" or method not in NEWTONIAN_METHODS:
        return GROWTH_FACTOR
    scale = np.array([1.0, rate])
    M = step_matrix(method, problem, rate, dt) * scale[None, :] / scale[:, None]
    with np.errstate(all="ignore"):
        kappa = np.linalg.cond(np.linalg.eig(M)[1])
    if not np.isfinite(kappa) or kappa > 1e8:  # ω dt = 2: a Jordan block, linear growth
        kappa = 1e8
    return GROWTH_FACTOR * float(kappa)


def _fmt_factor(value: float) -> str:
    """``|R|`` for a verdict: near 1, show the distance from 1, which is what matters."""
    if not np.isfinite(value):
        return "∞"
    gap = value - 1.0
    if abs(gap) <= 1e-12:  # round-off: exactly on the boundary
        return "1"
    if abs(gap) < 5e-4:
        return f"1 {'+' if gap > 0 else '-'} {abs(gap):.2g}"
    return f"{value:.4g}"


def limit_text(method: str, dt_max: float) -> str:
    """The stability limit in words: ``"stable for dt ≤ 2 s"`` (``<`` for symplectic)."""
    if np.isinf(dt_max):
        return "stable for every dt"
    if dt_max == 0.0:
        return "unstable for every dt"
    return f"stable for dt {'<' if method in NEWTONIAN_METHODS else '≤'} {dt_max:.4g} s"


def run_experiment(
    problem: str = "decay",
    method: str = "forward_euler",
    dt: float = 0.5,
    rate: float = 1.0,
    t_end: float | None = None,
) -> ExperimentResult:
    """Run ``method`` with step ``dt`` on a test problem and judge its stability.

    Parameters
    ----------
    problem : {"decay", "oscillator"}
        See the module docstring.
    method : str
        One of :data:`course_lib.METHODS`.
    dt : float
        Time step (s), > 0.
    rate : float
        ``k`` (1/s) for the decay, ``ω`` (rad/s) for the oscillator, > 0.
    t_end : float, optional
        Length of the run (s); default :func:`default_t_end`. Rounded to a whole number of
        steps (at least one, at most :data:`MAX_STEPS`).

    Returns
    -------
    ExperimentResult

    Examples
    --------
    >>> run_experiment("decay", "forward_euler", dt=1.9).stable
    True
    >>> r = run_experiment("decay", "forward_euler", dt=2.1)
    >>> r.stable, r.blowup_step
    (False, 8)
    """
    _check_choice("problem", problem, PROBLEMS)
    _check_choice("method", method, METHODS)
    dt, rate = float(dt), float(rate)
    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be a finite number > 0, got {dt!r}")
    if not (np.isfinite(rate) and rate > 0):
        raise ValueError(f"rate must be a finite number > 0, got {rate!r}")
    t_end = default_t_end(problem, rate) if t_end is None else float(t_end)
    n = max(1, round(t_end / dt))
    if n > MAX_STEPS:
        raise ValueError(f"t_end / dt = {n} steps; at most {MAX_STEPS} (shorten t_end)")
    t_end = n * dt
    lam = eigenvalue(problem, rate)
    z = lam * dt
    t_exact = np.linspace(0.0, t_end, 400)
    y_exact = exact_solution(problem, rate, t_exact)
    y0 = np.atleast_1d(exact_solution(problem, rate, 0.0))
    t = dt * np.arange(n + 1)

    if problem == "decay" and method in NEWTONIAN_METHODS:
        nan = float("nan")
        verdict = (f"does not apply: {METHOD_LABELS[method]} needs a second-order state "
                   "(x, v); the decay is first order. Choose the oscillator.")
        return ExperimentResult(
            problem, method, dt, rate, t_end, lam, z, complex(nan, nan), nan, False, False,
            verdict, None, nan, t[:1], y0, t_exact, y_exact, nan,
        )

    R = complex(amplification_factor(method, z))
    abs_R = float(abs(R))
    stable = theory_stable(method, z)
    dt_max = unit_dt_max(method, problem) / rate
    bound = blowup_bound(problem, method, rate, dt)
    y = linear_run(step_matrix(method, problem, rate, dt), y0, n)
    if problem == "decay":
        y = y[:, 0]
    size = state_size(problem, rate, y)
    past = ~(size <= bound)  # NaN (after an overflow) counts as past
    blowup_step = int(np.argmax(past)) if past.any() else None

    if stable:
        verdict = f"stable: |R(z)| = {_fmt_factor(abs_R)} ≤ 1"
    elif method in NEWTONIAN_METHODS and abs(z) == 2.0:
        verdict = ("unstable: ω dt = 2 exactly, a double eigenvalue -1 with one eigenvector "
                   "(a Jordan block): runs from most starts grow linearly")
    else:
        verdict = f"unstable: |R(z)| = {_fmt_factor(abs_R)} > 1"
        if blowup_step is not None:
            verdict += f"; blew up at step {blowup_step} (t = {t[blowup_step]:.3g} s)"
        else:
            verdict += f"; slow growth, not past the bound by t = {t_end:.3g} s"
    verdict += f"; {limit_text(method, dt_max)}"
    return ExperimentResult(
        problem, method, dt, rate, t_end, lam, z, R, abs_R, stable, True, verdict,
        blowup_step, dt_max, t, y, t_exact, y_exact, bound,
    )

"""The stability explorer: one method, one test problem, one time step, and the verdict.

Two linear test problems, each with a single rate:

``"decay"``
    ``dx/dt = -k x``, ``x(0) = 1``; exact ``x = e^{-k t}``; eigenvalue ``λ = -k``.
``"oscillator"``
    ``x'' = -ω² x`` as the first-order system ``y = (x, v)``
    (:func:`course_lib.systems.oscillator`), ``y(0) = (1, 0)``; exact ``x = cos ω t``,
    ``v = -ω sin ω t``; eigenvalues ``λ = ±iω``.

:func:`run_experiment` is the pure computation (tested directly); it integrates the
problem with :func:`course_lib.integrate`, places ``z = λ dt`` on the method's stability
region (:func:`course_lib.amplification_factor`) and writes a verdict. The verdict is
decided by theory, ``|R(z)| <= 1``; the run adds what was observed: the step at which the
state first grew past a bound (see :func:`blowup_bound`). :func:`draw_experiment` plots a
result, and :func:`stability_explorer` wires both to ipywidgets controls
(:class:`course_lib.widgets.ExplorerView`).

The symplectic methods (``symplectic_euler``, ``velocity_verlet``) need a second-order
state ``(x, v)``: they apply to the oscillator only, and on the decay problem the result
says so (``applicable=False``) instead of raising.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..integrators import IMPLICIT_METHODS, METHODS, NEWTONIAN_METHODS, integrate, step
from ..plotting import METHOD_LABELS
from ..stability import amplification_factor, is_stable, max_stable_dt
from ..systems import oscillator

#: The test problems, with readable names.
PROBLEMS: dict[str, str] = {
    "decay": "decay  dx/dt = -k x",
    "oscillator": "oscillator  x'' = -ω² x",
}
#: Search limit of ``|λ| dt`` for the stability limit; beyond it we report "no limit".
_UNLIMITED = 1e3
#: A run counts as blown up once its size exceeds this many times the largest size any
#: stable run of the same method could reach (see :func:`blowup_bound`).
GROWTH_FACTOR = 2.0
#: An unstable run is drawn on until its size passes this multiple of the blow-up bound,
#: so the student sees it leave the axes rather than stop at the marker.
DISPLAY_FACTOR = 20.0


@dataclass
class ExperimentResult:
    """Everything the explorer shows for one (problem, method, dt, rate).

    Attributes
    ----------
    problem, method : str
        The choices.
    dt : float
        Time step (s).
    rate : float
        ``k`` (1/s) for the decay, ``ω`` (rad/s) for the oscillator.
    t_end : float
        Length of the run (s).
    lam : complex
        The eigenvalue that sets stability: ``-k`` or ``iω`` (1/s).
    z : complex
        ``λ dt`` (dimensionless).
    R : complex
        The amplification factor ``R(z)`` (NaN when the method does not apply).
    abs_R : float
        ``|R(z)|``: the factor by which the state's size changes each step.
    stable : bool
        The theory's verdict, ``|R(z)| <= 1`` (``False`` when the method does not apply).
    applicable : bool
        ``False`` for a symplectic method on the (first-order) decay problem.
    verdict : str
        One line for the reader, e.g. ``"unstable: |R(z)| = 1.1 > 1; blew up at step 8
        (t = 16.8 s)"``.
    blowup_step : int or None
        Observed: first step whose size exceeded :attr:`bound` (``None`` if none did).
    dt_max : float
        Largest stable step for this λ (:func:`course_lib.max_stable_dt`), ``inf`` when
        there is none within ``|λ| dt <= 1000`` and ``0.0`` when every step is unstable.
    t, y : ndarray
        The numerical run: times ``(n+1,)`` and states, ``(n+1,)`` for the decay and
        ``(n+1, 2)`` (columns ``x``, ``v``) for the oscillator; NaN after a blow-up.
    t_exact, y_exact : ndarray
        The exact solution on a fine grid over the same span, same layout as ``y``.
    bound : float
        Size (in the problem's natural norm, see :func:`state_size`) past which the run
        counts as blown up.
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
    def blowup_time(self) -> float | None:
        return None if self.blowup_step is None else float(self.t[self.blowup_step])


def _check_choice(name: str, value: str, options) -> str:
    if value not in options:
        raise ValueError(f"{name} must be one of {list(options)}, got {value!r}")
    return value


def eigenvalue(problem: str, rate: float) -> complex:
    """``λ`` of the test problem: ``-k`` for the decay, ``iω`` for the oscillator."""
    _check_choice("problem", problem, PROBLEMS)
    return complex(-rate) if problem == "decay" else complex(0.0, rate)


def default_t_end(problem: str, rate: float) -> float:
    """Span shown by the explorer: 20 time constants ``1/k``, or 4 periods ``2π/ω``."""
    _check_choice("problem", problem, PROBLEMS)
    return 20.0 / rate if problem == "decay" else 8.0 * np.pi / rate


def exact_solution(problem: str, rate: float, t) -> np.ndarray:
    """Exact state at times ``t``: ``e^{-k t}``, or ``(cos ω t, -ω sin ω t)`` as columns."""
    _check_choice("problem", problem, PROBLEMS)
    t = np.asarray(t, dtype=float)
    if problem == "decay":
        return np.exp(-rate * t)
    return np.stack((np.cos(rate * t), -rate * np.sin(rate * t)), axis=-1)


def state_size(problem: str, rate: float, y) -> np.ndarray:
    """Size of states ``y`` in the problem's natural norm: ``|x|``, or ``sqrt(x² + (v/ω)²)``.

    In the oscillator's scaled variables ``(x, v/ω)`` the exact motion is a circle of
    radius 1, and the Runge-Kutta and implicit steps act as normal matrices, so a stable run
    of those methods never grows in this norm.
    """
    y = np.asarray(y)
    if problem == "decay":
        return np.abs(y)
    return np.hypot(y[..., 0], y[..., 1] / rate)


@functools.lru_cache(maxsize=64)
def _unit_dt_max(method: str, problem: str) -> float:
    """Stability limit of ``|λ| dt`` (dimensionless) for the problem's direction of λ."""
    lam_hat = eigenvalue(problem, 1.0)
    limit = max_stable_dt(method, lam_hat, dt_max=_UNLIMITED)
    return np.inf if limit >= _UNLIMITED else limit


def _step_matrix(method: str, problem: str, rate: float, dt: float) -> np.ndarray:
    """One step of a linear problem as a matrix in the scaled variables ``(x, v/ω)``."""
    f, jac = _rhs(problem, rate)
    n = 1 if problem == "decay" else 2
    scale = np.ones(n) if problem == "decay" else np.array([1.0, rate])
    cols = []
    for j in range(n):
        e = np.zeros(n)
        e[j] = 1.0
        kw = {"jac": jac} if method in IMPLICIT_METHODS else {}
        cols.append(step(method, f, 0.0, e * scale, dt, **kw) / scale)
    return np.column_stack(cols)


def blowup_bound(problem: str, method: str, rate: float, dt: float) -> float:
    """Size (see :func:`state_size`) past which a run from size 1 counts as blown up.

    A stable linear step ``y <- M y`` need not shrink every state: it can stretch one by up
    to ``κ``, the condition number of ``M``'s eigenvector basis, before turning it back.
    ``κ = 1`` for the decay and for the Runge-Kutta and implicit methods on the
    oscillator; for the symplectic methods ``κ`` grows as ``ω dt`` approaches 2. We flag a
    blow-up at ``GROWTH_FACTOR * κ``, so a stable run is never flagged, and an unstable
    one (``|R| > 1``) is flagged after about ``log(2 κ) / log|R|`` steps.
    """
    if problem == "decay" or method not in NEWTONIAN_METHODS:
        return GROWTH_FACTOR
    M = _step_matrix(method, problem, rate, dt)
    with np.errstate(all="ignore"):
        _, vecs = np.linalg.eig(M)
        kappa = np.linalg.cond(vecs)
    if not np.isfinite(kappa) or kappa > 1e8:  # ω dt = 2: a Jordan block, linear growth
        kappa = 1e8
    return GROWTH_FACTOR * float(kappa)


def _rhs(problem: str, rate: float):
    if problem == "decay":
        jac_matrix = np.array([[-rate]])
        return (lambda t, x: -rate * x), (lambda t, x: jac_matrix)
    jac_matrix = np.array([[0.0, 1.0], [-(rate**2), 0.0]])
    return oscillator(rate), (lambda t, y: jac_matrix)


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


def _fmt_dt_max(dt_max: float) -> str:
    if np.isinf(dt_max):
        return "none (stable for every dt)"
    if dt_max == 0.0:
        return "0 (unstable for every dt)"
    return f"{dt_max:.4g} s"


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
        Length of the run (s); default :func:`default_t_end`. At least one step is taken.

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
    t_end = n * dt  # a whole number of steps
    lam = eigenvalue(problem, rate)
    z = lam * dt
    t_exact = np.linspace(0.0, t_end, 400)
    y_exact = exact_solution(problem, rate, t_exact)
    y0 = exact_solution(problem, rate, 0.0)

    if problem == "decay" and method in NEWTONIAN_METHODS:
        nan = float("nan")
        verdict = (
            f"does not apply: {METHOD_LABELS[method]} needs a second-order state (x, v); "
            "the decay is first order. Choose the oscillator."
        )
        return ExperimentResult(
            problem, method, dt, rate, t_end, lam, z, complex(nan, nan), nan, False, False,
            verdict, None, nan, np.array([0.0]), np.atleast_1d(y0), t_exact, y_exact, nan,
        )

    R = complex(amplification_factor(method, z))
    abs_R = float(abs(R))
    stable = bool(is_stable(method, z))
    dt_max = _unit_dt_max(method, problem) / rate
    bound = blowup_bound(problem, method, rate, dt)

    f, jac = _rhs(problem, rate)
    traj = integrate(
        f, np.atleast_1d(y0), (0.0, t_end), dt, method,
        jac=jac if method in IMPLICIT_METHODS else None,
        blowup_bound=1e6 * max(1.0, rate) * bound,
    )
    y = traj.y[:, 0] if problem == "decay" else traj.y
    # Observed blow-up: the first state whose size passed the bound (integrate's own,
    # much larger bound only guards against overflow).
    with np.errstate(invalid="ignore"):
        past = state_size(problem, rate, y) > bound
    past |= ~np.all(np.isfinite(np.atleast_2d(y.T)), axis=0)
    past[0] = False
    blowup_step = int(np.argmax(past)) if past.any() else None
    if blowup_step is not None:
        with np.errstate(invalid="ignore"):
            far = state_size(problem, rate, y) > DISPLAY_FACTOR * bound
        far[: blowup_step + 1] = False
        if far.any():
            y = y.copy()
            y[int(np.argmax(far)) + 1:] = np.nan

    if stable:
        verdict = f"stable: |R(z)| = {_fmt_factor(abs_R)} ≤ 1"
        if blowup_step is not None:  # only possible at the ω dt = 2 edge (linear growth)
            verdict += f", yet the run passed the bound at step {blowup_step}"
    else:
        verdict = f"unstable: |R(z)| = {_fmt_factor(abs_R)} > 1"
        if blowup_step is not None:
            verdict += f"; blew up at step {blowup_step} (t = {traj.t[blowup_step]:.3g} s)"
        else:
            verdict += f"; slow growth, not past the bound by t = {t_end:.3g} s"
    verdict += f"; dt_max = {_fmt_dt_max(dt_max)}"
    return ExperimentResult(
        problem, method, dt, rate, t_end, lam, z, R, abs_R, stable, True, verdict,
        blowup_step, dt_max, traj.t, y, t_exact, y_exact, bound,
    )


# --- drawing ------------------------------------------------------------------------------

#: Window of the complex plane shown beside a run (Re z, Im z limits).
REGION_WINDOW = (-5.0, 3.0, -3.5, 3.5)


@functools.lru_cache(maxsize=16)
def region_grid(method: str, window: tuple = REGION_WINDOW, n: int = 241):
    """``(re, im, |R|)`` of ``method`` on an ``n × n`` grid of the complex plane (cached)."""
    re = np.linspace(window[0], window[1], n)
    im = np.linspace(window[2], window[3], n)
    Z = re[None, :] + 1j * im[:, None]
    absR = np.abs(amplification_factor(method, Z))
    absR.setflags(write=False)
    return re, im, absR

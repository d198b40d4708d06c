"""Notebook 03 (stability): the two linear test problems and their step matrices.

``"decay"``
    ``dx/dt = -k x``, ``x(0) = 1``; exact ``x = e^{-k t}``; eigenvalue ``λ = -k``.
``"oscillator"``
    ``x'' = -ω² x`` as the first-order system ``y = (x, v)``
    (:func:`course_lib.systems.oscillator`), ``y(0) = (1, 0)``; exact ``x = cos ω t``,
    ``v = -ω sin ω t``; eigenvalues ``λ = ±iω``.

Both are linear, so one step of any method is a matrix, ``y_{n+1} = M y_n``.
:func:`step_matrix` builds ``M`` by stepping the basis vectors with the course's own
steppers (:func:`course_lib.step`), and :func:`linear_run` computes a whole run,
``y_n = M^n y_0``, with a handful of vectorised products instead of a loop over steps.
:func:`theory_stable` is the verdict of linear stability theory.

Imports the core only (integrators, stability, systems).
"""

from __future__ import annotations

import functools

import numpy as np

from ..integrators import IMPLICIT_METHODS, METHODS, step
from ..stability import is_stable, max_stable_dt
from ..systems import oscillator

#: The test problems, with readable names.
PROBLEMS: dict[str, str] = {
    "decay": "decay  dx/dt = -k x",
    "oscillator": "oscillator  x'' = -ω² x",
}
#: Search limit of ``|λ| dt`` for the stability limit; beyond it we report "no limit".
_UNLIMITED = 1e3

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
    with np.errstate(over="ignore", invalid="ignore"):
        if problem == "decay":
            return np.abs(y)
        return np.hypot(y[..., 0], y[..., 1] / rate)


@functools.lru_cache(maxsize=64)
def unit_dt_max(method: str, problem: str) -> float:
    """Stability limit of ``|λ| dt`` (dimensionless) for the problem's direction of λ."""
    limit = max_stable_dt(method, eigenvalue(problem, 1.0), dt_max=_UNLIMITED)
    return np.inf if limit >= _UNLIMITED else limit


def _rhs(problem: str, rate: float):
    if problem == "decay":
        jac_matrix = np.array([[-rate]])
        return (lambda t, x: -rate * x), (lambda t, x: jac_matrix)
    jac_matrix = np.array([[0.0, 1.0], [-(rate**2), 0.0]])
    return oscillator(rate), (lambda t, y: jac_matrix)


@functools.lru_cache(maxsize=256)
def step_matrix(method: str, problem: str, rate: float, dt: float) -> np.ndarray:
    """One step of ``method`` on a test problem as a matrix: ``y_{n+1} = M y_n``.

    Column ``j`` is one step (:func:`course_lib.step`) from the ``j``-th basis vector, so
    ``M`` is exactly what the method does to this linear problem. Shape ``(1, 1)`` for the
    decay, ``(2, 2)`` acting on ``(x, v)`` for the oscillator. Cached and read-only.
    """
    _check_choice("method", method, METHODS)
    f, jac = _rhs(problem, rate)
    n = 1 if problem == "decay" else 2
    kw = {"jac": jac} if method in IMPLICIT_METHODS else {}
    M = np.column_stack([step(method, f, 0.0, e, dt, **kw) for e in np.eye(n)])
    M.setflags(write=False)
    return M


def linear_run(M, y0, n: int) -> np.ndarray:
    """States ``y_k = M^k y0`` for ``k = 0..n``, shape ``(n+1, len(y0))``.

    Built by doubling: the block of the first ``m`` states times ``M^m`` gives the next
    ``m``, so a run of ``n`` steps costs about ``log2(n)`` small matrix products.
    Overflow gives ``inf``; every state after the first non-finite one is NaN.
    """
    M = np.asarray(M, dtype=float)
    y = np.empty((n + 1, M.shape[0]))
    y[0] = np.asarray(y0, dtype=float)
    done, power = 1, M.copy()  # y[:done] are known, power = M^done
    with np.errstate(over="ignore", invalid="ignore"):
        while done <= n:
            take = min(done, n + 1 - done)
            y[done:done + take] = y[:take] @ power.T
            done += take
            power = power @ power
    bad = ~np.all(np.isfinite(y), axis=1)
    if bad.any():
        y[int(np.argmax(bad)) + 1:] = np.nan
    return y


def theory_stable(method: str, z: complex) -> bool:
    """Is ``z`` in the method's stable set (:func:`course_lib.is_stable`)? ``|R(z)| <= 1``,
    except for the symplectic methods at ``ω dt = 2``: there their step matrix is a Jordan
    block with the double eigenvalue -1, and runs grow linearly (stable iff ``ω dt < 2``)."""
    return bool(is_stable(method, z))

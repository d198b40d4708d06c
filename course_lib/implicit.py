"""Newton's method for the equations that implicit integrators must solve each step.

An implicit step asks for the end state ``Y`` of

    Y = c + a * dt * f(t1, Y)

(backward Euler: ``c = y``, ``a = 1``; trapezoid: ``c = y + dt/2 f(t, y)``, ``a = 1/2``).
We solve ``G(Y) = Y - c - a dt f(t1, Y) = 0`` by Newton's method with the Jacobian
``I - a dt J``, where ``J = df/dy`` comes from the caller's ``jac(t, y)`` when given and
from forward finite differences otherwise. On a linear ``f`` an exact Jacobian converges
in one iteration, and the finite-difference one in two or three, to round-off.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

Jacobian = Callable[[float, np.ndarray], np.ndarray]


class ConvergenceError(RuntimeError):
    """Newton's method did not converge within the allowed iterations."""


def finite_difference_jacobian(f: Callable, t: float, y: np.ndarray, fy: np.ndarray | None = None):
    """Forward-difference Jacobian of ``f(t, y)`` with respect to ``y``.

    Parameters
    ----------
    f : callable
        ``f(t, y) -> dy/dt`` with ``y`` of any shape.
    t : float
        Time at which to differentiate.
    y : ndarray
        State, any shape; it is flattened, so the result is ``(y.size, y.size)``.
    fy : ndarray, optional
        ``f(t, y)`` if already known (saves one evaluation).

    Returns
    -------
    ndarray, shape (y.size, y.size)
        ``J[i, j] = d f_i / d y_j``.
    """
    y_flat = y.ravel()
    if fy is None:
        fy = np.asarray(f(t, y))
    fy_flat = fy.ravel()
    n = y_flat.size
    jac = np.empty((n, n), dtype=np.result_type(fy_flat, y_flat, float))
    # sqrt(machine epsilon) balances truncation against cancellation for a first difference.
    steps = np.sqrt(np.finfo(float).eps) * np.maximum(1.0, np.abs(y_flat))
    for j in range(n):
        y_pert = y_flat.copy()
        y_pert[j] += steps[j]
        jac[:, j] = (np.asarray(f(t, y_pert.reshape(y.shape))).ravel() - fy_flat) / steps[j]
    return jac


def solve_implicit(
    f: Callable,
    t1: float,
    c: np.ndarray,
    a_dt: float,
    guess: np.ndarray,
    jac: Jacobian | None = None,
    *,
    rtol: float = 1e-13,
    max_iter: int = 50,
) -> np.ndarray:
    """Solve ``Y = c + a_dt * f(t1, Y)`` for ``Y`` by Newton's method.

    Parameters
    ----------
    f : callable
        Right-hand side ``f(t, y)``.
    t1 : float
        Time of the unknown state (end of the step).
    c : ndarray
        Known part of the equation, same shape as the state.
    a_dt : float
        ``a * dt``: the weight of the unknown derivative (``dt`` for backward Euler).
    guess : ndarray
        Starting iterate, e.g. a forward Euler predictor.
    jac : callable, optional
        ``jac(t, y)``: the Jacobian ``df/dy`` as a ``(y.size, y.size)`` array. Finite
        differences are used when it is omitted.
    rtol : float
        Stop when the Newton update is below ``rtol * max(1, |Y|)`` (max norm).
    max_iter : int
        Give up after this many iterations.

    Returns
    -------
    ndarray
        The end state ``Y``, same shape as ``c``.

    Raises
    ------
    ConvergenceError
        If Newton's method does not converge (or the Jacobian is singular).
    """
    shape = c.shape
    y = np.array(guess, dtype=np.result_type(guess, c, float), copy=True)
    eye = np.eye(y.size)
    prev_norm = np.inf
    for _ in range(max_iter):
        fy = np.asarray(f(t1, y))
        residual = (y - c - a_dt * fy).ravel()
        if jac is None:
            jmat = finite_difference_jacobian(f, t1, y, fy)
        else:
            jmat = np.asarray(jac(t1, y))
            if jmat.shape != (y.size, y.size):
                raise ValueError(
                    f"jac must return shape ({y.size}, {y.size}) for a state of shape "
                    f"{shape}, got {jmat.shape}"
                )
        try:
            delta = np.linalg.solve(eye - a_dt * jmat, residual)
        except np.linalg.LinAlgError:
            raise ConvergenceError(
                f"implicit step at t = {t1:g}: the Newton matrix I - {a_dt:g} J is singular"
            ) from None
        y = y - delta.reshape(shape)
        norm = np.max(np.abs(delta))
        scale = max(1.0, float(np.max(np.abs(y))))
        if not np.isfinite(norm):
            raise ConvergenceError(f"implicit step at t = {t1:g}: Newton iterates diverged")
        # Converged, or stalled at round-off (the update stopped shrinking).
        if norm <= rtol * scale or (norm <= 1e-9 * scale and norm >= prev_norm):
            return y
        prev_norm = norm
    raise ConvergenceError(
        f"implicit step at t = {t1:g}: Newton's method did not converge in {max_iter} "
        "iterations; try a smaller dt or pass an exact jac"
    )

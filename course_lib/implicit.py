"""Newton's method for the equation that an implicit integrator solves each step.

An implicit step asks for the end state ``Y`` of

    Y = c + a dt f(t1, Y)

(backward Euler: ``c = y``, ``a = 1``; trapezoid: ``c = y + dt/2 f(t, y)``, ``a = 1/2``).
:class:`NewtonSolver` solves ``G(Y) = Y - c - a dt f(t1, Y) = 0`` with the matrix
``M = I - a dt J``, where ``J = df/dy`` is the caller's ``jac`` (a constant matrix, or a
function ``jac(t, y)``; dense or ``scipy.sparse``) or, without one, a forward
finite-difference Jacobian. Each step factorizes ``M`` once (LU, or ``splu`` for a sparse
``J``) and reuses it for every Newton iteration; a constant ``jac`` is factorized once per
step size for the whole run. The Jacobian is re-evaluated only when the iteration slows.
A sparse ``J`` of a Newtonian state, ``[[0, I], [A, B]]`` for ``y = (x, v)``, is solved
through the half-size velocity matrix ``I - h B - h² A`` (Baraff & Witkin, 1998).

Everything is relative to the size of the state, so the solve does not depend on units:
the iteration stops when the update is below ``rtol`` times ``max(|Y|, |c|)`` (max norm),
and the finite-difference steps are ``sqrt(eps)`` times that scale (or ``|y_j|`` if larger).

Imports: numpy and scipy only (core layer).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

#: ``jac(t, y) -> J``, or ``J`` itself: a ``(n, n)`` ndarray or scipy.sparse matrix.
Jacobian = Callable[[float, np.ndarray], Any] | np.ndarray | Any

_SQRT_EPS = float(np.sqrt(np.finfo(float).eps))


class ConvergenceError(RuntimeError):
    """Newton's method did not converge (``nonfinite`` when ``f`` or an iterate was NaN/inf)."""

    def __init__(self, message: str, nonfinite: bool = False):
        super().__init__(message)
        self.nonfinite = nonfinite


def _max_abs(a: np.ndarray) -> float:
    # The ufunc's own reduce skips numpy's Python wrappers around np.max (a third of the
    # cost for a 2-vector); NaN still propagates.
    return float(np.maximum.reduce(np.abs(a), axis=None)) if a.size else 0.0


def _dense_lu(M: np.ndarray, a_dt: float, t1: float) -> Callable[[np.ndarray], np.ndarray]:
    """``r -> M^{-1} r`` from LAPACK ``getrf``/``getrs`` called directly.

    The same routines as ``scipy.linalg.lu_factor``/``lu_solve`` (so the same bits), without
    their per-call wrappers, which dominate the cost of a small system's implicit step.
    """
    getrf, getrs = sla.get_lapack_funcs(("getrf", "getrs"), (M,))
    lu, piv, info = getrf(M, overwrite_a=True)
    if info < 0:  # pragma: no cover - LAPACK argument error, cannot happen for a square M
        raise ValueError(f"illegal value in argument {-info} of LAPACK getrf")
    if np.any(np.diag(lu) == 0):
        raise ConvergenceError(f"implicit step at t = {t1:g}: the Newton matrix "
                               f"I - {a_dt:g} J is singular")

    def solve(r: np.ndarray) -> np.ndarray:
        if r.dtype != lu.dtype:
            return sla.lu_solve((lu, piv), r, check_finite=False)
        x, info = getrs(lu, piv, r)
        if info:  # pragma: no cover - LAPACK argument error
            raise ValueError(f"illegal value in argument {-info} of LAPACK getrs")
        return x

    return solve


def finite_difference_jacobian(f: Callable, t: float, y: np.ndarray, fy: np.ndarray | None = None,
                               scale: float | None = None) -> np.ndarray:
    """Forward-difference Jacobian of ``f(t, y)`` with respect to ``y``.

    Parameters
    ----------
    f : callable
        ``f(t, y) -> dy/dt`` with ``y`` of any shape. It may return the same buffer every
        call and may modify its argument: ``fy`` is copied and each call gets a fresh state.
    t : float
        Time (s) at which to differentiate.
    y : ndarray
        State, any shape; it is flattened, so the result is ``(y.size, y.size)``.
    fy : ndarray, optional
        ``f(t, y)`` if already known (saves one evaluation).
    scale : float, optional
        Typical size of the state (same units as ``y``); default ``max|y|`` (1 if ``y = 0``).
        Column ``j`` is perturbed by ``sqrt(eps) max(|y_j|, scale)``.

    Returns
    -------
    ndarray, shape (y.size, y.size)
        ``J[i, j] = d f_i / d y_j`` (units of ``f`` per unit of ``y``).
    """
    y_flat = np.asarray(y).ravel()
    f0 = np.array(f(t, y.copy()) if fy is None else fy, copy=True).ravel()
    if scale is None or not scale > 0:
        scale = _max_abs(y_flat) or 1.0
    n = y_flat.size
    jac = np.empty((n, n), dtype=np.result_type(f0, y_flat, float))
    # sqrt(eps) relative steps balance truncation against cancellation; taking the step as
    # the difference of two floats makes it exact, so the quotient loses nothing more.
    bumped = y_flat + _SQRT_EPS * np.maximum(np.abs(y_flat), scale)
    steps = bumped - y_flat
    for j in range(n):
        y_pert = y_flat.copy()
        y_pert[j] = bumped[j]
        jac[:, j] = (np.asarray(f(t, y_pert.reshape(y.shape))).ravel() - f0) / steps[j]
    return jac


def _newtonian_blocks(J):
    """``(A, B)`` if the sparse ``J`` is ``[[0, I], [A, B]]`` (a Newtonian ``f = (v, a)``)."""
    n = J.shape[0]
    if n % 2:
        return None
    half = n // 2
    top = sp.csr_matrix(J[:half])
    top.sum_duplicates()
    top.eliminate_zeros()
    if (top.nnz != half or not np.array_equal(top.indices, np.arange(half, n))
            or not np.all(top.data == 1)):
        return None
    bottom = sp.csr_matrix(J[half:])
    return bottom[:, :half].tocsc(), bottom[:, half:].tocsc()


def _sparse_lu(M, a_dt: float, t1: float) -> Callable[[np.ndarray], np.ndarray]:
    M = sp.csc_matrix(M)
    if not np.all(np.isfinite(M.data)):
        raise ConvergenceError(f"implicit step at t = {t1:g}: jac has non-finite entries",
                               nonfinite=True)
    try:
        return spla.splu(M).solve
    except RuntimeError:  # "Factor is exactly singular"
        raise ConvergenceError(f"implicit step at t = {t1:g}: the Newton matrix "
                               f"I - {a_dt:g} J is singular") from None


class NewtonSolver:
    """Solves ``Y = c + a_dt f(t1, Y)`` by Newton's method, reusing its Jacobian.

    Parameters
    ----------
    jac : callable, ndarray or scipy.sparse matrix, optional
        ``df/dy`` as a ``(n, n)`` matrix with ``n = y.size`` (units of ``f`` per unit of
        ``y``): a constant matrix, or ``jac(t, y)`` returning one (dense or sparse). Finite
        differences are used when it is omitted. A sparse ``J`` gives a sparse solve.
    rtol : float
        Stop when the Newton update is below ``rtol * max(|Y|, |c|)`` (max norm).
    max_iter : int
        Give up after this many iterations (:class:`ConvergenceError`).
    """

    def __init__(self, jac: Jacobian | None = None, *, rtol: float = 1e-13, max_iter: int = 50):
        self._const = None
        self._func = None
        if jac is not None:
            if callable(jac):
                self._func = jac
            elif sp.issparse(jac) or isinstance(jac, np.ndarray | list | tuple):
                self._const = jac if sp.issparse(jac) else np.asarray(jac)
            else:
                raise TypeError("jac must be a (n, n) array, a scipy.sparse matrix, or callable "
                                f"as jac(t, y) returning one; got {type(jac).__name__}")
        self.rtol = float(rtol)
        self.max_iter = int(max_iter)
        self._cache: dict[float, Callable] = {}   # factorizations of a constant jac, by a_dt

    def jacobian(self, f: Callable, t: float, y: np.ndarray, fy: np.ndarray, scale: float):
        """``J = df/dy`` at ``(t, y)``: from ``jac``, or by finite differences."""
        if self._func is None and self._const is None:
            return finite_difference_jacobian(f, t, y, fy, scale)
        J = self._const if self._const is not None else self._func(t, y.copy())
        if not sp.issparse(J):
            J = np.asarray(J)
        if J.shape != (y.size, y.size):
            raise ValueError(f"jac must return shape ({y.size}, {y.size}) for a state of shape "
                             f"{y.shape}, got {J.shape}")
        return J

    @staticmethod
    def factorize(J, a_dt: float, t1: float) -> Callable[[np.ndarray], np.ndarray]:
        """A function ``r -> (I - a_dt J)^{-1} r``, from one LU factorization of the matrix."""
        n = J.shape[0]
        if sp.issparse(J):
            blocks = _newtonian_blocks(J)
            if blocks is not None:
                # J = [[0, I], [A, B]] (y = (x, v)): eliminate dx = rx + h dv and factorize
                # the half-size velocity matrix I - h B - h² A (Baraff & Witkin's system).
                A, B = blocks
                half = n // 2
                solve_v = _sparse_lu(sp.identity(half, dtype=J.dtype, format="csc")
                                     - a_dt * B - a_dt * a_dt * A, a_dt, t1)

                def solve(r: np.ndarray) -> np.ndarray:
                    dv = solve_v(r[half:] + a_dt * (A @ r[:half]))
                    return np.concatenate((r[:half] + a_dt * dv, dv))

                return solve
            return _sparse_lu(sp.identity(n, dtype=J.dtype, format="csc") - a_dt * J, a_dt, t1)
        M = np.eye(n) - a_dt * J
        if not np.isfinite(M).all():
            raise ConvergenceError(f"implicit step at t = {t1:g}: the Jacobian has non-finite "
                                   "entries", nonfinite=True)
        if n and M.dtype.char in "fdFD":
            return _dense_lu(M, a_dt, t1)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", sla.LinAlgWarning)
            lu_piv = sla.lu_factor(M, check_finite=False)
        if np.any(np.diag(lu_piv[0]) == 0):
            raise ConvergenceError(f"implicit step at t = {t1:g}: the Newton matrix "
                                   f"I - {a_dt:g} J is singular")
        return lambda r: sla.lu_solve(lu_piv, r, check_finite=False)

    def solve(self, f: Callable, t1: float, c: np.ndarray, a_dt: float,
              guess: np.ndarray) -> np.ndarray:
        """The end state ``Y`` (a new array of ``c``'s shape).

        ``f`` may reuse its output buffer and may modify its argument; ``c`` and ``guess``
        are not modified. Raises :class:`ConvergenceError` when the iteration fails.
        """
        shape = c.shape
        y = np.array(guess, dtype=np.result_type(guess, c, float), copy=True)
        c_scale = _max_abs(c)
        y_max = _max_abs(y)   # max|y| of the current iterate, kept across iterations
        solve_lin = self._cache.get(a_dt) if self._const is not None else None
        fresh, prev = False, np.inf
        for _ in range(self.max_iter):
            fy = np.asarray(f(t1, y.copy()))
            residual = (y - c - a_dt * fy).ravel()
            if not np.isfinite(residual).all():
                raise ConvergenceError(f"implicit step at t = {t1:g}: f returned non-finite "
                                       "values", nonfinite=True)
            scale = max(c_scale, y_max) or 1.0
            if solve_lin is None:
                solve_lin = self.factorize(self.jacobian(f, t1, y, fy, scale), a_dt, t1)
                fresh = True
                if self._const is not None and len(self._cache) < 8:
                    self._cache[a_dt] = solve_lin
            delta = solve_lin(residual)
            norm = _max_abs(delta)
            if norm > 0.25 * prev and not fresh and self._const is None:
                # The reused Jacobian no longer contracts well: re-evaluate it here and
                # take a full Newton step instead (the residual is already known).
                solve_lin = self.factorize(self.jacobian(f, t1, y, fy, scale), a_dt, t1)
                fresh = True
                delta = solve_lin(residual)
                norm = _max_abs(delta)
            y = y - delta.reshape(shape)
            if not np.isfinite(norm):
                raise ConvergenceError(f"implicit step at t = {t1:g}: Newton iterates diverged",
                                       nonfinite=True)
            y_max = _max_abs(y)
            scale = max(scale, y_max)
            # Converged, or stalled at round-off (the update stopped shrinking).
            if norm <= self.rtol * scale or (norm <= 1e-9 * scale and norm >= prev):
                return y
            fresh, prev = False, norm
        raise ConvergenceError(
            f"implicit step at t = {t1:g}: Newton's method did not converge in {self.max_iter} "
            "iterations; try a smaller dt or pass an exact jac"
        )


def solve_implicit(f: Callable, t1: float, c: np.ndarray, a_dt: float, guess: np.ndarray,
                   jac: Jacobian | None = None, *, rtol: float = 1e-13,
                   max_iter: int = 50) -> np.ndarray:
    """Solve ``Y = c + a_dt * f(t1, Y)`` for ``Y`` (one-off use of :class:`NewtonSolver`).

    Parameters
    ----------
    f : callable
        Right-hand side ``f(t, y)``.
    t1 : float
        Time (s) of the unknown state (end of the step).
    c : ndarray
        Known part of the equation, same shape as the state.
    a_dt : float
        ``a * dt`` (s): the weight of the unknown derivative (``dt`` for backward Euler).
    guess : ndarray
        Starting iterate, e.g. the state at the start of the step.
    jac : callable, ndarray or sparse matrix, optional
        ``df/dy``, see :class:`NewtonSolver`.
    rtol, max_iter
        See :class:`NewtonSolver`.

    Returns
    -------
    ndarray
        The end state ``Y``, same shape as ``c``.

    Raises
    ------
    ConvergenceError
        If Newton's method does not converge (or the Newton matrix is singular).
    """
    return NewtonSolver(jac, rtol=rtol, max_iter=max_iter).solve(f, t1, c, a_dt, guess)

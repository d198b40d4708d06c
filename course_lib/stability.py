"""Linear stability of the one-step methods.

Applied to the test equation ``dy/dt = λ y``, every one-step method multiplies the state
by a fixed factor each step, ``y_{k+1} = R(z) y_k`` with ``z = λ dt``. The run stays
bounded when ``|R(z)| <= 1`` and decays when ``|R(z)| < 1``; the set of such ``z`` is the
method's *stability region*. On its boundary ``|R| = 1`` a run neither grows nor decays.

For ``symplectic_euler`` and ``velocity_verlet``, which need a state ``(x, v)``, the test
problem is ``x'' = λ² x`` (whose solutions grow or decay like ``exp(±λ t)``; the undamped
oscillator has ``λ = iω``). One step multiplies ``(x, v)`` by a 2×2 matrix whose
eigenvalues ``μ`` solve ``μ² - (2 + z²) μ + 1 = 0`` for both methods; we return the
eigenvalue of larger modulus as ``R(z)``. On the imaginary axis ``|R(iθ)| = 1`` for
``θ <= 2`` and ``> 1`` beyond, but at ``θ = 2`` the two eigenvalues meet at ``-1`` and the
step matrix is a Jordan block: the run grows linearly. So the pair is stable exactly when
``ω dt < 2`` (strictly), and :func:`is_stable` says so.

:func:`max_stable_dt` finds where ``|R(λ dt)|`` first exceeds 1 along the ray of ``λ`` as
the root of a polynomial with exactly computed coefficients, to round-off at any scale.
Imports: numpy and :mod:`course_lib.steppers` (core layer).
"""

from __future__ import annotations

import cmath
import math
from fractions import Fraction
from functools import cache

import numpy as np

from . import _validate
from .steppers import METHODS


def _newtonian_R(z: np.ndarray) -> np.ndarray:
    root = z * np.sqrt(1.0 + z * z / 4.0)
    mu1 = 1.0 + z * z / 2.0 + root
    mu2 = 1.0 + z * z / 2.0 - root
    return np.where(np.abs(mu1) >= np.abs(mu2), mu1, mu2)


_R = {
    "forward_euler": lambda z: 1.0 + z,
    "midpoint": lambda z: 1.0 + z + z**2 / 2.0,
    "heun": lambda z: 1.0 + z + z**2 / 2.0,
    "rk4": lambda z: 1.0 + z + z**2 / 2.0 + z**3 / 6.0 + z**4 / 24.0,
    "backward_euler": lambda z: 1.0 / (1.0 - z),
    "trapezoidal": lambda z: (1.0 + z / 2.0) / (1.0 - z / 2.0),
    "symplectic_euler": _newtonian_R,
    "velocity_verlet": _newtonian_R,
}
assert set(_R) == set(METHODS)


def amplification_factor(method: str, z):
    """Stability function ``R(z)`` of a one-step method.

    Parameters
    ----------
    method : str
        One of :data:`course_lib.METHODS`.
    z : complex or array_like of complex
        ``λ dt`` (dimensionless). Any shape.

    Returns
    -------
    complex ndarray (a Python complex for scalar ``z``)
        ``R(z)``; a run of the test equation grows when ``|R| > 1``. At the poles of the
        implicit methods (``z = 1`` for backward Euler, ``z = 2`` for the trapezoid)
        the result is ``inf``.

    Examples
    --------
    >>> amplification_factor("forward_euler", -3.0)
    (-2+0j)
    """
    _validate.choice("method", method, _R)
    z_arr = np.asarray(z, dtype=complex)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.asarray(_R[method](z_arr), dtype=complex)
    out = np.where(np.isnan(out), np.inf, out)
    return complex(out) if out.ndim == 0 else out


def is_stable(method: str, z, tol: float = 1e-12):
    """True where a run of the test problem stays bounded, for ``z = λ dt`` of any shape.

    That is ``|R(z)| <= 1`` (within ``tol``; on ``|R| = 1`` the run neither grows nor
    decays), except for ``symplectic_euler`` and ``velocity_verlet`` at ``z² = -4``
    (``ω dt = 2``), where the step matrix is a Jordan block and the run grows linearly:
    on the imaginary axis the pair is stable exactly for ``ω dt < 2``.

    Examples
    --------
    >>> bool(is_stable("symplectic_euler", 1.99j)), bool(is_stable("symplectic_euler", 2j))
    (True, False)
    """
    tol = _validate.nonnegative("tol", tol)
    bounded = np.abs(amplification_factor(method, z)) <= 1.0 + tol
    if method in _NEWTONIAN:
        z = np.asarray(z, dtype=complex)
        bounded = bounded & (np.abs(z * z + 4.0) > 4.0 * tol)
    return bounded


# |R(u e^{iφ})|² - 1 = |N|² - |D|² for R = N/D, as a polynomial in u whose coefficients are
# polynomials in a = cos φ (Re e^{ijφ} e^{-ikφ} = T_|j-k|(a), Chebyshev). Built once from
# the exact rational coefficients of N and D, so that no cancellation is left for floats.
_ND = {
    "forward_euler": ([1, 1], [1]),
    "midpoint": ([1, 1, Fraction(1, 2)], [1]),
    "heun": ([1, 1, Fraction(1, 2)], [1]),
    "rk4": ([1, 1, Fraction(1, 2), Fraction(1, 6), Fraction(1, 24)], [1]),
    "backward_euler": ([1], [1, -1]),
    "trapezoidal": ([1, Fraction(1, 2)], [1, Fraction(-1, 2)]),
}
_NEWTONIAN = frozenset({"symplectic_euler", "velocity_verlet"})
assert set(_ND) | _NEWTONIAN == set(METHODS)


def _chebyshev(n: int) -> list[Fraction]:
    prev, cur = [Fraction(1)], [Fraction(0), Fraction(1)]
    if n == 0:
        return prev
    for _ in range(n - 1):
        nxt = [Fraction(0)] + [2 * c for c in cur]
        for i, c in enumerate(prev):
            nxt[i] -= c
        prev, cur = cur, nxt
    return cur


@cache
def _growth_coefficients(method: str) -> tuple[tuple[float, ...], ...]:
    """``E[m][i]``: |R|² - 1 = Σ_m u^m Σ_i E[m][i] a^i, exact up to the final rounding."""
    p, q = _ND[method]
    size = max(len(p), len(q))
    p = [Fraction(c) for c in p] + [Fraction(0)] * (size - len(p))
    q = [Fraction(c) for c in q] + [Fraction(0)] * (size - len(q))
    coeffs = [[Fraction(0)] * (2 * size) for _ in range(2 * size - 1)]
    for j in range(size):
        for k in range(size):
            w = p[j] * p[k] - q[j] * q[k]
            for i, c in enumerate(_chebyshev(abs(j - k))):
                coeffs[j + k][i] += w * c
    return tuple(tuple(float(c) for c in row) for row in coeffs)


def _ray_polynomial(method: str, a: float) -> np.ndarray:
    """Coefficients (lowest power first) of ``|R(u d)|² - 1`` in ``u``, ``Re d = a``."""
    return np.array([math.fsum(c * a**i for i, c in enumerate(row) if c)
                     for row in _growth_coefficients(method)])


def _first_growth(c: np.ndarray) -> float:
    """Smallest ``u > 0`` past which ``Σ c_m u^m`` turns positive (``inf`` if never)."""
    nonzero = np.flatnonzero(c)
    if nonzero.size == 0:
        return math.inf                 # |R| = 1 all along the ray
    c = c[nonzero[0]:nonzero[-1] + 1]   # divide out u^m0: the root at u = 0
    if c[0] > 0:
        return 0.0                      # grows for the smallest steps
    coeffs = c[::-1].tolist()            # highest power first, for Horner's rule

    def poly(u: float) -> float:
        acc = 0.0
        for ck in coeffs:
            acc = acc * u + ck
        return acc

    roots = np.roots(coeffs)
    cand = np.sort([r.real for r in roots if r.real > 0 and abs(r.imag) <= 1e-6 * abs(r)])
    edges = np.concatenate(([0.0], cand, [2.0 * cand[-1] + 1.0 if cand.size else 1.0])).tolist()
    for lo, r, hi in zip(edges[:-2], edges[1:-1], edges[2:], strict=True):
        left, right = 0.5 * (lo + r), 0.5 * (r + hi)
        if poly(left) <= 0 < poly(right):
            for _ in range(200):        # bisect to the float where the sign flips
                mid = 0.5 * (left + right)
                if not left < mid < right:
                    break
                left, right = (mid, right) if poly(mid) <= 0 else (left, mid)
            return left
    return math.inf


def max_stable_dt(method: str, lam: complex, dt_max: float = math.inf) -> float:
    """Supremum of the stable steps along the ray ``λ dt``: every smaller ``dt`` is stable.

    Parameters
    ----------
    method : str
        One of :data:`course_lib.METHODS`.
    lam : complex
        The eigenvalue ``λ`` (1/s): ``-k`` for decay at rate ``k``, ``iω`` for an undamped
        oscillator of angular frequency ``ω``; non-zero and finite.
    dt_max : float
        Cap on the result (s), > 0; default ``inf``.

    Returns
    -------
    float
        The limit (s), to about 1e-13 relative at any scale of ``λ``: stable for
        ``dt < max_stable_dt``. At the limit itself ``|R| = 1`` (the run neither grows nor
        decays), except for the symplectic pair at ``ω dt = 2``, whose runs grow linearly.
        ``0.0`` if even the smallest steps grow (forward Euler on an undamped oscillator:
        ``|1 + iω dt| > 1`` for every ``dt > 0``); ``inf`` if no step does (backward Euler
        and the trapezoid for ``Re λ <= 0``).

    Examples
    --------
    >>> max_stable_dt("forward_euler", -1.0)   # dt < 2/k
    2.0
    >>> round(max_stable_dt("rk4", 1j), 12)    # ω dt < 2√2
    2.828427124746
    >>> max_stable_dt("symplectic_euler", 4j)  # ω dt < 2 (strictly)
    0.5
    """
    _validate.choice("method", method, _R)
    if isinstance(lam, bool) or not isinstance(lam, complex | float | int | np.number):
        raise TypeError(f"lam must be a number, got {type(lam).__name__}")
    lam = complex(lam)
    if not cmath.isfinite(lam) or lam == 0:
        raise ValueError(f"lam must be finite and non-zero, got {lam!r}")
    if isinstance(dt_max, bool) or not isinstance(dt_max, float | int | np.number):
        raise TypeError(f"dt_max must be a real number, got {type(dt_max).__name__}")
    if not dt_max > 0:
        raise ValueError(f"dt_max must be > 0, got {dt_max!r}")
    size = abs(lam)
    if method in _NEWTONIAN:
        limit = 2.0 / size if lam.real == 0.0 else 0.0
    else:
        limit = _first_growth(_ray_polynomial(method, lam.real / size)) / size
    return float(min(limit, dt_max))


def bisect_stable_dt(is_stable, lo: float, hi: float, rtol: float = 1e-5) -> float:
    """Largest ``dt`` in ``[lo, hi]`` for which ``is_stable(dt)`` holds, by bisection.

    ``is_stable(lo)`` must be true and ``is_stable(hi)`` false (checked). Returns the
    stable end of the final bracket, whose width is below ``rtol * lo``.
    """
    _validate.callable_arg("is_stable", is_stable, "(dt)")
    lo, hi = _validate.positive_finite("lo", lo), _validate.positive_finite("hi", hi)
    if hi <= lo:
        raise ValueError(f"hi must exceed lo, got lo = {lo!r} and hi = {hi!r}")
    rtol = _validate.positive_finite("rtol", rtol)
    if not is_stable(lo):
        raise ValueError(f"the run is already unstable at the lower bracket dt = {lo:g}")
    if is_stable(hi):
        raise ValueError(f"the run is still stable at the upper bracket dt = {hi:g}")
    while hi - lo > rtol * lo:
        mid = 0.5 * (lo + hi)
        if is_stable(mid):
            lo = mid
        else:
            hi = mid
    return float(lo)

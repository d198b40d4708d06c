"""Linear stability of the one-step methods.

Applied to the test equation ``dy/dt = λ y``, every one-step method multiplies the state
by a fixed factor each step, ``y_{k+1} = R(z) y_k`` with ``z = λ dt``. The run decays
when ``|R(z)| < 1``, and the set of such ``z`` is the method's *stability region*.

For ``symplectic_euler`` and ``velocity_verlet``, which need a state ``(x, v)``, the test
problem is ``x'' = λ² x`` (whose solutions grow or decay like ``exp(±λ t)``; the undamped
oscillator has ``λ = iω``). One step multiplies ``(x, v)`` by a 2×2 matrix whose
eigenvalues ``μ`` solve ``μ² - (2 + z²) μ + 1 = 0`` for both methods; we return the
eigenvalue of larger modulus, so that ``|R(z)| <= 1`` is again the stability test. On the
imaginary axis ``|R(iθ)| = 1`` for ``θ <= 2`` and ``> 1`` beyond: stable iff ``ω dt <= 2``.
"""

from __future__ import annotations

import numpy as np

from . import _validate
from .integrators import METHODS


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
    """True where ``|R(z)| <= 1`` (with a round-off allowance ``tol``)."""
    return np.abs(amplification_factor(method, z)) <= 1.0 + tol


def max_stable_dt(method: str, lam: complex, dt_max: float = 1e3) -> float:
    """Largest ``dt`` with ``|R(λ dt)| <= 1`` for all smaller steps along the ray ``λ dt``.

    Parameters
    ----------
    method : str
        One of :data:`course_lib.METHODS`.
    lam : complex
        The eigenvalue ``λ`` (1/s): ``-k`` for decay at rate ``k``, ``iω`` for an undamped
        oscillator of angular frequency ``ω``.
    dt_max : float
        Search limit (s); returned when the method is stable all the way there (as
        backward Euler and the trapezoid are for ``Re λ <= 0``).

    Returns
    -------
    float
        The stability limit (s), to about 1e-13 relative. ``0.0`` if even the smallest
        steps are unstable (forward Euler on an undamped oscillator:
        ``|1 + iω dt| > 1`` for every ``dt > 0``).

    Examples
    --------
    >>> round(max_stable_dt("forward_euler", -1.0), 10)   # dt < 2/k
    2.0
    >>> round(max_stable_dt("rk4", 1j), 4)     # ω dt < 2√2
    2.8284
    """
    _validate.choice("method", method, _R)
    lam = complex(lam)
    if lam == 0:
        raise ValueError("lam must be non-zero")
    dt_max = _validate.positive_finite("dt_max", dt_max)

    def excess(dt: float) -> float:
        return float(abs(amplification_factor(method, lam * dt))) - 1.0

    # Scan a log grid of |λ| dt for the first step where |R| exceeds 1, then bisect on that
    # predicate. Bisection (not root finding on |R| - 1) also handles the symplectic
    # methods, whose |R| sits at exactly 1 on a whole interval before it rises. Scanning
    # from |λ| dt = 0.01 keeps round-off from hiding slow growth such as midpoint's
    # |R(iθ)|² = 1 + θ⁴/4 on the imaginary axis.
    tol = 1e-14
    grid = np.geomspace(1e-2, max(1e-2, dt_max * abs(lam)), 2000) / abs(lam)
    unstable = np.array([excess(dt) > tol for dt in grid])
    if unstable[0]:
        return 0.0
    if not unstable.any():
        return float(dt_max)
    j = int(np.argmax(unstable))
    lo, hi = grid[j - 1], grid[j]
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if excess(mid) > tol:
            hi = mid
        else:
            lo = mid
        if hi - lo <= 4 * np.finfo(float).eps * hi:
            break
    return float(lo)


def bisect_stable_dt(is_stable, lo: float, hi: float, rtol: float = 1e-5) -> float:
    """Largest ``dt`` in ``[lo, hi]`` for which ``is_stable(dt)`` holds, by bisection.

    ``is_stable(lo)`` must be true and ``is_stable(hi)`` false (checked). Returns the
    stable end of the final bracket, whose width is below ``rtol * lo``.
    """
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

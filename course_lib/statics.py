"""Resting shapes of spring networks under gravity: a stable minimum, or a clear error.

An equilibrium is a state where the net force on every free particle vanishes: a
stationary point of the total energy ``E(x) = Σ ½ k (ℓ - L)² - Σ m g·x``. A stationary
point can be a minimum (the shape rests there) or a *saddle*: a planar zigzag strand held
out sideways balances its weight in its plane, but the slightest push across the plane
lets it fall. Plain Newton's method converges to whichever stationary point is near, and
from a symmetric start (every particle in one plane) the force never leaves that plane, so
no method that only follows the force can notice the way down. :func:`equilibrium`
looks at the curvature as well:

- each step minimizes the quadratic model ``E + g·p + ½ pᵀKp`` (``g`` the gradient, minus
  the net force; ``K`` the stiffness matrix, the Hessian of ``E``) within a trust radius:
  Newton's step where ``K`` is positive definite and the step is short enough, otherwise
  the model's exact minimizer on the sphere, found from the eigenvalues of ``K``, which
  goes down along a direction of negative curvature even where the force is zero (the
  "hard case"); the radius grows or shrinks with how well the model predicted the energy
  (Moré & Sorensen 1983; Nocedal & Wright 2006, ch. 4);
- it stops only where the net force is below ``rtol`` times the weight **and** ``K`` has no
  eigenvalue below ``-CURVATURE_RTOL × λ_max`` on the free coordinates: a stable minimum
  (a flat direction, such as a symmetry, counts as stable). Otherwise it raises
  ``RuntimeError`` saying where it stopped.

The Hessian is dense: this module is meant for strands and small networks (up to a few
thousand coordinates).

Core module: imports NumPy, SciPy and :mod:`course_lib.springs`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import LinAlgError, cho_factor, cho_solve, eigh, eigvalsh
from scipy.optimize import brentq

from . import _validate
from .springs import SpringNetwork, stiffness_matrix

#: Eigenvalues of K above ``-CURVATURE_RTOL × λ_max`` count as zero (round-off, symmetries).
CURVATURE_RTOL = 1e-8


@dataclass
class Equilibrium:
    """Result of :func:`equilibrium`.

    Attributes
    ----------
    x : ndarray, shape (N, d)
        Positions at rest (m).
    energy : float
        Elastic plus gravitational energy there (J).
    lowest : float
        Smallest eigenvalue of the stiffness matrix on the free coordinates (N/m): ``>= 0``
        up to the tolerance, since the point is a stable minimum.
    iterations : int
        Steps tried (accepted or not).
    escapes : int
        Steps taken along a direction of negative curvature where the force gave no
        direction (saddle points left on the way).
    """

    x: np.ndarray
    energy: float
    lowest: float
    iterations: int
    escapes: int


def free_coordinates(n: int, dim: int, pinned=(), axes=None) -> np.ndarray:
    """Indices into ``x.ravel()`` of the coordinates that may move: every component in
    ``axes`` (all if None) of every particle not in ``pinned``."""
    n, dim = _validate.positive_int("n", n), _validate.positive_int("dim", dim)
    free = np.setdiff1d(np.arange(n), _validate.indices("pinned", pinned, n))
    axes = np.arange(dim) if axes is None else np.unique(np.asarray(axes, dtype=int))
    if axes.size == 0 or axes.min() < 0 or axes.max() >= dim:
        raise ValueError(f"axes must be coordinate indices in 0..{dim - 1}, got {axes.tolist()}")
    return (free[:, None] * dim + axes).ravel()


def curvature(network: SpringNetwork, x, pinned=(), axes=None) -> np.ndarray:
    """Eigenvalues (N/m, ascending) of the stiffness matrix restricted to the free
    coordinates at ``x``: all positive at a strict minimum, one or more negative at a
    saddle. (Gravity is constant, so it adds nothing to the Hessian.)"""
    x = _validate.positions("x", x, network.n_particles)
    dofs = free_coordinates(*x.shape, pinned, axes)
    return eigvalsh(stiffness_matrix(network, x)[np.ix_(dofs, dofs)])


def model_step(lam, V, grad, radius: float) -> tuple[np.ndarray, bool]:
    """Minimizer of ``g·p + ½ pᵀKp`` over ``|p| <= radius``, with ``K = V diag(lam) Vᵀ``.

    Newton's step if ``K`` is positive definite and the step is short enough; else
    ``p(μ) = -(K + μ I)⁻¹ g`` with the shift ``μ >= max(0, -λ_min)`` that puts it on the
    sphere. In the "hard case" the gradient has no component along the lowest eigenvector
    and no shift reaches the sphere; the step then goes along that eigenvector for the rest
    of the radius. Returns ``(p, escape)``, ``escape`` True for a hard-case step along
    negative curvature.
    """
    c = V.T @ grad
    tiny = 1e-12 * max(abs(lam[0]), abs(lam[-1]), 1e-300)
    if lam[0] > tiny:
        p = -(c / lam)
        if np.linalg.norm(p) <= radius:
            return V @ p, False
    shift = max(0.0, -lam[0])

    def excess(mu):
        return np.linalg.norm(c / (lam + mu)) - radius

    lo = shift + tiny
    if excess(lo) >= 0.0:
        hi = shift + np.linalg.norm(c) / radius + tiny
        mu = brentq(excess, lo, hi, xtol=1e-14 * hi, rtol=1e-10)
        return V @ (-c / (lam + mu)), False
    bottom = lam - lam[0] <= tiny
    p = np.where(bottom, 0.0, -c / np.where(bottom, 1.0, lam + shift))
    low = int(np.flatnonzero(bottom)[0])
    length = np.sqrt(max(radius**2 - p @ p, 0.0))
    if c[low] != 0.0:
        p[low] = -np.copysign(length, c[low])
    else:   # no gradient to follow: a sign of our own, not the eigen-solver's (machine-free)
        v = V[:, low]
        p[low] = length if v[np.argmax(np.abs(v))] >= 0 else -length
    return V @ p, bool(lam[0] < -tiny)


def _top(K) -> float:
    """Largest |eigenvalue| of the symmetric ``K``, bounded above by its largest row sum."""
    return float(np.abs(K).sum(axis=1).max()) or 1e-300


def _newton(K, grad, radius):
    """Newton's step ``-K⁻¹ g`` if ``K`` is positive definite and the step is within the
    trust radius, else ``(None, False)``."""
    try:
        p = -cho_solve(cho_factor(K), grad)
    except LinAlgError:
        return None, False
    return (p, False) if np.linalg.norm(p) <= radius else (None, False)


def equilibrium(x0, network: SpringNetwork, mass, pinned=(), gravity=(0.0, -9.81, 0.0),
                axes=None, rtol: float = 1e-9, max_iter: int = 600) -> Equilibrium:
    """A stable resting shape under gravity reached from ``x0`` (see the module docstring).

    Parameters
    ----------
    x0 : array_like, shape (N, d)
        Start (m); pinned particles stay where they are.
    network : SpringNetwork
    mass : float or array_like, shape (N,)
        Particle masses (kg), > 0.
    pinned : sequence of int
        Particles held fixed.
    gravity : array_like, shape (d,)
        Acceleration of gravity (m/s²).
    axes : sequence of int, optional
        Coordinates the free particles may move along, e.g. ``(0, 1)`` to keep a strand in
        its plane (a 2D problem): the minimum is then a minimum among such shapes.
    rtol : float
        Stop when the net force on the free coordinates is below ``rtol`` × their weight.
    max_iter : int
        Steps allowed.

    Raises
    ------
    RuntimeError
        When no stable minimum is found within ``max_iter`` steps; the message says where
        it stopped.
    """
    x = _validate.positions("x0", x0, network.n_particles)
    n, dim = x.shape
    m = _validate.masses("mass", mass, n)
    g = _validate.real_array("gravity", gravity, (dim,))
    rtol = _validate.positive_finite("rtol", rtol)
    max_iter = _validate.positive_int("max_iter", max_iter)
    dofs = free_coordinates(n, dim, pinned, axes)
    weight = float(np.sum(m[np.unique(dofs // dim)]) * np.linalg.norm(g)) or 1.0
    # steps are measured over all free coordinates: a strand of n segments s long that
    # turns about its root by θ moves by about θ s n^1.5 / √3
    scale = float(np.median(network.rest)) * np.sqrt(dofs.size) if network.n_springs else 1.0
    radius, escapes = 0.1 * scale, 0

    def energy(z):
        return float(network.energy(z)) - float(np.sum(m * (z @ g)))

    def gradient(z):
        return -(network.forces(z) + m[:, None] * g).ravel()[dofs]

    E, grad = energy(x), gradient(x)
    for it in range(max_iter):
        K = stiffness_matrix(network, x)[np.ix_(dofs, dofs)]
        norm = float(np.linalg.norm(grad))
        if norm < rtol * weight:
            lowest, top = eigvalsh(K, subset_by_index=[0, 0])[0], _top(K)
            if lowest >= -CURVATURE_RTOL * top:
                return Equilibrium(x, E, float(lowest), it, escapes)
        p, escape = _newton(K, grad, radius)
        if p is None:               # K not positive definite, or the step too long
            lam, V = eigh(K)
            p, escape = model_step(lam, V, grad, radius)
        predicted = float(grad @ p + 0.5 * p @ (K @ p))
        trial = x.copy()
        trial.ravel()[dofs] += p
        E_t, g_t = energy(trial), gradient(trial)
        ratio = (E_t - E) / predicted if predicted < 0 else -1.0
        length = float(np.linalg.norm(p))
        if ratio < 0.25:
            radius = 0.5 * length
        elif ratio > 0.75 and length > 0.99 * radius:
            radius = min(1.5 * radius, 10.0 * scale)
        # near convergence the energy no longer resolves the change: judge by the force
        if ratio > 0.1 or (abs(predicted) < 1e-13 * abs(E) and np.linalg.norm(g_t) < norm):
            x, E, grad = trial, E_t, g_t
            escapes += bool(escape)
        elif radius < 1e-14 * scale:
            break
    lowest = float(eigvalsh(stiffness_matrix(network, x)[np.ix_(dofs, dofs)])[0])
    raise RuntimeError(
        f"equilibrium: no stable minimum found within {max_iter} steps: it stopped where the "
        f"net force is {np.linalg.norm(grad) / weight:.2g} × the weight and the lowest "
        f"curvature {lowest:.3g} N/m ({escapes} saddle points left on the way)")

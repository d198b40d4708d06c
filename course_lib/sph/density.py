"""Pairs of particles, their kernel values, and the density by summation.

:func:`neighbourhood` finds, for fluid positions ``x`` (N, dim) and a wall, every fluid
pair closer than the kernel's support (each pair once, ``i < j``, with
:func:`course_lib.neighbors.pairs`, the k-d tree search notebook 10 shares) and every
(fluid, wall) pair, and evaluates the kernel ``W`` and its gradient ``∇_i W`` on them once per step, in
a :class:`Neighbourhood`. :func:`scatter` adds a pair quantity to both particles of each
pair (``+f`` to ``i``, ``sign · f`` to ``j``) without a Python loop, and
:func:`summation_density` computes

    ρ_i = m_i W(0) + Σ_j m_j W(|x_i - x_j|) + Σ_k ψ_k W(|x_i - x_k|)        (kg/m^dim)

over fluid neighbours ``j`` and wall particles ``k`` of weight ``ψ_k`` (Akinci et al. 2012;
see :mod:`course_lib.sph.boundary`). Core module: NumPy and SciPy only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import neighbors
from . import _search
from .kernels import KERNELS, SUPPORT, check_name, gradient


@dataclass
class Neighbourhood:
    """The pairs of one configuration and the kernel on them.

    ``i, j`` (P,) fluid pairs with ``i < j``; ``d`` (P, dim) = ``x_i - x_j`` (m); ``r`` (P,)
    their lengths; ``w`` (P,) kernel values (1/m^dim); ``gw`` (P, dim) = ``∇_i W``. The
    same with prefix ``b`` for (fluid ``bi``, wall ``bk``) pairs, ``bd = x_i - x_k``.
    ``n`` fluid particles, ``w0 = W(0)``, ``h`` the kernel's h (m).
    """

    n: int
    h: float
    w0: float
    i: np.ndarray
    j: np.ndarray
    d: np.ndarray
    r: np.ndarray
    w: np.ndarray
    gw: np.ndarray
    bi: np.ndarray
    bk: np.ndarray
    bd: np.ndarray
    br: np.ndarray
    bw: np.ndarray
    bgw: np.ndarray

    @property
    def n_pairs(self) -> int:
        """Number of fluid pairs, each counted once."""
        return len(self.i)


def neighbourhood(x, h: float, kernel: str = "cubic", wall=None) -> Neighbourhood:
    """Fluid pairs and (fluid, wall) pairs within the support of ``kernel`` (see
    :data:`~course_lib.sph.kernels.SUPPORT`), with ``W`` and ``∇W`` evaluated on them.

    ``x`` is ``(N, dim)`` (m), ``h`` the kernel's h (m), ``wall`` a
    :class:`~course_lib.sph.boundary.Boundary` or None.
    """
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[1] not in (1, 2, 3):
        raise ValueError(f"x must have shape (N, dim) with dim 1, 2 or 3, got {x.shape}")
    W = KERNELS[check_name(kernel)]
    dim, radius = x.shape[1], SUPPORT[kernel] * h
    found = neighbors.pairs(x, radius, sort=False)      # the course's shared search
    i, j, d, r = found.i, found.j, -found.offset, found.distance
    if wall is not None and wall.n:
        bi, bk = _search.cross_pairs(x, wall.tree, radius)
    else:
        bi = bk = np.zeros(0, dtype=np.intp)
    bd = x[bi] - (wall.x[bk] if wall is not None and wall.n else np.zeros((0, dim)))
    br = np.sqrt(np.einsum("pk,pk->p", bd, bd))
    return Neighbourhood(len(x), float(h), float(W(0.0, h, dim)), i, j, d, r, W(r, h, dim),
                         gradient(kernel, d, r, h), bi, bk, bd, br, W(br, h, dim),
                         gradient(kernel, bd, br, h))


def scatter(i: np.ndarray, j: np.ndarray, f: np.ndarray, n: int, f_j: np.ndarray | None = None,
            sign: float = -1.0) -> np.ndarray:
    """Sum pair values onto particles: ``out[i] += f`` and ``out[j] += f_j``.

    ``f`` is ``(P,)`` or ``(P, dim)``; returns ``(n,)`` or ``(n, dim)``. Without ``f_j``,
    ``j`` gets ``sign · f``: with ``sign = -1`` (the default) every pair adds equal and
    opposite amounts, as a pair force on equal masses must.
    """
    f = np.asarray(f, dtype=float)
    g = sign * f if f_j is None else np.asarray(f_j, dtype=float)
    if f.ndim == 1:
        return np.bincount(i, f, minlength=n) + np.bincount(j, g, minlength=n)
    out = np.empty((n, f.shape[1]))
    for k in range(f.shape[1]):       # bincount sums 1D weights: one column at a time
        out[:, k] = np.bincount(i, f[:, k], minlength=n) + np.bincount(j, g[:, k], minlength=n)
    return out


def wall_sum(nb: Neighbourhood, f: np.ndarray) -> np.ndarray:
    """Sum (fluid, wall) pair values onto the fluid particles: ``out[bi] += f``."""
    f = np.asarray(f, dtype=float)
    if f.ndim == 1:
        return np.bincount(nb.bi, f, minlength=nb.n)
    return np.stack([np.bincount(nb.bi, f[:, k], minlength=nb.n) for k in range(f.shape[1])],
                    axis=1)


def summation_density(nb: Neighbourhood, mass, psi=None) -> np.ndarray:
    """``ρ_i`` (kg/m^dim) by summation over the particle itself, its fluid neighbours and
    the wall particles near it (weights ``psi`` (K,), kg; ignored without wall pairs).

    ``mass`` is a scalar or ``(N,)`` (kg)."""
    m = np.broadcast_to(np.asarray(mass, dtype=float), (nb.n,))
    rho = m * nb.w0 + np.bincount(nb.i, m[nb.j] * nb.w, minlength=nb.n) \
        + np.bincount(nb.j, m[nb.i] * nb.w, minlength=nb.n)
    if len(nb.bi):
        rho += wall_sum(nb, np.asarray(psi, dtype=float)[nb.bk] * nb.bw)
    return rho

"""Analytic Jacobians of spring forces, the stiffness matrix, and the fastest frequency.

For one spring with ``d = x_i - x_j``, ``ℓ = |d|``, ``u = d/ℓ`` and relative velocity
``w = v_i - v_j``, the force on ``i`` is ``F_i = -[k (ℓ - L) + c w·u] u``. Its derivatives
form one ``d × d`` block ``G`` per spring, placed with the signs ``[[G, -G], [-G, G]]`` at
the particle pairs ``(i, i), (i, j), (j, i), (j, j)``:

- elastic: ``∂F_i/∂x_i = -K_s``, ``K_s = k [u uᵀ + (1 - L/ℓ)(I - u uᵀ)]`` (the second,
  *geometric* term is the stiffness of a stretched string against sideways motion; it is
  negative for a compressed spring, ``ℓ < L``);
- damping, velocities: ``∂F_i/∂v_i = -c u uᵀ`` (symmetric, negative semidefinite);
- damping, positions: ``-(c/ℓ) [u wᵀ + (w·u) I] (I - u uᵀ)`` (not symmetric: Baraff &
  Witkin 1998 leave it out of their solve).

``definite=True`` drops the negative geometric term of compressed springs (Choi & Ko
2002), so that ``-∂F/∂x`` is positive semidefinite and conjugate gradients apply. Where a
spring's ends coincide we take ``1/ℓ = 0`` as the force does, so its block is ``k I`` (exact
for a zero rest length). Matrices are ``scipy.sparse`` CSR of shape ``(N d, N d)``; row
``a d + p`` is component ``p`` of particle ``a`` (the order of ``x.ravel()``).

Core module: imports NumPy, SciPy, :mod:`course_lib._validate` and the network.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .. import _validate
from .network import SpringNetwork

#: Above this many unknowns :func:`max_frequency` uses a sparse eigensolver.
DENSE_LIMIT = 1500


def _pattern(network: SpringNetwork, dim: int):
    """CSR structure of ``Σ_s [[G, -G], [-G, G]]`` and where each block entry lands."""
    key = ("pattern", dim)
    if key not in network._work:
        n, i, j = network.n_particles, network.i, network.j
        p, q = np.meshgrid(np.arange(dim), np.arange(dim), indexing="ij")
        rows = np.concatenate([a[:, None, None] * dim + p for a in (i, i, j, j)])
        cols = np.concatenate([b[:, None, None] * dim + q for b in (i, j, i, j)])
        keys, slot = np.unique((rows * (n * dim) + cols).ravel(), return_inverse=True)
        indptr = np.searchsorted(keys, np.arange(n * dim + 1) * (n * dim))
        network._work[key] = (slot, (keys % (n * dim)).astype(np.int32), indptr.astype(np.int32))
    return network._work[key]


def assemble(network: SpringNetwork, blocks: np.ndarray) -> sp.csr_matrix:
    """Sparse ``(N d, N d)`` matrix ``Σ_s`` of block ``G_s`` at ``(i, i)`` and ``(j, j)`` and
    ``-G_s`` at ``(i, j)`` and ``(j, i)``, for per-spring blocks of shape ``(M, d, d)``."""
    m, dim = network.n_springs, blocks.shape[-1]
    if blocks.shape != (m, dim, dim):
        raise ValueError(f"blocks must have shape ({m}, d, d), got {blocks.shape}")
    slot, indices, indptr = _pattern(network, dim)
    signed = np.concatenate((blocks, -blocks, -blocks, blocks)).ravel()
    data = np.bincount(slot, weights=signed, minlength=indices.size)
    size = network.n_particles * dim
    return sp.csr_matrix((data, indices, indptr), shape=(size, size))


def _geometry(network: SpringNetwork, x):
    d, inv, _ = network.spring_coefficients(x)
    u = d * inv[:, None]                           # unit vectors, (M, d)
    return u, inv, u[:, :, None] * u[:, None, :], np.eye(d.shape[1])


def jacobian_x(network: SpringNetwork, x, v=None, *, definite: bool = False) -> sp.csr_matrix:
    """``∂F/∂x`` of the spring forces at positions ``x`` (N/m), sparse ``(N d, N d)``.

    Parameters
    ----------
    network : SpringNetwork
    x : ndarray, shape (N, d)
        Positions (m).
    v : ndarray, shape (N, d), optional
        Velocities (m/s). When given (and the springs are damped) the result includes the
        derivative of the damping force with respect to positions, which is not symmetric;
        without it the result is the symmetric elastic part ``-K``.
    definite : bool
        Drop the negative geometric term of compressed springs, so that ``-∂F/∂x`` (elastic
        part) is positive semidefinite.
    """
    x = _validate.positions("x", x, network.n_particles)
    v = None if v is None else _validate.positions("v", v, *x.shape)
    return _jacobian_x(network, x, v, definite)


def _jacobian_x(network, x, v, definite):
    u, inv, uu, eye = _geometry(network, x)
    geometric = 1.0 - network.rest * inv
    if definite:
        geometric = np.maximum(geometric, 0.0)
    k = network.k[:, None, None]
    blocks = -k * (uu + geometric[:, None, None] * (eye - uu))
    if v is not None and np.any(network.c):
        v = np.asarray(v, dtype=float)
        w = v[network.i] - v[network.j]
        rate = np.einsum("md,md->m", w, u)
        side = eye - uu
        lead = u[:, :, None] * np.einsum("mp,mpq->mq", w, side)[:, None, :] + rate[:, None, None] * side
        blocks -= (network.c * inv)[:, None, None] * lead
    return assemble(network, blocks)


def jacobian_v(network: SpringNetwork, x) -> sp.csr_matrix:
    """``∂F/∂v`` of the damping along the springs (N s/m): blocks ``-c u uᵀ``, sparse
    ``(N d, N d)``, symmetric negative semidefinite."""
    _, _, uu, _ = _geometry(network, _validate.positions("x", x, network.n_particles))
    return assemble(network, -network.c[:, None, None] * uu)


def stiffness_matrix(network: SpringNetwork, x, *, sparse: bool = False, definite: bool = False):
    """Hessian ``K = ∂²E/∂x² = -∂F/∂x`` of the elastic energy at positions ``x`` (N/m).

    For a spring the block of particle ``i`` is ``K_s = k [u uᵀ + (1 - L/ℓ)(I - u uᵀ)]``;
    ``(j, j)`` gets ``K_s`` too and the two off-diagonal blocks ``-K_s``. Small motions
    ``δx`` about ``x`` feel ``δF = -K δx``.

    Returns
    -------
    ndarray or scipy.sparse.csr_matrix, shape (N d, N d)
        Symmetric; dense unless ``sparse=True``. Row ``a d + p`` is component ``p`` of
        particle ``a``.
    """
    K = -jacobian_x(network, x, definite=definite)
    return K if sparse else K.toarray()


def _free_dofs(n: int, dim: int, pinned) -> np.ndarray:
    pinned = np.asarray([] if pinned is None else pinned, dtype=int)
    free = np.setdiff1d(np.arange(n), pinned)
    return (free[:, None] * dim + np.arange(dim)).ravel(), free


def max_frequency(network: SpringNetwork, x, mass, pinned=None) -> float:
    """Highest angular frequency ``ω_max`` (rad/s) of small oscillations about ``x``.

    The square root of the largest eigenvalue of ``M^{-1/2} K M^{-1/2}`` over the free (not
    pinned) particles. An explicit method is stable while ``ω_max dt`` stays inside its
    stability interval, e.g. ``dt < 2 / ω_max`` for symplectic Euler.
    """
    x = _validate.positions("x", x, network.n_particles)
    n, dim = x.shape
    m = _validate.masses("mass", mass, n)
    dofs, free = _free_dofs(n, dim, _validate.indices("pinned", pinned, n))
    w = sp.diags(1.0 / np.sqrt(np.repeat(m[free], dim)))
    A = w @ stiffness_matrix(network, x, sparse=True)[dofs][:, dofs] @ w
    if A.shape[0] <= DENSE_LIMIT:
        top = np.linalg.eigvalsh(A.toarray()).max()
    else:
        top = spla.eigsh(A, k=1, which="LA", return_eigenvectors=False, tol=1e-10)[0]
    return float(np.sqrt(max(top, 0.0)))


def chain_max_frequency(n_free: int, k: float, m: float) -> float:
    """Exact ``ω_max`` of a chain of ``n_free`` equal masses ``m`` joined by equal springs
    ``k`` and fixed at one end (longitudinal motion): ``2 √(k/m) sin((2N-1)π / (4N+2))``.
    Tends to ``2 √(k/m)`` as the chain grows."""
    n_free = _validate.positive_int("n_free", n_free)
    k, m = _validate.positive_finite("k", k), _validate.positive_finite("m", m)
    return float(2.0 * np.sqrt(k / m) * np.sin((2 * n_free - 1) * np.pi / (4 * n_free + 2)))


def newtonian_jacobian(network: SpringNetwork, mass, pinned=None):
    """``jac(t, y)`` of ``f(t, y) = (v, F/m)`` for springs (plus any constant force) on a
    stacked state ``y = (x, v)`` of shape ``(2, N, d)``: the sparse ``(2 N d, 2 N d)``
    matrix ``[[0, I], [M⁻¹ ∂F/∂x, M⁻¹ ∂F/∂v]]``, with zero rows for pinned particles.

    For the implicit methods of :func:`~course_lib.integrators.integrate` (``jac=``).
    """
    m = _validate.masses("mass", mass, network.n_particles)
    pins = _validate.indices("pinned", pinned, network.n_particles)

    def jac(t, y):  # at every Newton iteration: the state is the run's (checked there)
        x, v = y[0], y[1]
        n, dim = x.shape
        scale = np.repeat(1.0 / m, dim)
        scale.reshape(n, dim)[pins] = 0.0
        S = sp.diags(scale)
        top = sp.hstack([sp.csr_matrix((n * dim, n * dim)), sp.identity(n * dim)])
        _, _, uu, _ = _geometry(network, x)
        bottom = sp.hstack([S @ _jacobian_x(network, x, v, False),
                            S @ assemble(network, -network.c[:, None, None] * uu)])
        return sp.vstack([top, bottom]).tocsr()

    return jac

"""The pressure operators of one configuration as sparse matrices (for IISPH's solve).

For a fixed set of pairs, the pressure acceleration is linear in the pressures and the
velocity divergence is linear in the velocities. :class:`PressureOperator` assembles
both once per step as SciPy sparse matrices, so that each sweep of the pressure solve
costs a few sparse products instead of gathers over every pair. With
``G[a, b] = m_b ∇_a W_ab`` (one matrix per axis; ``G[j, i] = -m_i ∇_i W_ij``), its row
sums ``g_i = Σ_j m_j ∇W_ij`` and ``q = p/ρ²``,

    a^p_i   = -(g_i q_i + (G q)_i) - (w_i q_i + (B p_wall)_i / ρ₀²),
    div(u)_i = u_i·(g_i + w_i) - Σ_axes (G u)_i,

where ``B[i, k] = ψ_k ∇_i W_ik`` couples to the wall particles, ``w_i`` its row sums and
``p_wall = E p + h`` the extrapolated wall pressures (Adami et al. 2012, see
:func:`course_lib.sph.forces.wall_pressure`). They equal
:func:`~course_lib.sph.forces.pressure_acceleration` and the pair sums to round-off
(tested). Core module: NumPy and SciPy.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .density import Neighbourhood


def _matrices(rows, cols, columns: list[np.ndarray], shape) -> tuple[list[sp.csr_array], sp.csr_array]:
    """CSR matrices sharing one sparsity pattern, one per data array (no duplicates), and
    the same stacked one above the other (``len(columns) · shape[0]`` rows): the entries
    grouped by row with a stable sort (a radix sort on small row numbers), so no COO
    conversion is needed. The stacked matrix multiplies a vector by every one at once,
    with each row's sum in the same order."""
    rows = np.asarray(rows)
    key = rows.astype(np.uint16) if shape[0] <= np.iinfo(np.uint16).max else rows
    perm = np.argsort(key, kind="stable")
    indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=shape[0]))])
    indices = np.asarray(cols)[perm]
    data = [c[perm] for c in columns]
    single = [sp.csr_array((d, indices, indptr), shape=shape) for d in data]
    nnz = len(indices)
    stacked_ptr = np.concatenate([indptr[:-1] + k * nnz for k in range(len(data))] + [[len(data) * nnz]])
    stacked = sp.csr_array((np.concatenate(data), np.tile(indices, len(data)), stacked_ptr),
                           shape=(len(data) * shape[0], shape[1]))
    return single, stacked


class PressureOperator:
    """``accel(p)`` (N, dim) and ``divergence(u)`` (N,) of one configuration.

    ``nb`` the :class:`~course_lib.sph.density.Neighbourhood`, ``mass`` scalar or (N,),
    ``rho`` (N,) densities, ``psi`` (K,) wall weights (None: no wall), ``gravity`` (dim,),
    ``rho0`` the rest density, ``wall_pressure`` ``"extrapolated"`` or ``"mirrored"``.
    """

    def __init__(self, nb: Neighbourhood, mass, rho, psi=None, gravity=(0.0, -9.81),
                 rho0: float = 1000.0, wall_pressure: str = "extrapolated"):
        n, dim = nb.n, nb.gw.shape[1]
        m = np.broadcast_to(np.asarray(mass, dtype=float), (n,))
        self.n, self.rho0, self.rho2 = n, float(rho0), np.asarray(rho, dtype=float) ** 2
        rows, cols = np.concatenate([nb.i, nb.j]), np.concatenate([nb.j, nb.i])
        data = [np.concatenate([m[nb.j] * nb.gw[:, k], -m[nb.i] * nb.gw[:, k]]) for k in range(dim)]
        self.G, self._G_stacked = _matrices(rows, cols, data, (n, n))
        self.g = np.stack([np.bincount(rows, d, minlength=n) for d in data], axis=1)   # row sums
        g2 = np.einsum("pk,pk->p", nb.gw, nb.gw)
        self.grad2 = m * (np.bincount(nb.i, m[nb.j] * g2, minlength=n)
                          + np.bincount(nb.j, m[nb.i] * g2, minlength=n))
        self.mirrored = wall_pressure == "mirrored"
        self.B, self.w = None, np.zeros((n, dim))
        if psi is not None and len(nb.bi):
            psi = np.asarray(psi, dtype=float)
            K = len(psi)
            wall = [psi[nb.bk] * nb.bgw[:, k] for k in range(dim)]
            self.B, self._B_stacked = _matrices(nb.bi, nb.bk, wall, (n, K))
            self._pairs, self._wall_terms = nb.bi, wall
            self.w = np.stack([np.bincount(nb.bi, d, minlength=n) for d in wall], axis=1)
            total = np.bincount(nb.bk, nb.bw, minlength=K)
            share = np.divide(nb.bw, total[nb.bk], out=np.zeros_like(nb.bw), where=total[nb.bk] > 0)
            self.E = _matrices(nb.bk, nb.bi, [share], (K, n))[0][0]
            self._share = share
            head = -np.asarray(rho, dtype=float)[nb.bi] * (nb.bd @ np.asarray(gravity, dtype=float))
            self.head = np.bincount(nb.bk, share * head, minlength=K)

    def wall_pressures(self, p) -> np.ndarray:
        """Extrapolated wall pressures ``E p + h`` (Pa, (K,))."""
        return self.E @ np.asarray(p, dtype=float) + self.head

    def accel(self, p) -> np.ndarray:
        """The pressure acceleration (m/s², (N, dim)) of the pressures ``p`` (Pa, (N,))."""
        p = np.asarray(p, dtype=float)
        q = p / self.rho2
        Gq = (self._G_stacked @ q).reshape(-1, self.n).T          # (G_k q) for every axis k
        a = -(self.g * q[:, None] + Gq)
        if self.B is not None:
            if self.mirrored:
                a -= 2.0 * self.w * q[:, None]
            else:
                p_wall = self.wall_pressures(p) / self.rho0**2
                a -= self.w * q[:, None] + (self._B_stacked @ p_wall).reshape(-1, self.n).T
        return a

    def divergence(self, u) -> np.ndarray:
        """``Σ_j m_j (u_i - u_j)·∇W_ij + Σ_k ψ_k u_i·∇W_ik`` (walls at rest) for ``u`` (N, dim)."""
        u = np.asarray(u, dtype=float)
        out = np.einsum("nk,nk->n", u, self.g + self.w)
        for k, Gk in enumerate(self.G):
            out -= Gk @ u[:, k]
        return out

    def wall_flux(self, v_wall) -> np.ndarray:
        """``Σ_k ψ_k v_k·∇W_ik`` (N,) for wall velocities ``v_wall`` (K, dim): what moving
        walls take from :meth:`divergence`, whose wall term assumes them at rest."""
        out = np.zeros(self.n)
        if self.B is not None:
            v_wall = np.asarray(v_wall, dtype=float)
            for k, Bk in enumerate(self.B):
                out += Bk @ v_wall[:, k]
        return out

    def diagonal(self, dt: float) -> np.ndarray:
        """``a_ii`` (N,) of ``A = Δt² div(a^p(·))``: the coefficient of ``p_i`` in ``(A p)_i``
        (the wall pressures' share of ``p_i`` included, their effect on the neighbours left
        out). With ``D_i = ∂a^p_i/∂p_i`` and ``G_i = Σ_j m_j ∇W_ij + Σ_k ψ_k ∇W_ik``,
        ``a_ii = Δt² [D_i·G_i - (m_i/ρ_i²) Σ_j m_j |∇W_ij|²] < 0``."""
        D = -self.g / self.rho2[:, None]
        if self.B is not None:
            if self.mirrored:
                D -= 2.0 * self.w / self.rho2[:, None]
            else:   # p_i's share in the pressure of each wall particle near it
                D -= self.w / self.rho2[:, None]
                for k, wall in enumerate(self._wall_terms):      # Σ_k B[i, k] E[k, i]
                    D[:, k] -= np.bincount(self._pairs, wall * self._share, minlength=self.n) / self.rho0**2
        return dt * dt * (np.einsum("nk,nk->n", D, self.g + self.w) - self.grad2 / self.rho2)

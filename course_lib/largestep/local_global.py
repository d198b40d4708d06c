"""Fast mass-springs: implicit Euler by local/global alternation (Liu, Bargteil, O'Brien &
Kavan 2013), optionally accelerated by L-BFGS (Liu, Bouaziz & Kavan 2017).

Implicit Euler's end positions ``x`` minimize (with ``y = x₀ + h v₀ + h² M⁻¹ f_ext`` the
inertial prediction)

    g(x) = ½ (x - y)ᵀ M (x - y) + h² E(x) + (h/2) (x - x₀)ᵀ C₀ (x - x₀),

``E`` the spring energy and the last term damping along the springs, with their
directions frozen at the start of the step (``C₀ = Σ c u uᵀ`` blocks). Liu et al. write a
spring's energy as ``½ k |dᵢⱼ - p|²`` minimized over vectors ``p`` of length ``L``, and
the damping term likewise as ``½ (c/h) |dᵢⱼ - e|²`` over ``e`` with ``u₀·e = u₀·d₀``.
Then ``g`` is minimized by alternating two exact steps, neither of which can raise it:

- **local**: project every spring (:meth:`SpringNetwork.project
  <course_lib.springs.network.SpringNetwork.project>`): ``p = L d/|d|``, ``e = d - u₀ u₀·(d - d₀)``;
- **global**: solve ``(M + h² L_k + h L_c) x = M y + Σ (e_i - e_j)(h² k p + h c e)`` with
  ``L_w`` the ``w``-weighted graph Laplacian of the springs: one *constant* matrix,
  factored once per step length and set of pins (:class:`FactorCache`, sparse LU with a
  fill-reducing order, the pinned rows replaced by the identity) and reused by every
  iteration of every step.

One local/global iteration is exactly ``x ← x - A⁻¹ ∇g(x)``, a gradient step with the
constant matrix ``A`` as preconditioner. It converges fast for stretching but slowly for
the sideways motion of stiff springs, where ``A`` overestimates the true stiffness;
L-BFGS (``memory > 0``) keeps the same ``A`` as its first guess of the Hessian and
corrects it with the last few steps, with a backtracking line search on ``g``.

Core module: imports NumPy, SciPy, :mod:`course_lib.springs` and :mod:`.base`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .. import _validate
from ..springs import Projection
from .base import SpringSolver


def _dot(a: np.ndarray, b: np.ndarray) -> float:
    """``Σ a b`` over all entries, without BLAS (its threads stall on a busy machine)."""
    return float(np.einsum("ij,ij->", a, b))


def laplacian(network, weights) -> sp.csr_matrix:
    """``Σ_s w_s (e_i - e_j)(e_i - e_j)ᵀ``: the ``w``-weighted graph Laplacian (N, N)."""
    m, n = network.n_springs, network.n_particles
    s = np.arange(m)
    B = sp.csr_matrix((np.r_[np.ones(m), -np.ones(m)], (np.r_[network.i, network.j], np.r_[s, s])),
                      shape=(n, m))
    return (B @ sp.diags(np.broadcast_to(weights, (m,))) @ B.T).tocsr()


class FactorCache:
    """Factorizations of the global matrix over the free particles, one per ``(h, pins)``.

    Attributes
    ----------
    factorizations : int
        How many matrices were factored (each costs far more than a solve).
    """

    def __init__(self):
        self.factorizations = 0
        self._store: dict = {}

    def get(self, key, build):
        """The entry for ``key``, made by ``build()`` (and counted) the first time."""
        if key not in self._store:
            self._store[key] = build()
            self.factorizations += 1
        return self._store[key]


@dataclass
class GlobalSystem:
    """``A = M + h² L_k + h L_c`` with the pinned rows and columns replaced by the identity
    (so a solve keeps the particle layout and returns a pin's own right-hand side)."""

    lu: object                     # splu of A with identity rows at the pins
    coupling: sp.csr_matrix        # A_fp, pinned rows zero: N × P
    damping: sp.csr_matrix         # h L_c over all particles
    projection: Projection         # x -> Σ h² k (e_i - e_j) L u


@dataclass
class IterationInfo:
    """One step: iterations, line-search halvings and ``g`` after each iteration (J, with
    ``record=True``; the first entry is ``g(y)``, where the iterations start)."""

    iterations: int
    halvings: int
    objective: list


class FastMassSpring(SpringSolver):
    """Implicit Euler for a spring network by local/global iterations.

    Parameters
    ----------
    network, mass, pinned, gravity, external
        As for :class:`~course_lib.largestep.base.SpringSolver`.
    iterations : int
        Iterations per step (fixed, so every step costs the same), >= 1.
    memory : int
        0 for Liu et al.'s local/global iterations; ``m > 0`` for L-BFGS with the last
        ``m`` steps (Liu, Bouaziz & Kavan 2017).
    cache : FactorCache, optional
        Where factorizations are kept (a new one by default).
    record : bool
        Record ``g`` after every iteration in :attr:`info` (one more energy evaluation per
        iteration of plain local/global).
    """

    def __init__(self, network, mass, *, pinned=None, gravity=None, external=None,
                 iterations: int = 20, memory: int = 5, cache: FactorCache | None = None,
                 record: bool = False):
        super().__init__(network, mass, pinned=pinned, gravity=gravity, external=external)
        self.iterations = _validate.positive_int("iterations", iterations)
        if isinstance(memory, bool) or not isinstance(memory, int | np.integer) or memory < 0:
            raise ValueError(f"memory must be an integer >= 0, got {memory!r}")
        self.memory = int(memory)
        self.cache = FactorCache() if cache is None else cache
        self.record = bool(record)
        self.info: IterationInfo | None = None

    def system(self, h: float) -> GlobalSystem:
        """The factored global system for step ``h`` and the current pins (cached)."""
        def build():
            net = self.network
            A = (sp.diags(self.mass) + laplacian(net, h * h * net.k + h * net.c)).tocsr()
            keep = sp.diags(self._free.astype(float))
            # Pinned rows and columns out, 1 on their diagonal: the free block A_ff, and
            # pinned values that pass through a solve unchanged.
            A_free = (keep @ A @ keep + sp.diags((~self._free).astype(float))).tocsc()
            lu = spla.splu(A_free, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options={"SymmetricMode": True})
            return GlobalSystem(lu, (keep @ A)[:, self.pinned].tocsr(), laplacian(net, h * net.c),
                                Projection(net, h * h * net.k))
        return self.cache.get((float(h), self.pinned.tobytes()), build)

    def _solve(self, sys: GlobalSystem, rhs: np.ndarray, x: np.ndarray | None = None) -> np.ndarray:
        """Positions with free rows ``A_ff⁻¹ (rhs_f - A_fp x_p)`` and pinned rows of ``x``
        (``None``: zero at the pins, as for a gradient)."""
        r = np.array(rhs, order="F")
        if self.pinned.size:
            if x is None:
                r[self.pinned] = 0.0
            else:
                r -= sys.coupling @ x[self.pinned]
                r[self.pinned] = x[self.pinned]
        return np.ascontiguousarray(sys.lu.solve(r))

    def objective(self, x, y, x0, h: float, damping=None) -> tuple[float, np.ndarray]:
        """``g(x)`` (J) and its gradient ``(N, d)`` (zero at pins); ``damping`` is the
        network linearized at ``x0`` (or ``None`` without damping)."""
        energy, force = self.network.potential(x)
        dx = x - y
        mdx = self.mass[:, None] * dx
        value = 0.5 * _dot(dx, mdx) + h * h * energy
        grad = mdx - (h * h) * force
        if damping is not None:
            moved = x - x0
            cdx = damping.product(moved, stiffness=0.0, damping=h)
            value += 0.5 * _dot(moved, cdx)
            grad += cdx
        grad[self.pinned] = 0.0
        return value, grad

    def local_global(self, x, y, x0, h: float, damping=None) -> np.ndarray:
        """One local/global iteration from ``x``: project every spring, then solve."""
        sys = self.system(h)
        rhs = self.mass[:, None] * y + sys.projection(x)       # M y + h² J p
        if damping is not None:
            rhs += sys.damping @ x - damping.product(x - x0, stiffness=0.0, damping=h)
        return self._solve(sys, rhs, x)

    def step(self, x, v, dt: float, t: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """One implicit Euler step of ``dt`` (s) from ``(x, v)`` (both ``(N, d)``, finite)."""
        _validate.finite_real("t", t)
        x0, v = self.check_state(x, v)
        h = _validate.positive_finite("dt", dt)
        free = self._free[:, None]
        y = x0 + free * (h * v + (h * h) * self.external_force(t, x0, v) / self.mass[:, None])
        damping = self.network.linearize(x0) if self.network.c.any() else None
        xk, halvings, trace = y.copy(), 0, []
        if self.memory == 0:
            if self.record:
                trace.append(self.objective(xk, y, x0, h, damping)[0])
            for _ in range(self.iterations):
                xk = self.local_global(xk, y, x0, h, damping)
                if self.record:
                    trace.append(self.objective(xk, y, x0, h, damping)[0])
        else:
            xk, halvings, trace = self._lbfgs(y, x0, h, damping)
        self.info = IterationInfo(self.iterations, halvings, trace)
        return xk, np.where(free, (xk - x0) / h, 0.0)

    def _lbfgs(self, y, x0, h, damping):
        """L-BFGS on ``g`` from ``y``, first Hessian guess ``A`` (two-loop recursion)."""
        sys = self.system(h)
        x = y.copy()
        g, grad = self.objective(x, y, x0, h, damping)
        trace = [g] if self.record else []
        pairs, halvings = [], 0
        for _ in range(self.iterations):
            q, alphas = grad.copy(), []
            for s, z, rho in reversed(pairs):
                a = rho * _dot(s, q)
                q -= a * z
                alphas.append(a)
            r = self._solve(sys, q)
            for (s, z, rho), a in zip(pairs, reversed(alphas), strict=True):
                r += s * (a - rho * _dot(z, r))
            slope = -_dot(grad, r)
            if not slope < 0.0:                      # not a descent direction: restart
                pairs, r = [], self._solve(sys, grad)
                slope = -_dot(grad, r)
            if slope == 0.0:
                break
            step = 1.0
            while True:
                x_new = x - step * r
                g_new, grad_new = self.objective(x_new, y, x0, h, damping)
                if g_new <= g + 1e-4 * step * slope or step < 1e-3:
                    break
                step *= 0.5
                halvings += 1
            s, z = x_new - x, grad_new - grad
            sz = _dot(s, z)
            if sz > 0.0:
                pairs = [*pairs[-(self.memory - 1):], (s, z, 1.0 / sz)] if self.memory > 1 \
                    else [(s, z, 1.0 / sz)]
            x, g, grad = x_new, g_new, grad_new
            if self.record:
                trace.append(g)
        return x, halvings, trace

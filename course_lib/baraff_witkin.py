"""Implicit Euler for spring systems as in Baraff & Witkin (1998), "Large steps in cloth
simulation": one linear solve per step, by conjugate gradients.

Backward Euler asks for the end velocity ``v1 = v0 + Δv`` with ``x1 = x0 + h v1`` and
``M Δv = h F(x1, v1)``. Baraff & Witkin linearize the force about the start of the step,
``F(x1, v1) ≈ F0 + ∂F/∂x (h v1) + ∂F/∂v Δv``, which leaves one *linear* system per step:

    (M - h ∂F/∂v - h² ∂F/∂x) Δv = h (F0 + h ∂F/∂x v0).

For springs ``-∂F/∂v`` and the elastic ``-∂F/∂x`` are symmetric positive semidefinite (we
drop, as they do, the non-symmetric derivative of the damping force with respect to
positions, and with ``definite=True`` the negative geometric stiffness of compressed
springs), so the matrix is symmetric positive definite and conjugate gradients
(``scipy.sparse.linalg.cg``) solve it. We never assemble it: per spring, with
``w = p_i - p_j``, the product is ``A p = M p + Dᵀ[β w + γ (w·d) d]`` (see
:mod:`course_lib.springs.jacobian` for the blocks), a few whole-array operations.

Pinned particles are handled exactly as in the paper's "filtered" solve: with ``S`` the
projection that zeroes pinned particles, we solve ``(S A S + I - S) Δv = S b``, so
``Δv = 0`` there and the other unknowns see the pinned ones as fixed. A particle pinned at
rest never moves. On a linear force (a zero-rest-length spring, or motion along a fixed
spring) the step is backward Euler's, exactly.

Core module: imports NumPy, SciPy, :mod:`course_lib._validate` and
:mod:`course_lib.springs`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from . import _validate
from .springs import SpringNetwork
from .springs.network import sum_rows


@dataclass
class StepInfo:
    """How the linear solve of one step went.

    Attributes
    ----------
    iterations : int
        Conjugate-gradient iterations.
    residual : float
        ``|b - A Δv| / |b|`` at the end (0 when ``b = 0``; NaN if not checked).
    converged : bool
        Whether CG met its tolerance within ``maxiter``.
    """

    iterations: int
    residual: float
    converged: bool


class BaraffWitkin:
    """Baraff–Witkin implicit Euler for a spring network plus constant forces.

    Parameters
    ----------
    network : SpringNetwork
        The springs (with damping ``c`` along them, if any).
    mass : float or array_like, shape (N,)
        Particle masses (kg), > 0.
    pinned : sequence of int, optional
        Particles held fixed: their velocity change is zero, so a pinned particle that
        starts at rest stays exactly where it is.
    gravity : array_like, shape (d,), optional
        Uniform acceleration ``g`` (m/s²): a force ``m g`` on every particle.
    external : callable, optional
        Extra force ``external(t, x, v) -> (N, d)`` (N), taken explicitly (at the start of
        the step; its derivatives are not part of the solve).
    rtol : float
        CG stops when ``|b - A Δv| <= rtol |b|``.
    maxiter : int, optional
        CG iteration cap (default ``10 N d``).
    definite : bool
        Drop the negative geometric stiffness of compressed springs (keeps ``A`` positive
        definite; Choi & Ko 2002). With ``False`` the step is the exact linearization, and
        CG may fail on strongly compressed networks.
    warm_start : bool
        Start CG from a linear extrapolation of the last two steps' ``Δv`` (same ``dt``):
        in a smooth motion it changes little from step to step.
    check : bool
        After the solve, compute the true relative residual ``|b - A Δv| / |b|`` for
        :attr:`info` (one more product with ``A``); ``False`` records NaN.

    Attributes
    ----------
    info : StepInfo or None
        The last step's solve.
    """

    def __init__(self, network: SpringNetwork, mass, *, pinned=None, gravity=None,
                 external: Callable | None = None, rtol: float = 1e-6, maxiter: int | None = None,
                 definite: bool = True, warm_start: bool = True, check: bool = True):
        if not isinstance(network, SpringNetwork):
            raise TypeError(f"network must be a SpringNetwork, got {type(network).__name__}")
        self.network = network
        n = network.n_particles
        m = _validate.state_array("mass", mass)
        if m.ndim > 1 or (m.ndim == 1 and m.shape != (n,)) or np.any(m <= 0):
            raise ValueError(f"mass must be > 0, a scalar or one per particle ({n})")
        self.mass = np.broadcast_to(m, (n,)).astype(float)
        pinned = np.asarray([] if pinned is None else pinned)
        if pinned.size and (not np.issubdtype(pinned.dtype, np.integer)
                            or pinned.min() < 0 or pinned.max() >= n):
            raise ValueError(f"pinned must hold particle indices in [0, {n})")
        self.pinned = np.unique(pinned.astype(np.intp))
        self.gravity = None if gravity is None else _validate.state_array("gravity", gravity)
        if external is not None:
            _validate.callable_arg("external", external)
        self.external = external
        self.rtol = _validate.positive_finite("rtol", rtol)
        self.maxiter = maxiter
        self.definite = bool(definite)
        self.warm_start = bool(warm_start)
        self.check = bool(check)
        self.info: StepInfo | None = None
        self._history: list = []                   # (dt, Δv) of the last two steps
        self._t = 0.0
        self._d: np.ndarray | None = None

    # --- the linear system ------------------------------------------------------------

    def _coefficients(self, x, v, h: float):
        """Force at the start, and the per-slot factors ``β, γ`` of the matrix."""
        net = self.network
        d, inv, a = net.slot_coefficients(x, v)   # per slot of net.layout, d is (dim, S)
        if self._d is None or self._d.shape != d.shape:
            self._d, self._w, self._prod = np.empty_like(d), np.empty_like(d), np.empty_like(d)
            self._along = np.empty(d.shape[1])
        np.copyto(self._d, d)                      # the network's work arrays get reused
        force = -net.slot_sums(np.multiply(a, d, out=self._w))
        stretch = 1.0 - net.slot_rest * inv        # (1 - L/ℓ); 1 where the ends coincide
        if self.definite:
            np.maximum(stretch, 0.0, out=stretch)
        geometric = net.slot_k * stretch           # stiffness across the spring
        along = net.slot_k - geometric             # extra stiffness along it: k L/ℓ
        inv2 = inv * inv
        self._beta = h * h * geometric
        self._gamma = (h * net.slot_c + h * h * along) * inv2
        self._gamma_x = h * h * along * inv2       # the ∂F/∂x part alone, for the right side
        return force

    def _springs_apply(self, p: np.ndarray, gamma: np.ndarray) -> np.ndarray:
        """``Dᵀ[β w + γ (w·d) d]`` with ``w = p_lo - p_hi``: the springs' part of ``A p``."""
        w = self.network.slot_differences(p, out=self._w)   # (dim, S)
        np.multiply(w, self._d, out=self._prod)
        sum_rows(self._prod, out=self._along)     # w·d
        self._along *= gamma
        w *= self._beta
        w += np.multiply(self._d, self._along, out=self._prod)
        return self.network.slot_sums(w)

    def _per_particle(self, dim: int):
        """``(N, dim)`` copies of the masses and of the gravity force (contiguous, so that
        no operation broadcasts along rows of length ``dim``)."""
        if getattr(self, "_dim", None) != dim:
            if self.gravity is not None and self.gravity.shape != (dim,):
                raise ValueError(f"gravity must have shape ({dim},) like the positions' last "
                                 f"axis, got {self.gravity.shape}")
            self._dim = dim
            self._mass = np.repeat(self.mass, dim).reshape(-1, dim)
            g = np.zeros(dim) if self.gravity is None else self.gravity
            self._weight = self._mass * g
        return self._mass, self._weight

    def system(self, x, v, dt: float):
        """The filtered system of one step at ``(x, v)``: ``(A, b, diagonal)``.

        ``A`` is a ``scipy.sparse.linalg.LinearOperator`` of size ``N d``, ``b`` the right
        side (flat), ``diagonal`` the diagonal of ``A`` (for the Jacobi preconditioner).
        """
        x, v = np.asarray(x, dtype=float), np.asarray(v, dtype=float)
        n, dim = x.shape
        h = _validate.positive_finite("dt", dt)
        mass, weight = self._per_particle(dim)
        force = self._coefficients(x, v, h)
        force += weight
        if self.external is not None:
            force += self.external(self._t, x, v)
        pinned = self.pinned
        # b = h F0 + h² ∂F/∂x v0, and ∂F/∂x v0 = -Dᵀ[β' w + γ' (w·d) d] with w = D v0.
        b = h * force - self._springs_apply(v, self._gamma_x)
        b[pinned] = 0.0                            # S b

        def matvec(p_flat):
            p = p_flat.reshape(n, dim)
            if pinned.size:
                p, kept = p.copy(), p[pinned]
                p[pinned] = 0.0                    # S p
            out = self._springs_apply(p, self._gamma)
            out += mass * p
            if pinned.size:
                out[pinned] = kept                 # S A S p + (I - S) p
            return out.ravel()

        along = np.multiply(self._d, self._d, out=self._prod)
        along *= self._gamma
        along += self._beta
        diagonal = mass + self.network.slot_sums(along, same_sign=True)
        diagonal[pinned] = 1.0
        A = spla.LinearOperator((n * dim, n * dim), matvec=matvec, dtype=float)
        return A, b.ravel(), diagonal.ravel()

    # --- one step -------------------------------------------------------------------------

    def step(self, x, v, dt: float, t: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """One implicit step of length ``dt`` (s) from positions ``x`` and velocities ``v``
        (both ``(N, d)``); returns the new ``(x, v)`` and records :attr:`info`."""
        self._t = _validate.finite_real("t", t)
        x = self.network._check("x", x)
        v = self.network._check("v", v)
        A, b, diagonal = self.system(x, v, dt)
        guess = np.zeros_like(b)
        past = [dv for h, dv in self._history if h == dt and dv.shape == b.shape]
        if self.warm_start and past:
            # Δv changes smoothly from step to step: extrapolate the last two (or repeat one).
            guess = 2.0 * past[-1] - past[-2] if len(past) == 2 else past[-1].copy()
            guess.reshape(x.shape)[self.pinned] = 0.0
        iterations = [0]

        def count(_):
            iterations[0] += 1

        precondition = spla.LinearOperator(A.shape, matvec=lambda r: r / diagonal, dtype=float)
        dv, status = spla.cg(A, b, x0=guess, rtol=self.rtol, atol=0.0, M=precondition,
                             maxiter=self.maxiter or 10 * b.size, callback=count)
        residual = np.nan
        if self.check:
            norm_b = np.linalg.norm(b)
            residual = float(np.linalg.norm(b - A @ dv) / norm_b) if norm_b else 0.0
        self.info = StepInfo(iterations[0], residual, status == 0)
        self._history = [*self._history[-1:], (dt, dv)]
        v_new = v + dv.reshape(x.shape)
        return x + dt * v_new, v_new

    def run(self, x0, v0, dt: float, n_steps: int):
        """``n_steps`` steps from ``(x0, v0)``: arrays ``x, v`` of shape ``(n_steps + 1, N, d)``
        and the list of :class:`StepInfo`."""
        xs = np.empty((n_steps + 1, *np.shape(x0)))
        vs = np.empty_like(xs)
        xs[0], vs[0] = x0, v0
        infos = []
        for k in range(n_steps):
            xs[k + 1], vs[k + 1] = self.step(xs[k], vs[k], dt, t=k * dt)
            infos.append(self.info)
        return xs, vs, infos


def baraff_witkin_step(network: SpringNetwork, x, v, dt: float, mass, *, pinned=None,
                       gravity=None, rtol: float = 1e-6, definite: bool = True):
    """One Baraff–Witkin step (see :class:`BaraffWitkin`): returns ``(x1, v1, info)``."""
    solver = BaraffWitkin(network, mass, pinned=pinned, gravity=gravity, rtol=rtol,
                          definite=definite, warm_start=False)
    x1, v1 = solver.step(x, v, dt)
    return x1, v1, solver.info

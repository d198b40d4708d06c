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
(``scipy.sparse.linalg.cg``) solve it. We never assemble it: the network linearized
at the start of the step (:meth:`SpringNetwork.linearize
<course_lib.springs.network.SpringNetwork.linearize>`) gives the force and the products
``h² K p + h C p`` with a few whole-array operations each.

Pinned particles are handled exactly as in the paper's "filtered" solve: with ``S`` the
projection that zeroes pinned particles, we solve ``(S A S + I - S) Δv = S b``, so
``Δv = 0`` there and the other unknowns see the pinned ones as fixed. A particle pinned at
rest never moves. On a linear force (a zero-rest-length spring, or motion along a fixed
spring) the step is backward Euler's, exactly.

Every state and step is checked before any work (shape, finiteness), so a NaN state
fails at once instead of spending CG iterations (:class:`~course_lib.largestep.base.
SpringSolver`).

Core module: imports NumPy, SciPy, :mod:`course_lib._validate`, :mod:`course_lib.springs`
and :mod:`course_lib.largestep.base`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from . import _validate
from .largestep.base import SpringSolver
from .springs import SpringNetwork


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


class BaraffWitkin(SpringSolver):
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
        super().__init__(network, mass, pinned=pinned, gravity=gravity, external=external)
        self.rtol = _validate.positive_finite("rtol", rtol)
        self.maxiter = None if maxiter is None else _validate.positive_int("maxiter", maxiter)
        self.definite = bool(definite)
        self.warm_start = bool(warm_start)
        self.check = bool(check)
        self.info: StepInfo | None = None
        self._history: list = []                   # (dt, Δv) of the last two steps
        self._t = 0.0

    def system(self, x, v, dt: float):
        """The filtered system of one step at ``(x, v)``: ``(A, b, diagonal)``.

        ``A`` is a ``scipy.sparse.linalg.LinearOperator`` of size ``N d``, ``b`` the right
        side (flat), ``diagonal`` the diagonal of ``A`` (for the Jacobi preconditioner).
        """
        x, v = self.check_state(x, v)
        n, dim = x.shape
        h = _validate.positive_finite("dt", dt)
        lin = self.network.linearize(x, v, definite=self.definite)
        force = lin.force + self.external_force(self._t, x, v)
        mass = np.repeat(self.mass, dim).reshape(n, dim)
        pinned = self.pinned
        # b = h F0 + h² ∂F/∂x v0 = h F0 - h² K v0
        b = h * force - lin.product(v, stiffness=h * h)
        b[pinned] = 0.0                            # S b

        def matvec(p_flat):
            p = p_flat.reshape(n, dim)
            if pinned.size:
                p, kept = p.copy(), p[pinned]
                p[pinned] = 0.0                    # S p
            out = lin.product(p, stiffness=h * h, damping=h)
            out += mass * p
            if pinned.size:
                out[pinned] = kept                 # S A S p + (I - S) p
            return out.ravel()

        diagonal = mass + lin.diagonal(stiffness=h * h, damping=h)
        diagonal[pinned] = 1.0
        A = spla.LinearOperator((n * dim, n * dim), matvec=matvec, dtype=float)
        return A, b.ravel(), diagonal.ravel()

    def step(self, x, v, dt: float, t: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """One implicit step of length ``dt`` (s) from positions ``x`` and velocities ``v``
        (both ``(N, d)``, finite); returns the new ``(x, v)`` and records :attr:`info`."""
        self._t = _validate.finite_real("t", t)
        x, v = self.check_state(x, v)
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
        x0 = _validate.positions("x0", x0, self.network.n_particles)
        x0, v0 = self.check_state(x0, _validate.positions("v0", v0, *x0.shape))
        n_steps = _validate.positive_int("n_steps", n_steps)
        _validate.positive_finite("dt", dt)
        xs = np.empty((n_steps + 1, *x0.shape))
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

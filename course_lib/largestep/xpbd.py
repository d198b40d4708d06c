"""Position-based dynamics for springs: PBD (Müller et al. 2007) and XPBD (Macklin, Müller &
Chentanez 2016), with small steps (Macklin et al. 2019) and long range attachments (Kim,
Chentanez & Müller 2012).

A step of length ``h`` first *predicts* every free particle without the springs,
``p = x + h v + h² g``, then corrects ``p`` spring by spring so that each spring's
constraint ``C = |p_i - p_j| - L`` is (nearly) met, and sets ``v = (p - x)/h``.

- **PBD** moves the ends by ``s`` times the full correction, ``Δλ = -s C/(w_i + w_j)``
  (``w = 1/m``). Its stiffness ``s`` has no unit, and more iterations make the same ``s``
  stiffer: the stretch a weight leaves shrinks like ``(1 - s)^n`` with ``n`` iterations.
- **XPBD** gives each spring a *compliance* ``α = 1/k`` (m/N) and keeps a multiplier
  ``λ`` per spring over the iterations of a step:

      Δλ = (-C - α̃ λ - γ u·(d - d₀)) / ((1 + γ)(w_i + w_j) + α̃),   α̃ = α/h²,  γ = α c/h,

  where ``d - d₀`` is how far the spring's vector moved in this step (the ``γ`` term is
  damping along the spring, ``c`` in N s/m). Its fixed point solves ``C + α̃ λ = 0``: the
  spring force ``k C`` of implicit Euler, whatever the number of iterations it took to
  get there. Unconverged, it is softer than ``k``.

The springs are corrected by independent sets (:class:`~.constraints.ColouredSprings`),
Gauss–Seidel over the sets. A sweep moves a correction only a spring or two along the
cloth, so a sheet hanging from its corners holds its weight through some 30 springs only
after many sweeps: unconverged, it is far softer than its springs. Small steps (one step
of length ``h`` is ``substeps`` steps of ``h/substeps``, each with ``iterations`` sweeps)
help most per sweep (Macklin et al. 2019); long range attachments
(:class:`~.attachments.LongRangeAttachments`, ``tethers=``) carry the pull of the pins to
every particle in one operation.

Core module: imports NumPy and the package's :mod:`.base`, :mod:`.constraints` and
:mod:`.attachments`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _validate
from .attachments import LongRangeAttachments
from .base import SpringSolver
from .constraints import TINY, ColouredSprings


def delta_lambda(C, lam, w, compliance, h: float, gamma=0.0, rate=0.0) -> np.ndarray:
    """XPBD's multiplier update (kg m) for constraints ``C`` (m) with multipliers ``lam``.

    ``Δλ = (-C - α̃ λ - γ rate) / ((1 + γ) w + α̃)`` with ``α̃ = compliance/h²``; ``w`` is
    the sum of the inverse masses the constraint moves (1/kg), ``compliance`` ``1/k`` (m/N),
    ``h`` the (small) step (s), ``gamma`` and ``rate`` the damping term (``γ = α c/h`` and
    ``u·(d - d₀)`` for a spring). Arrays broadcast.
    """
    alpha = np.asarray(compliance, dtype=float) / (h * h)
    return (-np.asarray(C, dtype=float) - alpha * lam - gamma * np.asarray(rate, dtype=float)) / (
        (1.0 + np.asarray(gamma, dtype=float)) * w + alpha)


@dataclass
class SweepInfo:
    """What one step did: small steps taken and constraint sweeps in all."""

    substeps: int
    sweeps: int


class XPBD(SpringSolver):
    """Extended position-based dynamics for a spring network (compliance ``1/k``).

    Parameters
    ----------
    network, mass, pinned, gravity, external
        As for :class:`~course_lib.largestep.base.SpringSolver`.
    iterations : int
        Gauss–Seidel sweeps over all springs per small step, >= 1.
    substeps : int
        Small steps per :meth:`step`, >= 1.
    damping : bool
        Use each spring's damping ``c`` (the ``γ`` term); ``False`` ignores it.
    tethers : LongRangeAttachments, optional
        Applied after every sweep (e.g. ``LongRangeAttachments(rest_positions, pinned)``).

    Attributes
    ----------
    info : SweepInfo or None
        The last step.
    """

    def __init__(self, network, mass, *, pinned=None, gravity=None, external=None,
                 iterations: int = 1, substeps: int = 1, damping: bool = True,
                 tethers: LongRangeAttachments | None = None):
        super().__init__(network, mass, pinned=pinned, gravity=gravity, external=external)
        self.iterations = _validate.positive_int("iterations", iterations)
        self.substeps = _validate.positive_int("substeps", substeps)
        self.damping = bool(damping)
        if tethers is not None and not isinstance(tethers, LongRangeAttachments):
            raise TypeError(f"tethers must be LongRangeAttachments or None, got "
                            f"{type(tethers).__name__}")
        if tethers is not None and tethers.n != network.n_particles:
            raise ValueError(f"tethers are for {tethers.n} particles, the network has "
                             f"{network.n_particles}")
        self.tethers = tethers
        self.inverse_mass = np.where(self._free, 1.0 / self.mass, 0.0)
        self.springs = ColouredSprings(network, self.inverse_mass)
        self._h = None
        self._buffers: dict = {}
        self.info: SweepInfo | None = None

    def _constants(self, h: float) -> None:
        """Per set, for small steps of ``h``, the coefficients of :meth:`_rule`: with
        ``α̃ = 1/(k h²)``, ``γ = c/(k h)`` and ``D = 1/((1 + γ) w + α̃)``, ``f = -Δλ/ℓ =
        D (1 + γ) - D L/ℓ - D γ d·d₀/ℓ² + D α̃ λ/ℓ`` (0 in unused slots)."""
        if h == self._h:
            return
        self._h = h
        for q in self.springs.sets:
            k = np.where(q.used, q.k, 1.0)
            alpha = 1.0 / (k * h * h)
            gamma = q.c / (k * h) if self.damping else np.zeros(q.shape)
            den = np.where(q.used, 1.0 / ((1.0 + gamma) * np.where(q.used, q.w, 1.0) + alpha), 0.0)
            q.damped = self.damping and bool(q.c.any())
            q.a, q.b, q.g, q.e = den * (1.0 + gamma), den * q.rest, den * gamma, den * alpha
            # The fused sweep's coefficients already times 1/m of the lo end (both ends where
            # their masses are equal): one product fewer per set.
            q.folded = q.symmetric and self.iterations == 1
            scale = q.wi if q.folded else 1.0
            q.coefficients = (q.a * scale, q.b * scale, q.g * scale)

    def _bound(self, buffer: np.ndarray, start: bool = False) -> list[tuple]:
        """Per set ``(q, pair, work, lo, hi)``: ``pair[0]`` the spring vectors, ``pair[1]``
        those at the start of the small step, and the ends' views in ``buffer``."""
        key = ("bound", id(buffer), buffer.shape[0])
        if key not in self._buffers:
            dim = buffer.shape[0]
            rows = []
            for q, _, work, lo, hi in self.springs.bound(buffer):
                pair_key = ("pair", id(q), dim)
                if pair_key not in self._buffers:
                    self._buffers[pair_key] = np.zeros((2, dim, *q.shape))
                rows.append((q, self._buffers[pair_key], work, lo, hi))
            self._buffers[key] = rows
        return self._buffers[key]

    def _begin(self, start: np.ndarray) -> None:
        """Per small step, before the sweeps: reset the multipliers, note each spring's
        vector ``d₀`` at the start (``start`` is the position buffer)."""
        for q, pair, _, lo, hi in self._bound(start):
            q.lam = np.zeros(q.shape) if self.iterations > 1 else None   # λ = 0: no α̃ λ
            if q.damped:
                q.d0 = pair[1]
                if lo is None:
                    q.difference(start, pair[1])
                else:
                    np.subtract(lo, hi, out=pair[1])

    def _rule(self, q, d, squared):
        """``f = -Δλ/ℓ`` of every slot of one set (:func:`delta_lambda`, rearranged): the
        readable form, for :meth:`ColouredSprings.sweep <.constraints.ColouredSprings.sweep>`;
        :meth:`_sweep` computes the same, fused."""
        inv2 = np.divide(1.0, squared + TINY)                  # 1/ℓ²
        inv = np.sqrt(inv2)
        f = q.a - q.b * inv
        if q.damped:                                            # γ u·(d - d₀) = γ (ℓ - d·d₀/ℓ)
            f -= q.g * np.einsum("k...,k...->...", d, q.d0) * inv2
        if q.lam is not None:                                   # α̃ λ, and λ += Δλ = -f ℓ
            f += q.e * q.lam * inv
            q.lam -= f * squared * inv
        return f

    def _sweep(self, buffer: np.ndarray) -> None:
        """One sweep of :meth:`_rule` over the sets, fused: ``ℓ²`` and ``d·d₀`` in one
        product, the lo end's ``1/m`` folded into the coefficients where both ends weigh
        the same (a cloth's springs away from the pins)."""
        for q, pair, work, lo, hi in self._bound(buffer):
            if lo is None or q.lam is not None:
                d = q.difference(buffer, pair[0])
                q.move(buffer, d, self._rule(q, d, np.einsum("k...,k...->...", d, d)), work)
                continue
            d = np.subtract(lo, hi, out=pair[0])
            if q.damped:
                squared, dd0 = np.einsum("k...,tk...->t...", d, pair)
            else:
                squared = np.einsum("k...,k...->...", d, d)
            a, b, g = q.coefficients
            squared += TINY
            inv2 = np.divide(1.0, squared, out=squared)
            f = a - b * np.sqrt(inv2)
            if q.damped:
                dd0 *= g
                dd0 *= inv2
                f -= dd0
            if q.folded:
                lo -= np.multiply(d, f, out=work)
                hi += work
            else:
                lo -= np.multiply(d, f * q.wi, out=work)
                hi += np.multiply(d, f * q.wj, out=work)

    def _buffer(self, name: str, dim: int) -> np.ndarray:
        key = (name, dim)
        if key not in self._buffers:
            self._buffers[key] = self.springs.buffer(dim)
        return self._buffers[key]

    def step(self, x, v, dt: float, t: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """One step of length ``dt`` (s) from ``(x, v)`` (both ``(N, d)``, finite), taken as
        :attr:`substeps` small steps; returns the new ``(x, v)``."""
        _validate.finite_real("t", t)
        x, v = self.check_state(x, v)
        h = _validate.positive_finite("dt", dt) / self.substeps
        self._constants(h)
        n, dim = x.shape
        P, X = self._buffer("p", dim), self._buffer("x", dim)
        X[:, :n] = x.T
        V = np.where(self._free, v.T, 0.0)
        inv_m = self.inverse_mass
        if self.external is None:                               # h² F/m, constant
            push = (h * h) * self.external_force(t, x, v).T * inv_m
        for k in range(self.substeps):
            if self.external is not None:
                push = (h * h) * inv_m * self.external_force(
                    t + k * h, X[:, :n].T.copy(), V.T.copy()).T
            Pn = P[:, :n]
            np.multiply(V, h, out=Pn)                           # p = x + h v + h² F/m
            Pn += X[:, :n]
            Pn += push
            self._begin(X)
            for _ in range(self.iterations):
                self._sweep(P)
                if self.tethers is not None:
                    self.tethers.project(Pn)
            np.subtract(Pn, X[:, :n], out=V)
            V *= 1.0 / h
            X[:, :n] = Pn
        self.info = SweepInfo(self.substeps, self.substeps * self.iterations)
        return X[:, :n].T.copy(), V.T.copy()


class PBD(XPBD):
    """Plain position-based dynamics: each sweep moves every spring's ends by ``stiffness``
    (in ``(0, 1]``, no unit) times the correction that would restore its rest length.
    The network's ``k`` only selects which springs take part; ``c`` is not used."""

    def __init__(self, network, mass, *, stiffness: float = 1.0, **options):
        s = _validate.positive_finite("stiffness", stiffness)
        if s > 1.0:
            raise ValueError(f"stiffness must lie in (0, 1], got {s}")
        super().__init__(network, mass, damping=False, **options)
        self.stiffness = s

    def _constants(self, h: float) -> None:
        for q in self.springs.sets:
            q.scale = np.where(q.used, self.stiffness / np.where(q.used, q.w, 1.0), 0.0)
            q.b = q.scale * q.rest

    def _begin(self, start: np.ndarray) -> None:
        pass

    def _rule(self, q, d, squared):
        return q.scale - q.b / np.sqrt(squared + TINY)        # s (ℓ - L)/(w ℓ)

    def _sweep(self, buffer: np.ndarray) -> None:
        self.springs.sweep(buffer, self._rule)

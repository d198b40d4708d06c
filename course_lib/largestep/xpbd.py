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
every particle in one operation. (:class:`~.pbd.PBD`, in :mod:`.pbd`, sweeps the same sets
with PBD's rule.)

On a cloth of equal masses a sweep is a dozen whole-array operations per set: the free
ends' ``1/m`` is folded into the coefficients (a pinned end is moved like a free one and
put back), the positions at the start of the small step sit below the current ones in one
array (one subtraction gives every spring's ``d`` and ``d₀``), and a long band of offset 2 is
swept as two strided rows.

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
        self._all_fused = all(self._fused(q) for q in self.springs.sets)
        for q in self.springs.sets:
            q.lam = None                                        # λ = 0 (see _begin)
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
        for key in [key for key in self._buffers if key[0] == "bound"]:
            del self._buffers[key]                  # its rows hold the old coefficients
        for q in self.springs.sets:
            k = np.where(q.used, q.k, 1.0)
            alpha = 1.0 / (k * h * h)
            gamma = q.c / (k * h) if self.damping else np.zeros(q.shape)
            den = np.where(q.used, 1.0 / ((1.0 + gamma) * np.where(q.used, q.w, 1.0) + alpha), 0.0)
            q.damped = self.damping and bool(q.c.any())
            q.a, q.b, q.g, q.e = den * (1.0 + gamma), den * q.rest, den * gamma, den * alpha
            # The fused sweep's coefficients already times the free ends' common 1/m (a
            # cloth of equal masses): one product fewer per set, and a pinned end, moved
            # like a free one, is put back after the set.
            q.folded = q.uniform and self.iterations == 1
            scale = np.maximum(q.wi, q.wj) if q.folded else 1.0
            q.coefficients = (q.a * scale, q.b * scale, q.g * scale)

    def _fused(self, q) -> bool:
        """Whether :meth:`_sweep` treats set ``q`` fused (a band set, one sweep per step)."""
        return q.ends is None and self.iterations == 1

    def _bound(self, buffer: np.ndarray, start: np.ndarray) -> list[tuple]:
        """Rows ``(q, pair, scalars, work, lo, hi, starts, per_slot)`` for sweeps of
        ``buffer`` in a small step that began at ``start``: ``pair[0]`` for the spring
        vectors, ``pair[1]`` for those at the start, two per-slot arrays, a scratch like
        ``pair[0]``, the ends' views in ``buffer`` (``None`` for a gathered set) and, for a
        fused row, ``starts``: the ends' views in ``start`` and ``None``, or the ends' views
        in the stacked ``(buffer, start)`` and ``pair`` as ``(2 dim, …)``. A fused set's
        scratch is a view of arrays shared by all sets (one set at a time uses it, and a
        small working set stays in cache); another set keeps its own ``pair``
        (``pair[1]``, its ``d₀``, lives through the step's sweeps).
        ``per_slot`` holds a fused row's coefficients ``a, b, g`` and ``wi, wj``; a band
        set may take several rows."""
        key = ("bound", id(buffer), id(start), buffer.shape[0])
        if key not in self._buffers:
            dim = buffer.shape[0]
            size = max(q.spring.size for q in self.springs.sets)
            shared = [np.zeros(2 * dim * size), np.zeros(2 * size), np.zeros(dim * size)]
            rows = []
            # ``buffer`` and ``start`` the two halves of one array (as :meth:`step` makes
            # them): one subtraction gives a set's ``d`` and ``d₀`` together.
            both = self._buffers.get(("stacked", dim))
            both = self.springs.bound(both[0]) if both is not None and both[1] is buffer \
                and both[2] is start else [(None,) * 5] * len(self.springs.sets)
            for (q, _, work, lo, hi), (_, _, _, slo, shi), (_, _, _, lo2, hi2) in zip(
                    self.springs.bound(buffer), self.springs.bound(start), both, strict=True):
                if not self._fused(q):
                    own = ("pair", id(q), dim)
                    if own not in self._buffers:
                        self._buffers[own] = (np.zeros((2, dim, *q.shape)), np.zeros((2, *q.shape)))
                    rows.append((q, *self._buffers[own], work, lo, hi, None, None))
                    continue
                # A long band of small offset 1 < o <= 4: one row per residue r < o, each
                # end a 1-D strided view (over the 2-D view an operation would run its
                # inner loop over the short axis of length o).
                a, b, g = q.coefficients
                per_slot = (a, b, g, q.wi, q.wj)
                o, _, blocks, transposed = q.band
                parts = [(r,) for r in range(o)] if transposed and 1 < o <= 4 and blocks >= 128 \
                    else [(slice(None),)]
                for part in parts:
                    shape = q.spring[part].shape
                    m = int(np.prod(shape))
                    at = (slice(None), *part)
                    pair = shared[0][:2 * dim * m].reshape(2, dim, *shape)
                    starts = (slo[at], shi[at], None) if lo2 is None else \
                        (lo2[at], hi2[at], pair.reshape(2 * dim, *shape))
                    rows.append((q, pair, shared[1][:2 * m].reshape(2, *shape),
                                 shared[2][:dim * m].reshape(dim, *shape),
                                 lo[at], hi[at], starts,
                                 tuple(c[part] for c in per_slot)))
            self._buffers[key] = rows
        return self._buffers[key]

    def _begin(self, start: np.ndarray) -> None:
        """Per small step, before the sweeps: reset the multipliers, note where the step
        starts (``start`` is the position buffer; a fused set takes each spring's vector
        ``d₀`` there as it goes, the others store it now)."""
        self._start = start
        if self._all_fused:                     # one sweep, band sets: nothing to reset
            return
        for q in self.springs.sets:
            q.lam = np.zeros(q.shape) if self.iterations > 1 else None   # λ = 0: no α̃ λ
            if q.damped and not self._fused(q):
                key = ("d0", id(q), start.shape[0])
                if key not in self._buffers:
                    self._buffers[key] = np.zeros((start.shape[0], *q.shape))
                q.d0 = q.difference(start, self._buffers[key])

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
        product, the free ends' ``1/m`` folded into the coefficients where the ends weigh
        the same or one is pinned (a cloth of equal masses; the pinned end is put back)."""
        start = self._start
        for q, pair, scalars, work, lo, hi, starts, per_slot in self._bound(buffer, start):
            if per_slot is None:
                d = q.difference(buffer, pair[0])
                q.move(buffer, d, self._rule(q, d, np.einsum("k...,k...->...", d, d)), work)
                continue
            d = pair[0]
            a, b, g, wi, wj = per_slot
            if q.damped:
                if starts[2] is None:                           # d, then d₀ at the start
                    np.subtract(lo, hi, out=d)
                    np.subtract(starts[0], starts[1], out=pair[1])
                else:                                           # both at once
                    np.subtract(starts[0], starts[1], out=starts[2])
                length, t = np.einsum("k...,tk...->t...", d, pair, out=scalars)   # ℓ², d·d₀
                t *= g
            else:
                np.subtract(lo, hi, out=d)
                length, t = np.einsum("k...,k...->...", d, d, out=scalars[0]), scalars[1]
            length += TINY
            np.sqrt(length, out=length)                         # ℓ
            if q.damped:                                        # f = a - (b + g d·d₀/ℓ)/ℓ
                t /= length
                t += b
                t /= length
            else:
                np.divide(b, length, out=t)
            f = np.subtract(a, t, out=t)
            if q.folded:
                lo -= np.multiply(d, f, out=work)
                hi += work
                if q.held.size:                         # pins back where they were
                    buffer[:, q.held_at] = start[:, q.held_at]
            else:
                lo -= np.multiply(d, f * wi, out=work)
                hi += np.multiply(d, f * wj, out=work)

    def _stacked(self, dim: int) -> tuple[np.ndarray, np.ndarray]:
        """The position buffers of a step, ``(P, X)``: the halves of one ``(2 dim, N +
        padding)`` array (made once per ``dim``)."""
        key = ("stacked", dim)
        if key not in self._buffers:
            both = self.springs.buffer(2 * dim)
            self._buffers[key] = (both, both[:dim], both[dim:])
        return self._buffers[key][1:]

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
        P, X = self._stacked(dim)
        Pn, Xn = P[:, :n], X[:, :n]
        Xn[...] = x.T
        D = np.where(self._free, v.T, 0.0) * h                  # h v: how far p moves from x
        inv_m = self.inverse_mass
        if self.external is None:                               # h² F/m, constant
            push = (h * h) * self.external_force(t, x, v).T * inv_m
        for k in range(self.substeps):
            if self.external is not None:
                push = (h * h) * inv_m * self.external_force(
                    t + k * h, Xn.T.copy(), (D / h).T.copy()).T
            np.add(Xn, D, out=Pn)                               # p = x + h v + h² F/m
            Pn += push
            self._begin(X)
            for _ in range(self.iterations):
                self._sweep(P)
                if self.tethers is not None:
                    self.tethers.project(Pn)
            np.subtract(Pn, Xn, out=D)                          # v = (p - x)/h, kept as h v
            Xn[...] = Pn
        self.info = SweepInfo(self.substeps, self.substeps * self.iterations)
        return Xn.T.copy(), (D / h).T.copy()


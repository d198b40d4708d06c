"""Provot's (1995) strain limiting: after a step, shorten every spring stretched too far.

Provot observed that a mass-spring cloth hanging from a few points stretches far more
near them than real cloth does ("super-elastic" springs), and that raising the stiffness
only shrinks the stable step. His fix acts after each step, on positions: every spring
longer than ``(1 + τ) L`` (``τ`` the largest strain, e.g. 0.1 for 10 %) is shortened to
that length by moving its two ends toward each other, in inverse proportion to their
masses (a pinned end does not move). Corrections interact: shortening one spring
stretches its neighbours. So we sweep, spring sets sharing no particle at once
(:class:`~.constraints.ColouredSprings`), until no spring is longer than its limit by more
than a small tolerance, and we check that after every sweep. The velocities take the same
correction divided by the step, ``v += Δx/h``, so the motion the limit removed does not
come back in the next step (Bridson, Fedkiw & Anderson 2002 limit velocities in the same
spirit).

What it guarantees: after :meth:`StrainLimiter.apply` no limited spring's strain exceeds
``τ (1 + tolerance)``, unless ``iterations`` sweeps did not get there (the pins may hold a
cloth farther apart than its limits allow, and then no number of sweeps would); then
:attr:`StrainLimiter.converged` is ``False`` and :attr:`StrainLimiter.last_violation`
says by how much.

The limit is one-sided: compressed springs are left alone. It works with any time
stepper; :func:`course_lib.cloth.simulate` applies it after each step when given
``strain_limit=τ``.

Core module: imports NumPy and the package's :mod:`.constraints`.
"""

from __future__ import annotations

import numpy as np

from .. import _validate
from .base import pinned_indices
from .constraints import TINY, ColouredSprings


class StrainLimiter:
    """Limit the strain ``(ℓ - L)/L`` of the springs of ``network`` to ``max_strain``.

    Parameters
    ----------
    network : SpringNetwork
    mass : float or array_like, shape (N,)
        Particle masses (kg), > 0.
    max_strain : float
        The largest strain allowed, ``τ > 0`` (0.01 is 1 %).
    pinned : sequence of int, optional
        Particles that never move.
    iterations : int
        The most sweeps over all springs per call, >= 1.
    tolerance : float
        Sweeps stop once no spring's strain exceeds ``τ (1 + tolerance)``; >= 0.
    kinds : sequence of str, optional
        Limit only springs of these kinds (e.g. ``("struct", "shear")``); default all.

    Attributes
    ----------
    last_violation : float
        The largest strain beyond ``max_strain`` left after the last call (0 if none).
    sweeps : int
        Sweeps the last call took (0 if no spring was too long).
    converged : bool
        Whether the last call ended with every strain within ``τ (1 + tolerance)``.
    """

    def __init__(self, network, mass, max_strain: float, *, pinned=None, iterations: int = 1000,
                 tolerance: float = 0.01, kinds=None):
        self.max_strain = _validate.positive_finite("max_strain", max_strain)
        self.iterations = _validate.positive_int("iterations", iterations)
        self.tolerance = _validate.finite_real("tolerance", tolerance)
        if self.tolerance < 0:
            raise ValueError(f"tolerance must be >= 0, got {tolerance!r}")
        n = network.n_particles
        m = np.broadcast_to(_validate.state_array("mass", mass), (n,)).astype(float)
        if np.any(m <= 0):
            raise ValueError("mass must be > 0")
        free = np.ones(n, dtype=bool)
        free[pinned_indices(pinned, n)] = False
        select = network.rest > 0
        if kinds is not None:
            select &= np.isin(network.kind, np.atleast_1d(kinds))
        self.network = network
        self.springs = ColouredSprings(network, np.where(free, 1.0 / m, 0.0), select)
        for q in self.springs.sets:
            q.scale = np.where(q.used, 1.0 / np.where(q.used, q.w, 1.0), 0.0)
            q.longest = (1.0 + self.max_strain) * q.rest * q.scale
        limited = np.concatenate([q.spring[q.used] for q in self.springs.sets]).astype(np.intp)
        self._i, self._j = network.i[limited], network.j[limited]
        self._rest = network.rest[limited]
        self._buffers: dict = {}
        self.last_violation, self.sweeps, self.converged = 0.0, 0, True

    @staticmethod
    def _rule(q, d, squared):
        # shorten to the longest length allowed: f = max(ℓ - ℓ_max, 0)/(w ℓ)
        return np.maximum(q.scale - q.longest / np.sqrt(squared + TINY), 0.0)

    def _excess(self, p: np.ndarray) -> float:
        """The largest strain beyond :attr:`max_strain` in component-major positions ``p``."""
        d = p[:, self._i] - p[:, self._j]
        length = np.sqrt(np.einsum("kn,kn->n", d, d))
        return float(np.max(length / self._rest, initial=1.0) - 1.0 - self.max_strain)

    def apply(self, x, v, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Limited positions and velocities (new arrays) after a step of ``dt`` (s) that
        ended at ``(x, v)`` (both ``(N, d)``)."""
        dt = _validate.positive_finite("dt", dt)
        x = np.asarray(x, dtype=float)
        dim = x.shape[1]
        if dim not in self._buffers:
            self._buffers[dim] = self.springs.buffer(dim)
        buffer = self.springs.load(self._buffers[dim], x)
        p = buffer[:, :x.shape[0]]
        allowed = self.tolerance * self.max_strain
        excess, self.sweeps = self._excess(p), 0
        while excess > allowed and self.sweeps < self.iterations:
            self.springs.sweep(buffer, self._rule)
            excess = self._excess(p)
            self.sweeps += 1
        self.last_violation, self.converged = max(excess, 0.0), bool(excess <= allowed)
        p = p.T.copy()
        return p, v + (p - x) / dt

    def violation(self, x) -> float:
        """The largest strain beyond :attr:`max_strain` among the limited springs (0 if none)."""
        return max(self._excess(np.asarray(x, dtype=float).T), 0.0)

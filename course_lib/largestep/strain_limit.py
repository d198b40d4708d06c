"""Provot's (1995) strain limiting: after a step, shorten every spring stretched too far.

Provot observed that a mass-spring cloth hanging from a few points stretches far more
near them than real cloth does ("super-elastic" springs), and that raising the stiffness
only shrinks the stable step. His fix acts after each step, on positions: every spring
longer than ``(1 + τ) L`` (``τ`` the largest strain, e.g. 0.1 for 10 %) is shortened to
that length by moving its two ends toward each other, in inverse proportion to their
masses (a pinned end does not move). Corrections interact, so we sweep several times,
spring sets sharing no particle at once (:class:`~.constraints.ColouredSprings`). The
velocities take the same correction divided by the step, ``v += Δx/h``, so the motion the
limit removed does not come back in the next step (Bridson, Fedkiw & Anderson 2002 limit
velocities in the same spirit).

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
        Sweeps over all springs per call, >= 1.
    kinds : sequence of str, optional
        Limit only springs of these kinds (e.g. ``("struct", "shear")``); default all.

    Attributes
    ----------
    last_violation : float
        The largest strain beyond ``max_strain`` left after the last call (0 if none).
    """

    def __init__(self, network, mass, max_strain: float, *, pinned=None, iterations: int = 8,
                 kinds=None):
        self.max_strain = _validate.positive_finite("max_strain", max_strain)
        self.iterations = _validate.positive_int("iterations", iterations)
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
        self._buffers: dict = {}
        self.last_violation = 0.0

    @staticmethod
    def _rule(q, d, squared):
        # shorten to the longest length allowed: f = max(ℓ - ℓ_max, 0)/(w ℓ)
        return np.maximum(q.scale - q.longest / np.sqrt(squared + TINY), 0.0)

    def apply(self, x, v, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """Limited positions and velocities (new arrays) after a step of ``dt`` (s) that
        ended at ``(x, v)`` (both ``(N, d)``)."""
        dt = _validate.positive_finite("dt", dt)
        x = np.asarray(x, dtype=float)
        dim = x.shape[1]
        if dim not in self._buffers:
            self._buffers[dim] = self.springs.buffer(dim)
        buffer = self.springs.load(self._buffers[dim], x)
        for _ in range(self.iterations):
            self.springs.sweep(buffer, self._rule)
        p = buffer[:, :x.shape[0]].T.copy()
        self.last_violation = self.violation(p)
        return p, v + (p - x) / dt

    def violation(self, x) -> float:
        """The largest strain beyond :attr:`max_strain` among the limited springs (0 if none)."""
        worst = 0.0
        x = np.asarray(x, dtype=float)
        for q in self.springs.sets:
            s = q.spring[q.used]
            length = np.linalg.norm(x[self.network.i[s]] - x[self.network.j[s]], axis=1)
            worst = max(worst, float(np.max(length / q.rest[q.used] - 1.0 - self.max_strain,
                                            initial=0.0)))
        return worst

"""Long range attachments (Kim, Chentanez & Müller 2012): every particle tethered to the pins.

A cloth hanging from a few pins holds its weight through a long path of springs. A
Gauss–Seidel sweep (:mod:`.constraints`) moves a correction only a spring or two along
that path, so with few sweeps per step the cloth hangs as if it were far softer than its
springs. Kim et al. add one *unilateral* constraint from every particle ``q`` to every
pin ``a``: the particle may come as close to the pin as it likes, but no farther than
``s D(q, a)``, with ``D`` the distance between them *along the cloth at rest* (its rest
geodesic distance; on a flat rest sheet that is the straight-line distance) and ``s`` the
tether scale (1: the cloth may not stretch away from its pins at all). The pins never
move, so a tether moves only its particle, straight back onto the sphere of that radius:
all particles at once, one pin after the other, a few whole-array operations per pin.

The tethers bound how far the cloth can stretch away from its pins, not how far each
spring stretches, and with ``s = 1`` they make a cloth that is inextensible away from its
pins, whatever its springs' stiffness: right for a stiff cloth (whose springs stretch a
fraction of a per cent), wrong for a rubber sheet. Game engines expose the same idea as
*tethers* with a stiffness and a stretch limit (PhysX's ``PxClothTetherConfig``, Unreal
Chaos's ``TetherScale``, Unity's ``Cloth.useTethers``).

Core module: imports NumPy and :mod:`.base`.
"""

from __future__ import annotations

import numpy as np

from .. import _validate
from .base import pinned_indices


class LongRangeAttachments:
    """Unilateral tethers ``|x_q - x_a| <= scale D(q, a)`` from every particle to every pin.

    Parameters
    ----------
    rest_positions : array_like, shape (N, d)
        The rest shape (m); ``D`` is the straight-line distance in it unless
        ``distances`` is given.
    pinned : sequence of int
        The pins ``a`` (they never move); none means no tethers.
    scale : float
        Tether length over rest distance, >= 1 (1 + the largest stretch away from the pins).
    distances : array_like, shape (P, N), optional
        Rest distances along the cloth from each pin (m), for a rest shape that is not
        flat (e.g. shortest paths along its springs).

    Attributes
    ----------
    limits : ndarray, shape (P, N)
        ``scale D``; infinite for pinned particles (they never move).
    """

    def __init__(self, rest_positions, pinned, *, scale: float = 1.0, distances=None):
        x = _validate.state_array("rest_positions", rest_positions)
        if x.ndim != 2 or np.iscomplexobj(x):
            raise ValueError(f"rest_positions must be a real array of shape (N, d), got {x.shape}")
        self.n = x.shape[0]
        self.pins = pinned_indices(pinned, self.n)
        self.scale = _validate.positive_finite("scale", scale)
        if self.scale < 1.0:
            raise ValueError(f"scale must be >= 1 (a tether shorter than the rest distance "
                             f"pulls the cloth in), got {self.scale}")
        if distances is None:
            distances = np.linalg.norm(x[None, :, :] - x[self.pins, None, :], axis=-1)
        distances = _validate.state_array("distances", distances)
        if distances.shape != (self.pins.size, self.n) or np.any(distances < 0):
            raise ValueError(f"distances must be >= 0 with shape ({self.pins.size}, {self.n}), "
                             f"got {distances.shape}")
        self.limits = self.scale * distances
        self.limits[:, self.pins] = np.inf
        self._work: dict = {}

    def project(self, p: np.ndarray) -> np.ndarray:
        """Move every particle farther than its limit from a pin back onto it, in place;
        ``p`` is component-major, shape ``(d, N)`` (a view is fine). Returns ``p``."""
        if p.shape[-1] != self.n:
            raise ValueError(f"p must have shape (d, {self.n}), got {p.shape}")
        dim = p.shape[0]
        if dim not in self._work:
            self._work[dim] = (np.empty((dim, self.n)), np.empty((dim, self.n)))
        d, sq = self._work[dim]
        for a, limit in zip(self.pins, self.limits, strict=True):
            np.subtract(p, p[:, a:a + 1], out=d)
            np.multiply(d, d, out=sq)
            dist = np.sqrt(sq.sum(axis=0))
            # the fraction of d to remove: 1 - limit/|d| where |d| > limit, else 0
            excess = np.maximum(dist - limit, 0.0)
            excess /= dist + 1e-300
            d *= excess
            p -= d
        return p

    def excess(self, x) -> float:
        """The largest distance beyond its limit of any particle of ``x`` (N, d) (m; 0 if none)."""
        x = np.asarray(x, dtype=float)
        dist = np.linalg.norm(x[None, :, :] - x[self.pins, None, :], axis=-1)
        return float(np.max(dist - self.limits, initial=0.0))

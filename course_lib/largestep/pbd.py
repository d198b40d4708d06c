"""Plain position-based dynamics (Müller, Heidelberger, Hennix & Ratcliff 2007) for springs.

Each sweep moves the two ends of every spring by ``s`` times the correction that would
restore its rest length, ``Δλ = -s C/(w_i + w_j)``: a stiffness ``s`` without a unit, and
more iterations make the same ``s`` stiffer (the stretch a weight leaves shrinks like
``(1 - s)^n`` after ``n`` iterations). :class:`PBD` shares :class:`~.xpbd.XPBD`'s
prediction, sets and small steps; only the rule of a sweep differs.

Core module: imports NumPy and the package's :mod:`.xpbd` and :mod:`.constraints`.
"""

from __future__ import annotations

import numpy as np

from .. import _validate
from .constraints import TINY
from .xpbd import XPBD


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

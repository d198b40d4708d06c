"""What every spring solver checks and keeps: the network, masses, pins and gravity.

:class:`SpringSolver` validates its arguments once, when a solver is built, and every
state and step length each time a step starts, so that bad input fails at once with a
message naming the argument (a state of the wrong shape, a NaN, a step that is not a
positive number), before any iteration is spent on it. Baraff–Witkin
(:mod:`course_lib.baraff_witkin`), local/global (:mod:`.local_global`) and the
position-based solvers (:mod:`.xpbd`) all build on it.

Core module: imports NumPy, :mod:`course_lib._validate` and :mod:`course_lib.springs`.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .. import _validate
from ..springs import SpringNetwork


def pinned_indices(pinned, n: int) -> np.ndarray:
    """Sorted unique particle indices from ``pinned`` (``None`` for none), each in ``[0, n)``."""
    arr = np.asarray([] if pinned is None else pinned)
    if arr.ndim > 1:
        raise ValueError(f"pinned must be a 1-D list of particle indices, got shape {arr.shape}")
    if arr.size and (not np.issubdtype(arr.dtype, np.integer) or arr.min() < 0 or arr.max() >= n):
        raise ValueError(f"pinned must hold particle indices in [0, {n})")
    return np.unique(arr.astype(np.intp))


class SpringSolver:
    """A time stepper for a :class:`~course_lib.springs.SpringNetwork` plus constant forces.

    Parameters
    ----------
    network : SpringNetwork
        The springs (with damping ``c`` along them, if any).
    mass : float or array_like, shape (N,)
        Particle masses (kg), > 0.
    pinned : sequence of int, optional
        Particles held where they are (their velocity is zero).
    gravity : array_like, shape (d,), optional
        Uniform acceleration (m/s²), a force ``m g`` on every free particle.
    external : callable, optional
        Extra force ``external(t, x, v) -> (N, d)`` (N), taken at the start of a step.
    """

    def __init__(self, network: SpringNetwork, mass, *, pinned=None, gravity=None,
                 external: Callable | None = None):
        if not isinstance(network, SpringNetwork):
            raise TypeError(f"network must be a SpringNetwork, got {type(network).__name__}")
        self.network = network
        n = network.n_particles
        m = _validate.state_array("mass", mass)
        if np.iscomplexobj(m) or m.ndim > 1 or (m.ndim == 1 and m.shape != (n,)) or np.any(m <= 0):
            raise ValueError(f"mass must be > 0, a scalar or one per particle ({n})")
        self.mass = np.broadcast_to(m, (n,)).astype(float)
        self.pinned = pinned_indices(pinned, n)
        self.gravity = None if gravity is None else _validate.vector("gravity", gravity)
        if external is not None:
            _validate.callable_arg("external", external, "(t, x, v)")
        self.external = external
        self._free = np.ones(n, dtype=bool)
        self._free[self.pinned] = False

    def check_state(self, x, v) -> tuple[np.ndarray, np.ndarray]:
        """``x`` and ``v`` as float arrays of shape ``(N, d)``, equal shapes, finite, and
        ``d`` matching gravity; otherwise ``ValueError``/``TypeError`` naming the argument."""
        n = self.network.n_particles
        out = []
        for name, a in (("x", x), ("v", v)):
            a = _validate.state_array(name, a)
            if np.iscomplexobj(a) or a.ndim != 2 or a.shape[0] != n:
                raise ValueError(f"{name} must be a real array of shape ({n}, d), got {a.shape}")
            out.append(a)
        if out[1].shape != out[0].shape:
            raise ValueError(f"v must have the shape of x {out[0].shape}, got {out[1].shape}")
        if self.gravity is not None and self.gravity.shape != (out[0].shape[1],):
            raise ValueError(f"gravity must have shape ({out[0].shape[1]},) like the positions' "
                             f"last axis, got {self.gravity.shape}")
        return out[0], out[1]

    def external_force(self, t: float, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Gravity plus ``external`` at the start of a step, ``(N, d)`` (N); checked finite."""
        f = np.zeros_like(x)
        if self.gravity is not None:
            f += self.mass[:, None] * self.gravity
        if self.external is not None:
            extra = np.asarray(self.external(t, x, v), dtype=float)
            if extra.shape != x.shape or not np.all(np.isfinite(extra)):
                raise ValueError(f"external must return finite forces of shape {x.shape}, got "
                                 f"shape {extra.shape}")
            f += extra
        return f

"""A spring network linearized about a state: its force there and Jacobian–vector products.

An implicit solver needs, at a state ``(x, v)``, the force ``F`` and products of the
matrices ``K = -∂F/∂x`` (elastic stiffness, N/m) and ``C = -∂F/∂v`` (damping, N s/m) with
many vectors ``p`` (one per conjugate-gradient iteration). :meth:`SpringNetwork.linearize
<course_lib.springs.network.SpringNetwork.linearize>` returns a :class:`Linearization`
that computes the per-spring geometry once and then answers

    ``product(p, stiffness=a, damping=b) = (a K + b C) p``

with a few whole-array operations and no matrix: per spring, with ``w = p_i - p_j``,
``d = x_i - x_j`` and ``ℓ = |d|``, the block ``k [u uᵀ + s (I - u uᵀ)]`` of ``K`` (``s =
1 - L/ℓ``, the geometric factor, clipped at 0 with ``definite=True``) and ``c u uᵀ`` of
``C`` act on ``w`` as ``a k s w + (a k (1 - s) + b c) (w·d) d / ℓ²``; the result is added
at ``i`` and subtracted at ``j``. See :mod:`course_lib.springs.jacobian` for the blocks
and the assembled matrices (which the tests compare with).

Core module: imports NumPy and :mod:`course_lib.springs.layout` (the network is passed in).
"""

from __future__ import annotations

import numpy as np

from .layout import sum_rows


class Linearization:
    """The springs of ``network`` linearized about ``(x, v)``.

    Build it with :meth:`SpringNetwork.linearize
    <course_lib.springs.network.SpringNetwork.linearize>`; it keeps its own copies, so
    it stays valid while the network evaluates other states.

    Parameters
    ----------
    network : SpringNetwork
    x : ndarray, shape (N, d)
        Positions (m), checked by the network.
    v : ndarray, shape (N, d), optional
        Velocities (m/s): the damping force enters :attr:`force` only if given.
    definite : bool
        Drop the negative geometric stiffness of compressed springs, so that ``K`` is
        positive semidefinite (Choi & Ko 2002).

    Attributes
    ----------
    force : ndarray, shape (N, d)
        Spring force at ``(x, v)`` (N), a new array.
    """

    def __init__(self, network, x, v=None, *, definite: bool = True):
        self.network = network
        d, inv, a = network.slot_coefficients(x, v)
        self.dim = d.shape[0]
        self._d = d.copy()                          # the network's work arrays get reused
        self.force = -network.slot_sums(np.multiply(a, d))
        stretch = 1.0 - network.slot_rest * inv     # 1 - L/ℓ; 1 where the ends coincide
        if definite:
            np.maximum(stretch, 0.0, out=stretch)
        inv2 = inv * inv
        self._geometric = network.slot_k * stretch  # stiffness across the spring
        self._along = (network.slot_k - self._geometric) * inv2   # k L/ℓ, over ℓ²
        self._damping = network.slot_c * inv2
        self._w = np.empty_like(self._d)
        self._prod = np.empty_like(self._d)
        self._dot = np.empty(self._d.shape[1])
        self._key = None

    def _factors(self, stiffness: float, damping: float):
        key = (float(stiffness), float(damping))
        if key != self._key:
            self._beta = stiffness * self._geometric
            self._gamma = stiffness * self._along + damping * self._damping
            self._key = key
        return self._beta, self._gamma

    def product(self, p, stiffness: float = 1.0, damping: float = 0.0) -> np.ndarray:
        """``(stiffness K + damping C) p`` for per-particle vectors ``p`` of shape ``(N, d)``
        (``stiffness`` in any unit, e.g. s² for ``h² K``; the result is a new ``(N, d)``
        array)."""
        beta, gamma = self._factors(stiffness, damping)
        w = self.network.slot_differences(p, out=self._w)
        if w.shape[0] != self.dim:
            raise ValueError(f"p must have shape (N, {self.dim}) like the linearized state, "
                             f"got {np.shape(p)}")
        np.multiply(w, self._d, out=self._prod)
        sum_rows(self._prod, out=self._dot)          # w·d
        self._dot *= gamma
        w *= beta
        w += np.multiply(self._d, self._dot, out=self._prod)
        return self.network.slot_sums(w)

    def diagonal(self, stiffness: float = 1.0, damping: float = 0.0) -> np.ndarray:
        """The diagonal of ``stiffness K + damping C``, shape ``(N, d)`` (for Jacobi
        preconditioning)."""
        beta, gamma = self._factors(stiffness, damping)
        along = np.multiply(self._d, self._d)
        along *= gamma
        along += beta
        return self.network.slot_sums(along, same_sign=True)

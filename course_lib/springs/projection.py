"""Each spring projected onto its rest length: the local step of constraint solvers.

The closest vector of length ``L`` to a spring's current vector ``d = x_i - x_j`` is
``p = L d/|d|`` (the spring turned neither way, only shortened or lengthened): the
*projection* of the spring. Liu, Bargteil, O'Brien & Kavan (2013) write the spring
energy as ``½ k |d - p|²`` minimized over such ``p``, and alternate this projection
(the *local step*) with a linear solve (the *global step*); position-based dynamics
moves the two ends along ``d`` by the same amount.

- :func:`rest_projection` returns ``p`` per spring (spring order, a new array);
- :class:`Projection` returns the sums the global step needs, ``Σ_s w_s (e_i - e_j) p_s``
  (``+w p`` at ``i``, ``-w p`` at ``j``), for fixed per-spring weights ``w``, fast.

Where the two ends coincide the direction is undefined; we take ``p = 0`` there, like
the force (see :mod:`course_lib.springs.network`).

Core module: imports NumPy and the network's helpers.
"""

from __future__ import annotations

import numpy as np


def rest_projection(network, x) -> np.ndarray:
    """``L_s u_s`` for every spring, ``u_s = (x_i - x_j)/|x_i - x_j|``: shape ``(M, d)`` (m).

    The exact minimizer of ``|(x_i - x_j) - p|`` over vectors ``p`` of length ``L_s``.
    """
    d, inv, _ = network.spring_coefficients(x)
    return d * (network.rest * inv)[:, None]


class Projection:
    """``x -> Σ_s w_s (e_i - e_j) ⊗ L_s u_s(x)``, shape ``(N, d)``, for weights ``w`` (M,).

    With ``w = h² k`` this is the right side ``h² J p`` of Liu et al.'s global step; note
    that ``Σ_s k_s (e_i - e_j)(d_s - p_s)`` is minus the spring force, so the sum equals
    ``F(x) + L x`` with ``L`` the stiffness-weighted graph Laplacian.

    Parameters
    ----------
    network : SpringNetwork
    weights : array_like, shape (M,) or scalar
        Per-spring weights (``k`` gives N/m × m = N).
    """

    def __init__(self, network, weights):
        w = np.broadcast_to(np.asarray(weights, dtype=float), (network.n_springs,))
        self.network = network
        self._scale = network.layout.to_slots(w * network.rest)   # w L per slot; 0 if unused

    def __call__(self, x, out: np.ndarray | None = None) -> np.ndarray:
        """The weighted sum of the projections at positions ``x`` (N, d)."""
        d, inv, _ = self.network.slot_coefficients(x)
        f = np.multiply(d, self._scale * inv)
        return self.network.slot_sums(f, out=out)


def elastic_energy_slots(network, x) -> tuple[float, np.ndarray]:
    """Elastic energy ``Σ ½ k (ℓ - L)²`` (J) and spring forces (N, d) at ``x`` in one pass
    (the lengths are computed once)."""
    d, _inv, a = network.slot_coefficients(x)
    length = network._workspace(d.shape[0]).length
    stretch = length - network.slot_rest
    energy = 0.5 * float(np.einsum("s,s,s->", network.slot_k, stretch, stretch))
    forces = network.slot_sums(np.multiply(a, d))
    return energy, np.negative(forces, out=forces)


"""Damped Hooke springs between particles, the networks built from them, and their
linearization.

- :mod:`~course_lib.springs.network`: :class:`SpringNetwork` (forces, energy, lengths) and
  :func:`spring_force_pair`;
- :mod:`~course_lib.springs.builders`: :func:`chain_pairs`, :func:`hair_chain`,
  :func:`cloth_grid`, :func:`anchored_spring`;
- :mod:`~course_lib.springs.jacobian`: analytic sparse ``∂F/∂x`` and ``∂F/∂v``
  (:func:`jacobian_x`, :func:`jacobian_v`), :func:`stiffness_matrix`,
  :func:`max_frequency`, :func:`newtonian_jacobian` for the implicit integrators;
- :mod:`~course_lib.springs.linearization`: :class:`Linearization`, the force and
  Jacobian–vector products at a state (``SpringNetwork.linearize``);
- :mod:`~course_lib.springs.projection`: :func:`rest_projection` and :class:`Projection`,
  each spring projected onto its rest length (``SpringNetwork.project``);
- :mod:`~course_lib.springs.oscillator`: :func:`critical_damping`,
  :func:`damped_oscillator`.

Core package: imports NumPy, SciPy and other core modules only.
"""

from .builders import anchored_spring, chain_pairs, cloth_grid, hair_chain
from .jacobian import (
    assemble,
    chain_max_frequency,
    jacobian_v,
    jacobian_x,
    max_frequency,
    newtonian_jacobian,
    stiffness_matrix,
)
from .linearization import Linearization
from .network import SpringNetwork
from .oscillator import critical_damping, damped_oscillator
from .pair import spring_force_pair
from .projection import Projection, rest_projection

__all__ = [
    "Linearization",
    "Projection",
    "SpringNetwork",
    "anchored_spring",
    "assemble",
    "chain_max_frequency",
    "chain_pairs",
    "cloth_grid",
    "critical_damping",
    "damped_oscillator",
    "hair_chain",
    "jacobian_v",
    "jacobian_x",
    "max_frequency",
    "newtonian_jacobian",
    "rest_projection",
    "spring_force_pair",
    "stiffness_matrix",
]

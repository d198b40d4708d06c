"""Smoothed particle hydrodynamics (SPH) for liquids: the core of notebook 13.

- :mod:`~course_lib.sph.kernels`: :data:`KERNELS` (cubic spline, poly6, spiky), name ->
  ``W(r, h, dim)`` in 1/m^dim, and their derivatives :data:`GRADIENTS`;
- :mod:`~course_lib.sph.density`: pairs from the shared k-d tree search
  (:func:`course_lib.neighbors.pairs`), density by summation;
- :mod:`~course_lib.sph.forces`: Tait's equation of state, symmetric pressure and
  viscosity forces;
- :mod:`~course_lib.sph.boundary`: walls of particles (Akinci et al. 2012), moving ones
  included (:class:`Gate`, a barrier lifted at a constant speed);
- :mod:`~course_lib.sph.params`: :class:`Params`, the liquid and its solvers' settings;
- :mod:`~course_lib.sph.wcsph` (Becker & Teschner 2007; its acoustic stability limit on
  the lattice) and :mod:`~course_lib.sph.iisph` (Ihmsen et al. 2014; its Jacobi pressure
  solve): one step each, at its CFL step; :mod:`~course_lib.sph.operators`, IISPH's
  pressure operators as sparse matrices;
- :mod:`~course_lib.sph.simulation`: :class:`Simulation` (state, frames, statistics);
- :mod:`~course_lib.sph.scenes`: the water column, the dam break and
  :func:`dam_break` -> ``(T, Z)`` against :data:`MARTIN_MOYCE` (:func:`front_errors`).
"""

from . import boundary, density, forces, iisph, kernels, operators, params, scenes, wcsph
from .boundary import Boundary, Gate
from .kernels import GRADIENTS, KERNELS, SUPPORT
from .params import Params
from .scenes import MARTIN_MOYCE, dam_break, dam_break_simulation, front_errors, ritter_front, water_column
from .simulation import METHODS, Frames, Simulation

__all__ = ["GRADIENTS", "KERNELS", "MARTIN_MOYCE", "METHODS", "SUPPORT", "Boundary", "Frames", "Gate",
           "Params", "Simulation", "boundary", "dam_break", "dam_break_simulation", "density",
           "forces", "front_errors", "iisph", "kernels", "operators", "params", "ritter_front", "scenes",
           "water_column", "wcsph"]

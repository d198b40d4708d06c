"""The parameters of an SPH liquid: its lattice, kernel, viscosity and time-step rules.

:class:`Params` is shared by both solvers (:mod:`~course_lib.sph.wcsph`,
:mod:`~course_lib.sph.iisph`). Particles start on a square lattice of side ``spacing``
(Δx, m); the kernel's support radius is ``support_ratio · Δx`` (2.4 Δx: about 20
neighbours in 2D) and each particle weighs ``ρ₀ V`` with ``V`` the lattice volume that
gives a full lattice the density ``ρ₀`` exactly. Core module.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .boundary import lattice_volume
from .kernels import SUPPORT, check_name

#: How wall particles get their pressure (see :mod:`course_lib.sph.forces`).
WALL_PRESSURES = ("extrapolated", "mirrored")
#: Which velocity a wall particle has in the viscous force (see :mod:`course_lib.sph.forces`).
WALL_VELOCITIES = ("own", "no-slip")


@dataclass(frozen=True)
class Params:
    """An SPH liquid in ``dim`` dimensions and its solvers' settings.

    spacing : lattice side Δx (m). rho0 : rest density (kg/m^dim). kernel : a name of
    :data:`~course_lib.sph.kernels.KERNELS`. support_ratio : support radius / Δx.
    viscosity, wall_viscosity : artificial kinematic viscosity ν (m²/s) between particles
    and against walls. gravity : (dim,) m/s². cfl : the Courant number λ of both step
    rules. sound_speed : c (m/s) of the weakly compressible equation of state (WCSPH
    only). max_dt : a cap on the step (s). tolerance : the mean compression the
    implicit pressure solve stops at (IISPH: 1e-3 is 0.1 %). omega : its relaxation.
    max_iterations : its cap. wall_pressure : ``"extrapolated"`` (Adami et al. 2012)
    or ``"mirrored"`` (a wall particle takes the fluid particle's pressure).
    wall_velocity : the wall particles' velocity in the viscous force, ``"own"`` (their
    own: zero for a fixed wall) or ``"no-slip"`` (Adami et al. 2012: ``2 v_w - ṽ``, the
    fluid's velocity near the wall mirrored).
    speed_limit : a run whose fastest particle passes it (m/s) has blown up and stops.
    """

    spacing: float
    rho0: float = 1000.0
    kernel: str = "cubic"
    support_ratio: float = 2.4
    viscosity: float = 0.0
    wall_viscosity: float = 0.0
    gravity: tuple[float, ...] = (0.0, -9.81)
    cfl: float = 0.4
    sound_speed: float = 0.0
    max_dt: float = np.inf
    tolerance: float = 1e-3
    omega: float = 0.5
    max_iterations: int = 500
    wall_pressure: str = "extrapolated"
    wall_velocity: str = "own"
    speed_limit: float = np.inf

    def __post_init__(self):
        check_name(self.kernel)
        for name in ("spacing", "rho0", "support_ratio", "cfl", "tolerance"):
            value = getattr(self, name)
            if not (isinstance(value, numbers.Real) and np.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
        for name in ("max_dt", "speed_limit"):          # inf means no limit
            value = getattr(self, name)
            if not (isinstance(value, numbers.Real) and value > 0 and not np.isnan(value)):
                raise ValueError(f"{name} must be a number > 0 (inf for no limit), got {value!r}")
        for name in ("viscosity", "wall_viscosity", "sound_speed"):
            value = getattr(self, name)
            if not (isinstance(value, numbers.Real) and np.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
        if self.wall_pressure not in WALL_PRESSURES:
            raise ValueError(f"unknown wall_pressure {self.wall_pressure!r}; valid choices are: "
                             f"{', '.join(WALL_PRESSURES)}")
        if self.wall_velocity not in WALL_VELOCITIES:
            raise ValueError(f"unknown wall_velocity {self.wall_velocity!r}; valid choices are: "
                             f"{', '.join(WALL_VELOCITIES)}")
        if not 0 < self.omega <= 1:
            raise ValueError(f"omega must lie in (0, 1], got {self.omega!r}")
        if not (isinstance(self.max_iterations, int) and self.max_iterations >= 1):
            raise ValueError(f"max_iterations must be an int >= 1, got {self.max_iterations!r}")
        g = np.asarray(self.gravity, dtype=float)
        if g.ndim != 1 or g.size not in (1, 2, 3) or not np.all(np.isfinite(g)):
            raise ValueError(f"gravity must be a finite vector of 1 to 3 components, got {self.gravity!r}")

    @property
    def dim(self) -> int:
        """Number of space dimensions (from ``gravity``)."""
        return len(self.gravity)

    @property
    def h(self) -> float:
        """The kernel's own h (m): the support radius over :data:`SUPPORT`."""
        return self.support_ratio * self.spacing / SUPPORT[self.kernel]

    @property
    def support(self) -> float:
        """The support radius (m)."""
        return self.support_ratio * self.spacing

    @cached_property
    def mass(self) -> float:
        """Mass of one particle (kg): ``ρ₀`` times the lattice volume."""
        return self.rho0 * lattice_volume(self.spacing, self.h, self.kernel, self.dim)

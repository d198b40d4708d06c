"""Notebook 05 (Newton's second law): the falling apple and the energy of symplectic methods.

Pure scenes built on the core (:mod:`course_lib.integrators`, :mod:`course_lib.systems`,
:mod:`course_lib.events`); the core never imports this module.
"""

from __future__ import annotations

import numpy as np

from .. import forces
from ..integrators import Trajectory, integrate
from ..systems import newtonian, stack_state

G_STD = 9.81  #: standard gravity (m/s²)


# --- notebook 05: the apple ---------------------------------------------------------------


def apple_drop(method: str, dt: float = 0.1, h0: float = 10.0, g: float = G_STD,
               t_end: float = 2.0) -> Trajectory:
    """An apple (1 kg) released at rest at height ``h0`` under constant gravity, in 2D.

    The state is ``y = (x, v)`` of shape ``(2, 1, 2)``; the height is ``y[:, 0, 0, 1]``.
    """
    system = newtonian(forces.constant_gravity(1.0, g=[0.0, -g]), mass=1.0)
    y0 = stack_state([[0.0, h0]], [[0.0, 0.0]])
    return integrate(system, y0, (0.0, t_end), dt, method)


def euler_apple_height(n, dt: float = 0.1, h0: float = 10.0, g: float = G_STD):
    """Closed form of forward Euler's height after ``n`` steps: ``h0 - g dt² n(n-1)/2``."""
    n = np.asarray(n, dtype=float)
    return h0 - g * dt**2 * n * (n - 1) / 2


def symplectic_apple_height(n, dt: float = 0.1, h0: float = 10.0, g: float = G_STD):
    """Closed form of symplectic Euler's height after ``n`` steps: ``h0 - g dt² n(n+1)/2``."""
    n = np.asarray(n, dtype=float)
    return h0 - g * dt**2 * n * (n + 1) / 2


# --- notebook 05: energy of the oscillator ---------------------------------------------


def symplectic_modified_energy(y, omega: float, dt: float):
    """``½ v² + ½ ω² x² - ½ dt ω² x v``: conserved exactly by symplectic Euler on
    ``x'' = -ω² x`` (states ``(..., 2)`` in the layout ``(x, v)``)."""
    y = np.asarray(y)
    x, v = y[..., 0], y[..., 1]
    return 0.5 * v**2 + 0.5 * omega**2 * x**2 - 0.5 * dt * omega**2 * x * v


def verlet_modified_energy(y, omega: float, dt: float):
    """``½ v² + ½ ω² (1 - ω² dt²/4) x²``: conserved exactly by velocity Verlet on
    ``x'' = -ω² x``."""
    y = np.asarray(y)
    x, v = y[..., 0], y[..., 1]
    return 0.5 * v**2 + 0.5 * omega**2 * (1.0 - 0.25 * (omega * dt) ** 2) * x**2

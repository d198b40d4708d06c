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


# --- notebook 05: the phase error of symplectic methods ----------------------------------


def discrete_frequency(omega: float, dt: float) -> float:
    """Angular frequency (rad/s) of symplectic Euler and velocity Verlet on ``x'' = -ω² x``:
    both step matrices have determinant 1 and trace ``2 - ω² dt²``, so their eigenvalues are
    ``e^{±i ω̃ dt}`` with ``cos ω̃ dt = 1 - ω² dt² / 2`` (for ``ω dt < 2``)."""
    return float(np.arccos(1.0 - 0.5 * (omega * dt) ** 2) / dt)


def phase_error(t, y, omega: float = 1.0):
    """Phase (rad) of an oscillator run ``y = (x, v)`` (shape ``(n, 2)``) minus the exact
    ``ω t`` of ``x0 cos ω t``: positive when the run is ahead. The phase is the angle of
    ``(x, -v/ω)``, unwrapped."""
    y = np.asarray(y, dtype=float)
    return np.unwrap(np.arctan2(-y[:, 1] / omega, y[:, 0])) - omega * np.asarray(t)


# --- notebook 05: the position (Störmer) form of Verlet -----------------------------------


def stormer_verlet(accel, x0, v0, dt: float, n_steps: int, start: str = "taylor"):
    """Positions of Störmer's (position) form of Verlet, ``x_{k+1} = 2 x_k - x_{k-1} + dt² a(x_k)``,
    started with the Taylor step ``x_1 = x0 + dt v0 + dt²/2 a(x0)`` (``start="euler"``:
    the usual slip ``x_1 = x0 + dt v0``). Returns the positions, shape ``(n+1, ...)``.

    No velocities are stored; they can be recovered as ``(x_{k+1} - x_{k-1}) / 2 dt``.
    """
    x = np.empty((n_steps + 1, *np.shape(x0)))
    x[0] = x0
    x[1] = x[0] + dt * np.asarray(v0) + (0.5 * dt**2 * accel(x[0]) if start == "taylor" else 0.0)
    for k in range(1, n_steps):
        x[k + 1] = 2.0 * x[k] - x[k - 1] + dt**2 * accel(x[k])
    return x


# --- notebook 05: orders measured without an exact solution ------------------------------


def pendulum(g_over_l: float = 9.81):
    """``f(t, y)`` of the pendulum ``θ'' = -(g/L) sin θ``, ``y = (θ, θ')`` of shape (2,):
    no elementary closed-form solution."""

    def f(t, y):
        return np.array([y[1], -g_over_l * np.sin(y[0])])

    return f


def reference_run(f, y0, t1: float, n_steps: int = 20000):
    """State at ``t1`` from RK4 with ``n_steps`` steps: a stand-in for the exact solution,
    far more accurate than the runs it judges."""
    return integrate(f, y0, (0.0, t1), t1 / n_steps, "rk4").y[-1]


def step_errors(method: str, dts, f=None, y0=(1.0, 0.0), t1: float = 2.0):
    """Local (one step from ``y0``) and global (at ``t1``) errors of ``method`` for each
    step in ``dts``, against :func:`reference_run`. Returns two arrays."""
    from ..integrators import step

    f = pendulum() if f is None else f
    y0 = np.asarray(y0, dtype=float)
    y_end = reference_run(f, y0, t1)
    local = [np.linalg.norm(step(method, f, 0.0, y0, h) - reference_run(f, y0, h, 200))
             for h in dts]
    glob = [np.linalg.norm(integrate(f, y0, (0.0, t1), h, method).y[-1] - y_end) for h in dts]
    return np.array(local), np.array(glob)


def three_grid_order(run, dt: float):
    """Order ``p`` and error of the finest run, from three runs ``run(dt)``, ``run(dt/2)``,
    ``run(dt/4)`` and nothing else: with ``y_h ≈ y + C h^p``,
    ``|y_h - y_{h/2}| / |y_{h/2} - y_{h/4}| ≈ 2^p``, and the finest run is off by about
    ``|y_{h/2} - y_{h/4}| / (2^p - 1)``. Returns ``(p, error)``."""
    coarse, middle, fine = (np.asarray(run(h), dtype=float) for h in (dt, dt / 2, dt / 4))
    d1, d2 = np.linalg.norm(coarse - middle), np.linalg.norm(middle - fine)
    p = float(np.log2(d1 / d2))
    return p, float(d2 / (2.0**p - 1.0))

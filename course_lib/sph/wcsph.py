"""Weakly compressible SPH (WCSPH) after Becker & Teschner (2007).

One step: neighbours, density by summation, pressure from Tait's equation of state
(:func:`~course_lib.sph.forces.tait_pressure`), then gravity, viscosity and the
symmetric pressure force, and a symplectic Euler update ``v += Δt a``, ``x += Δt v``.

The liquid is made stiff enough that its density varies by about 1 %: a speed of sound
``c`` ten times the largest flow speed (Mach 0.1; ``ρ/ρ₀ - 1 ≈ M²/2``). Sound must not
cross more than a fraction of a kernel per step, so the step obeys the CFL condition

    Δt ≤ λ h / (c + |v|max)   and   Δt ≤ λ √(h / |a|max),   λ = 0.4,

which is what makes WCSPH expensive: ``c`` and not the flow sets the step
(:func:`cfl_step`). Core module.
"""

from __future__ import annotations

import numpy as np

from .density import Neighbourhood, neighbourhood, summation_density
from .forces import pressure_acceleration, tait_pressure, viscosity_acceleration, wall_pressure
from .params import Params


def cfl_step(params: Params, v_max: float, a_max: float) -> float:
    """Becker & Teschner's step (s) for the largest speed ``v_max`` (m/s) and acceleration
    ``a_max`` (m/s²), capped at ``params.max_dt``."""
    if not params.sound_speed > 0:
        raise ValueError("WCSPH needs params.sound_speed > 0 (m/s)")
    dt = params.cfl * params.h / (params.sound_speed + v_max)
    if a_max > 0:
        dt = min(dt, params.cfl * np.sqrt(params.h / a_max))
    return float(min(dt, params.max_dt))


def accelerations(nb: Neighbourhood, params: Params, v: np.ndarray, wall=None):
    """Density (N,), pressure (N,) and total acceleration (N, dim) of the configuration
    ``nb`` with velocities ``v``."""
    psi = None if wall is None else wall.psi
    rho = summation_density(nb, params.mass, psi)
    p = tait_pressure(rho, params.rho0, params.sound_speed)
    p_wall = None
    if wall is not None and params.wall_pressure == "extrapolated":
        p_wall = wall_pressure(nb, p, rho, params.gravity, wall.n)
    a = pressure_acceleration(nb, params.mass, rho, p, psi, p_wall, params.rho0)
    a += viscosity_acceleration(nb, params.mass, rho, v, params.viscosity,
                                params.wall_viscosity, psi)
    a += np.asarray(params.gravity, dtype=float)
    return rho, p, a


def step(x: np.ndarray, v: np.ndarray, params: Params, wall=None, dt: float | None = None,
         dt_max: float = np.inf):
    """One WCSPH step from positions ``x`` and velocities ``v`` (N, dim).

    ``dt=None`` takes :func:`cfl_step`, at most ``dt_max``. Returns ``(x, v, info)`` with the new state and
    ``info`` holding ``dt``, ``rho`` and ``p`` (the density and pressure at the start of
    the step) and ``pairs``.
    """
    nb = neighbourhood(x, params.h, params.kernel, wall)
    rho, p, a = accelerations(nb, params, v, wall)
    if dt is None:
        v_max = float(np.sqrt(np.max(np.einsum("nk,nk->n", v, v), initial=0.0)))
        a_max = float(np.sqrt(np.max(np.einsum("nk,nk->n", a, a), initial=0.0)))
        dt = min(cfl_step(params, v_max, a_max), dt_max)
    v = v + dt * a
    return x + dt * v, v, {"dt": dt, "rho": rho, "p": p, "pairs": nb.n_pairs, "iterations": 0}

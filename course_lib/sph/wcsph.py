"""Weakly compressible SPH (WCSPH) after Becker & Teschner (2007), and its step.

One step (:func:`step`): neighbours, density by summation, pressure from Tait's equation
of state (:func:`~course_lib.sph.forces.tait_pressure`), then gravity, viscosity and the
symmetric pressure force, and a symplectic Euler update ``v += Δt a``, ``x += Δt v``.

The liquid is made stiff enough that its density varies by about 1 %: a speed of sound
``c`` ten times the largest flow speed (Mach 0.1; ``ρ/ρ₀ - 1 ≈ M²/2``). Sound then sets
the step. Linearised about a lattice at rest, a plane wave ``e^{ik·x}`` of the particles
oscillates at ``ω(k) = c |g(k)|`` with ``g(k) = Σ_j V ∇W(x_ij) sin(k·x_ij)`` over the lattice
neighbours (``V`` the lattice volume): the kernel smooths the shortest waves away, so
``ω`` peaks at a wavelength of a few spacings, ``ω_max ≈ 0.89 c/Δx`` for our cubic spline
with support ``2.4 Δx`` (:func:`acoustic_limit`). Symplectic Euler is stable for
``ω Δt ≤ 2``, so sound may cross at most ``2/(Δx max|g|) ≈ 2.2`` spacings per step. We step
at the Courant number ``λ`` (0.4, as Becker & Teschner, a wide margin):

    Δt ≤ λ Δx / (c + |v|max)   and   Δt ≤ λ √(Δx / |a|max),

measured in the lattice spacing ``Δx`` as IISPH's step is (:func:`cfl_step`). Core module.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize

from .boundary import lattice_volume
from .density import Neighbourhood, neighbourhood, summation_density
from .forces import (
    pressure_acceleration,
    tait_pressure,
    viscosity_acceleration,
    viscous_wall_velocity,
    wall_pressure,
)
from .kernels import gradient
from .params import Params


def cfl_step(params: Params, v_max: float, a_max: float) -> float:
    """The step (s) for the largest speed ``v_max`` (m/s) and acceleration ``a_max`` (m/s²):
    ``λ Δx / (c + v_max)`` and ``λ √(Δx / a_max)``, capped at ``params.max_dt``."""
    if not params.sound_speed > 0:
        raise ValueError("WCSPH needs params.sound_speed > 0 (m/s)")
    dt = params.cfl * params.spacing / (params.sound_speed + v_max)
    if a_max > 0:
        dt = min(dt, params.cfl * np.sqrt(params.spacing / a_max))
    return float(min(dt, params.max_dt))


def lattice_gradient(params: Params, k) -> np.ndarray:
    """``g(k) = Σ_j V ∇W(x_j) sin(k·x_j)`` (1/m) over the square lattice's points ``x_j ≠ 0``
    within the support, for wave vectors ``k`` (..., 2) in rad/m; returns (..., 2)."""
    dx, h = params.spacing, params.h
    reach = int(np.ceil(params.support / dx))
    axis = np.arange(-reach, reach + 1) * dx
    x = np.stack(np.meshgrid(axis, axis, indexing="ij"), axis=-1).reshape(-1, 2)
    r = np.linalg.norm(x, axis=1)
    x, r = x[(r > 0) & (r < params.support)], r[(r > 0) & (r < params.support)]
    weight = lattice_volume(dx, h, params.kernel, 2) * gradient(params.kernel, x, r, h)
    return np.sin(np.asarray(k, dtype=float) @ x.T) @ weight


def acoustic_limit(params: Params) -> tuple[float, np.ndarray]:
    """The largest stable acoustic Courant number ``c Δt / Δx = 2 / (Δx max_k |g(k)|)`` of
    symplectic Euler on the 2D lattice at rest, and the wave vector (rad/m, (2,)) of the
    fastest mode. ``max|g|`` by a grid over ``k ∈ [0, π/Δx]²``, refined by Nelder-Mead."""
    if params.dim != 2:
        raise ValueError(f"acoustic_limit is for 2D lattices, got dim = {params.dim}")
    grid = np.linspace(0.0, np.pi / params.spacing, 65)
    k = np.stack(np.meshgrid(grid, grid, indexing="ij"), axis=-1).reshape(-1, 2)
    size = np.linalg.norm(lattice_gradient(params, k), axis=1)
    best = minimize(lambda q: -np.linalg.norm(lattice_gradient(params, q)), k[np.argmax(size)],
                    method="Nelder-Mead", options={"xatol": 1e-10 / params.spacing, "fatol": 1e-14})
    return 2.0 / (params.spacing * -best.fun), best.x


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
                                params.wall_viscosity, psi, viscous_wall_velocity(nb, params, v, wall))
    a += np.asarray(params.gravity, dtype=float)
    return rho, p, a


def step(x: np.ndarray, v: np.ndarray, params: Params, wall=None, dt: float | None = None,
         dt_max: float = np.inf):
    """One WCSPH step from positions ``x`` and velocities ``v`` (N, dim).

    ``dt=None`` takes :func:`cfl_step`, at most ``dt_max``. Returns ``(x, v, info)`` with the
    new state and ``info`` holding ``dt``, ``rho`` and ``p`` (the density and pressure at the
    start of the step) and ``pairs``.
    """
    nb = neighbourhood(x, params.h, params.kernel, wall)
    rho, p, a = accelerations(nb, params, v, wall)
    if dt is None:
        v_max = float(np.sqrt(np.max(np.einsum("nk,nk->n", v, v), initial=0.0)))
        a_max = float(np.sqrt(np.max(np.einsum("nk,nk->n", a, a), initial=0.0)))
        dt = min(cfl_step(params, v_max, a_max), dt_max)
    v = v + dt * a
    return x + dt * v, v, {"dt": dt, "rho": rho, "p": p, "pairs": nb.n_pairs, "iterations": 0}

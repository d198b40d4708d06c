"""Implicit incompressible SPH (IISPH) after Ihmsen et al. (2014): large steps.

Instead of a stiff equation of state, IISPH solves for the pressures that make the
density at the end of the step equal ``ρ₀``. With the non-pressure accelerations
(gravity, viscosity) the velocities are first predicted, ``v* = v + Δt a_np``, and the
continuity equation predicts the density they lead to,

    ρ*_i = ρ_i + Δt [Σ_j m_j (v*_i - v*_j)·∇W_ij + Σ_k ψ_k v*_i·∇W_ik].

The pressure accelerations ``a^p(p)`` (:func:`~course_lib.sph.forces.pressure_acceleration`)
change it by ``(A p)_i = Δt² [Σ_j m_j (a^p_i - a^p_j)·∇W_ij + Σ_k ψ_k a^p_i·∇W_ik]``, so the
pressures solve the linear system ``A p = ρ₀ - ρ*``, with ``p ≥ 0`` (a free surface cannot
pull). It is solved by relaxed Jacobi, ``p ← max(0, p + ω (ρ₀ - ρ* - A p)/a_ii)`` with
``ω = 1/2``, starting from half the last step's pressures, until the mean compression is
below a tolerance (0.1 %). ``a_ii``, the diagonal of ``A``, is

    a_ii = Δt² [D_i·G_i - (m_i/ρ_i²) Σ_j m_j |∇W_ij|²],   G_i = Σ_j m_j ∇W_ij + Σ_k ψ_k ∇W_ik,

with ``D_i = ∂a^p_i/∂p_i`` (the wall pressures take a share of ``p_i``, see
:func:`~course_lib.sph.forces.wall_pressure`).

Since the pressure no longer comes from a speed of sound, the step follows the flow,
``Δt = λ Δx / |v|max`` (:func:`cfl_step`). Core module.
"""

from __future__ import annotations

import numpy as np

from .density import neighbourhood, scatter, summation_density
from .forces import viscosity_acceleration
from .operators import PressureOperator
from .params import Params


def cfl_step(params: Params, v_max: float, a_max: float) -> float:
    """The step (s) for the largest speed ``v_max`` (m/s) and non-pressure acceleration
    ``a_max`` (m/s²): ``λ Δx / v_max`` and ``λ √(Δx / a_max)``, capped at ``max_dt``."""
    dt = params.max_dt
    if v_max > 0:
        dt = min(dt, params.cfl * params.spacing / v_max)
    if a_max > 0:
        dt = min(dt, params.cfl * np.sqrt(params.spacing / a_max))
    if not np.isfinite(dt):
        raise ValueError("at rest without gravity the step is unbounded: set params.max_dt")
    return float(dt)


def solve_pressure(op: PressureOperator, params: Params, rho_star, dt: float, grad2, p0=None):
    """Relaxed Jacobi for ``A p = ρ₀ - ρ*``, ``p ≥ 0``, with ``A = Δt² div(a^p(·))`` of the
    operator ``op``. Returns ``(p, iterations, compression)``: the pressures (Pa), the
    sweeps taken and the predicted mean compression ``mean(max(ρ* + A p - ρ₀, 0))/ρ₀``
    of the last sweep; ``grad2`` (N,) is ``m_i Σ_j m_j |∇W_ij|²``."""
    a_ii = op.diagonal(dt, grad2)
    active = a_ii < 0.0                    # an isolated particle has no equation
    source = params.rho0 - rho_star
    p = np.zeros(op.n) if p0 is None else np.where(active, 0.5 * np.asarray(p0, dtype=float), 0.0)
    step_size = np.where(active, params.omega / np.where(active, a_ii, -1.0), 0.0)
    compression = np.inf
    for sweep in range(1, params.max_iterations + 1):
        residual = source - dt * dt * op.divergence(op.accel(p))
        compression = float(np.mean(np.maximum(-residual, 0.0))) / params.rho0
        p = np.maximum(p + step_size * residual, 0.0)
        if compression <= params.tolerance and sweep >= 2:
            break
    return p, sweep, compression


def step(x: np.ndarray, v: np.ndarray, params: Params, wall=None, dt: float | None = None,
         dt_max: float = np.inf, p_last=None):
    """One IISPH step from positions ``x`` and velocities ``v`` (N, dim); ``p_last`` the
    previous step's pressures (a warm start). ``dt=None`` takes :func:`cfl_step`, at most ``dt_max``.

    Returns ``(x, v, info)``: ``info`` holds ``dt``, ``rho`` (density at the start of the
    step), ``p`` (the pressures solved for), ``iterations``, ``compression`` and ``pairs``.
    """
    psi = None if wall is None else wall.psi
    nb = neighbourhood(x, params.h, params.kernel, wall)
    m = np.broadcast_to(np.asarray(params.mass, dtype=float), (nb.n,))
    rho = summation_density(nb, m, psi)
    a_np = viscosity_acceleration(nb, m, rho, v, params.viscosity, params.wall_viscosity, psi)
    a_np += np.asarray(params.gravity, dtype=float)
    if dt is None:
        v_max = float(np.sqrt(np.max(np.einsum("nk,nk->n", v, v), initial=0.0)))
        a_max = float(np.sqrt(np.max(np.einsum("nk,nk->n", a_np, a_np), initial=0.0)))
        dt = min(cfl_step(params, v_max, a_max), dt_max)
    op = PressureOperator(nb, m, rho, psi, params.gravity, params.rho0, params.wall_pressure)
    v_star = v + dt * a_np
    rho_star = rho + dt * op.divergence(v_star)
    g2 = np.einsum("pk,pk->p", nb.gw, nb.gw)
    grad2 = m * scatter(nb.i, nb.j, m[nb.j] * g2, nb.n, m[nb.i] * g2)
    p, iterations, compression = solve_pressure(op, params, rho_star, dt, grad2, p_last)
    v = v_star + dt * op.accel(p)
    return x + dt * v, v, {"dt": dt, "rho": rho, "p": p, "iterations": iterations,
                           "compression": compression, "pairs": nb.n_pairs}

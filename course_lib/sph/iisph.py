"""Implicit incompressible SPH (IISPH) after Ihmsen et al. (2014): large steps.

Instead of a stiff equation of state, IISPH solves for the pressures that make the
density at the end of the step equal ``ρ₀``. With the non-pressure accelerations
(gravity, viscosity) the velocities are first predicted, ``v* = v + Δt a_np``, and the
continuity equation predicts the density they lead to,

    ρ*_i = ρ_i + Δt [Σ_j m_j (v*_i - v*_j)·∇W_ij + Σ_k ψ_k (v*_i - v_k)·∇W_ik]

(``v_k`` the wall particles' velocities, zero unless a wall moves).

The pressure accelerations ``a^p(p)`` (:func:`~course_lib.sph.forces.pressure_acceleration`)
change it by ``(A p)_i = Δt² [Σ_j m_j (a^p_i - a^p_j)·∇W_ij + Σ_k ψ_k a^p_i·∇W_ik]``, so the
pressures solve the linear system ``A p = ρ₀ - ρ*``, with ``p ≥ 0`` (a free surface cannot
pull). :func:`jacobi` solves it by relaxed Jacobi, ``p ← max(0, p + ω (ρ₀ - ρ* - A p)/a_ii)``
with ``ω = 1/2``, starting from half the last step's pressures, until the mean predicted
compression ``mean(max(ρ* + A p - ρ₀, 0))/ρ₀`` is below a tolerance (0.1 %). ``a_ii``, the
diagonal of ``A`` (:meth:`~course_lib.sph.operators.PressureOperator.diagonal`), is negative:
raising ``p_i`` pushes the neighbours away and lowers ``ρ_i``, so a compressed particle
(``ρ* > ρ₀``) gets a higher pressure.

The prediction is first order in ``Δt``: the pairs, and the gradients on them, are those
at the start of the step, so the density reached differs from the one solved for by
``O(Δt²)``. The flow, not sound, sets the step, ``Δt = λ Δx / |v|max`` (:func:`cfl_step`),
and ``λ`` must stay small enough that particles move a fraction of a spacing. Core module.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .density import neighbourhood, summation_density
from .forces import viscosity_acceleration, viscous_wall_velocity
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


def jacobi(apply_A: Callable[[np.ndarray], np.ndarray], a_ii: np.ndarray, source: np.ndarray,
           p0: np.ndarray, rho0: float, omega: float = 0.5, tolerance: float = 1e-3,
           max_sweeps: int = 500) -> tuple[np.ndarray, int]:
    """Relaxed Jacobi for ``A p = source`` with ``p ≥ 0``: returns ``(p, sweeps)``.

    ``apply_A(p)`` (N,) -> (N,) is the operator, ``a_ii`` (N,) its diagonal (negative; a
    particle with ``a_ii ≥ 0`` has no neighbours and keeps ``p = 0``), ``source`` (N,) is
    ``ρ₀ - ρ*`` (kg/m^dim), ``p0`` (N,) the start (Pa). Each sweep computes the residual
    ``r = source - A p``, then ``p ← max(0, p + ω r / a_ii)``; it stops after the sweep whose
    residual gives a mean compression ``mean(max(-r, 0))/ρ₀ ≤ tolerance``.
    """
    active = a_ii < 0.0
    step = np.divide(omega, a_ii, out=np.zeros_like(a_ii, dtype=float), where=active)
    p = np.where(active, p0, 0.0)
    for sweep in range(1, max_sweeps + 1):  # noqa: B007 (the count is returned)
        residual = source - apply_A(p)
        compression = np.mean(np.maximum(-residual, 0.0)) / rho0
        p = np.maximum(p + step * residual, 0.0)
        if compression <= tolerance:
            break
    return p, sweep


def step(x: np.ndarray, v: np.ndarray, params: Params, wall=None, dt: float | None = None,
         dt_max: float = np.inf, p_last=None):
    """One IISPH step from positions ``x`` and velocities ``v`` (N, dim); ``p_last`` the
    previous step's pressures (a warm start from half of them). ``dt=None`` takes
    :func:`cfl_step`, at most ``dt_max``.

    Returns ``(x, v, info)``: ``info`` holds ``dt``, ``rho`` (density at the start of the
    step), ``p`` (the pressures solved for), ``iterations`` (Jacobi sweeps), ``predicted``
    (the density ``ρ* + A p`` the pressures lead to, to first order) and ``pairs``.
    """
    psi = None if wall is None else wall.psi
    nb = neighbourhood(x, params.h, params.kernel, wall)
    m = params.mass
    rho = summation_density(nb, m, psi)
    v_wall = None if wall is None or not wall.moving else wall.v
    a_np = viscosity_acceleration(nb, m, rho, v, params.viscosity, params.wall_viscosity, psi,
                                  viscous_wall_velocity(nb, params, v, wall))
    a_np += np.asarray(params.gravity, dtype=float)
    if dt is None:
        v_max = float(np.sqrt(np.max(np.einsum("nk,nk->n", v, v), initial=0.0)))
        a_max = float(np.sqrt(np.max(np.einsum("nk,nk->n", a_np, a_np), initial=0.0)))
        dt = min(cfl_step(params, v_max, a_max), dt_max)
    op = PressureOperator(nb, m, rho, psi, params.gravity, params.rho0, params.wall_pressure)
    v_star = v + dt * a_np
    rho_star = rho + dt * op.divergence(v_star)
    if v_wall is not None:                  # a moving wall particle k: v*_i - v_k in its term
        rho_star -= dt * op.wall_flux(v_wall)

    def apply_A(p):
        return dt * dt * op.divergence(op.accel(p))

    p0 = np.zeros(nb.n) if p_last is None else 0.5 * np.asarray(p_last, dtype=float)
    p, sweeps = jacobi(apply_A, op.diagonal(dt), params.rho0 - rho_star, p0, params.rho0,
                       params.omega, params.tolerance, params.max_iterations)
    v = v_star + dt * op.accel(p)
    return x + dt * v, v, {"dt": dt, "rho": rho, "p": p, "iterations": sweeps,
                           "predicted": rho_star + apply_A(p), "pairs": nb.n_pairs}

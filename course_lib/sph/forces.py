"""Pressure and viscosity in SPH: the equation of state and symmetric pair forces.

- :func:`tait_pressure`: the weakly compressible equation of state of Becker & Teschner
  (2007), ``p = B ((ρ/ρ₀)^γ - 1)`` with ``B = ρ₀ c²/γ`` and ``γ = 7``, negative values
  clamped to 0 (a free surface must not pull).
- :func:`pressure_acceleration`: ``a_i = -Σ_j m_j (p_i/ρ_i² + p_j/ρ_j²) ∇_i W_ij``
  (Monaghan 1992), and the same sum over the wall particles near ``i``, weighted by
  their ``ψ_k`` (Akinci et al. 2012), with wall pressures extrapolated from the fluid
  (:func:`wall_pressure`, Adami et al. 2012). Pair ``(i, j)`` pushes ``i`` by
  ``m_i m_j (...) ∇W_ij`` and ``j`` by exactly the opposite, because ``∇_j W_ji = -∇_i W_ij``
  and the bracket is symmetric: momentum is conserved to round-off.
- :func:`viscosity_acceleration`: an artificial viscosity of kinematic viscosity ``ν``
  (Monaghan 2005): ``a_i = 2(d+2) ν Σ_j (m_j/ρ̄_ij) (v_ij·x_ij)/(r² + 0.01 h²) ∇_i W_ij``,
  symmetric in the pair like the pressure force; against the wall particles (velocities
  ``v_k``, 0 for a fixed wall) with its own ``ν_w`` (0: free slip). For a stricter
  no-slip wall, :func:`no_slip_velocity` gives them Adami et al.'s (2012) velocities
  ``2 v_w - ṽ_k``, the fluid's velocity near the wall mirrored about the wall's.

Accelerations are ``(N, dim)`` in m/s². Core module: NumPy only.
"""

from __future__ import annotations

import numpy as np

from .density import Neighbourhood, scatter, wall_sum

#: Tait's exponent for water (Becker & Teschner 2007).
TAIT_GAMMA = 7.0


def tait_pressure(rho, rho0: float, c: float, gamma: float = TAIT_GAMMA) -> np.ndarray:
    """``max(0, B ((ρ/ρ₀)^γ - 1))`` (Pa) with ``B = ρ₀ c²/γ``; ``c`` the speed of sound
    (m/s), ``rho`` (kg/m^dim) any shape."""
    rho = np.asarray(rho, dtype=float)
    stiffness = rho0 * c * c / gamma
    return np.maximum(stiffness * ((rho / rho0) ** gamma - 1.0), 0.0)


def wall_pressure(nb: Neighbourhood, p, rho, gravity, n_wall: int) -> np.ndarray:
    """Pressures (Pa, (K,)) of the wall particles, extrapolated from the fluid after Adami
    et al. (2012): ``p_k = Σ_i (p_i + ρ_i g·(x_k - x_i)) W_ik / Σ_i W_ik`` (0 where no
    fluid is near; not clamped, so that it stays linear in ``p``). The hydrostatic term
    lets a fluid particle by the wall feel the whole pressure gradient, as one in the bulk
    does."""
    p, rho = np.asarray(p, dtype=float), np.asarray(rho, dtype=float)
    if not len(nb.bi):
        return np.zeros(n_wall)
    head = -rho[nb.bi] * (nb.bd @ np.asarray(gravity, dtype=float))       # ρ g·(x_k - x_i)
    top = np.bincount(nb.bk, (p[nb.bi] + head) * nb.bw, minlength=n_wall)
    bottom = np.bincount(nb.bk, nb.bw, minlength=n_wall)
    return np.divide(top, bottom, out=np.zeros(n_wall), where=bottom > 0)


def no_slip_velocity(nb: Neighbourhood, v, v_wall=None, n_wall: int | None = None) -> np.ndarray:
    """Wall-particle velocities (K, dim) for a no-slip wall after Adami et al. (2012):
    ``2 v_w,k - ṽ_k`` with ``ṽ_k = Σ_i v_i W_ik / Σ_i W_ik`` the fluid's velocity smoothed
    at wall particle ``k`` (``v_w,k`` where no fluid is near). ``v`` (N, dim) m/s;
    ``v_wall`` (K, dim) the walls' own velocities (None: at rest, then ``n_wall`` = K)."""
    v = np.asarray(v, dtype=float)
    n_wall = len(v_wall) if v_wall is not None else int(n_wall)
    own = np.zeros((n_wall, v.shape[1])) if v_wall is None else np.asarray(v_wall, dtype=float)
    bottom = np.bincount(nb.bk, nb.bw, minlength=n_wall)
    near = bottom > 0
    out = own.copy()
    for k in range(v.shape[1]):
        smooth = np.bincount(nb.bk, v[nb.bi, k] * nb.bw, minlength=n_wall)
        out[near, k] = 2.0 * own[near, k] - smooth[near] / bottom[near]
    return out


def viscous_wall_velocity(nb: Neighbourhood, params, v, wall) -> np.ndarray | None:
    """The wall particles' velocities (K, dim) in the viscous force under
    ``params.wall_velocity``: their own (None for walls at rest) or :func:`no_slip_velocity`."""
    if wall is None:
        return None
    own = wall.v if wall.moving else None
    if params.wall_velocity == "no-slip":
        return no_slip_velocity(nb, v, own, wall.n)
    return own


def pressure_acceleration(nb: Neighbourhood, mass, rho, p, psi=None, p_wall=None,
                          rho0: float = 1000.0) -> np.ndarray:
    """The symmetric SPH pressure acceleration (m/s², (N, dim)) of every fluid particle.

    ``mass`` scalar or (N,) (kg), ``rho`` (N,), ``p`` (N,) (Pa), ``psi`` (K,) wall weights
    (kg). Wall particle ``k`` enters as a particle of mass ``ψ_k``, density ``rho0`` and
    pressure ``p_wall[k]`` (:func:`wall_pressure`); ``p_wall=None`` mirrors instead
    (``p_k = p_i``, ``ρ_k = ρ_i``: the wall term becomes ``-2 ψ_k p_i/ρ_i² ∇W_ik``).
    """
    m = np.broadcast_to(np.asarray(mass, dtype=float), (nb.n,))
    over = np.asarray(p, dtype=float) / np.asarray(rho, dtype=float) ** 2
    pair = -(over[nb.i] + over[nb.j])[:, None] * nb.gw            # per unit m_i m_j
    a = scatter(nb.i, nb.j, pair * m[nb.j, None], nb.n, -pair * m[nb.i, None])
    if len(nb.bi):
        wall_over = over[nb.bi] if p_wall is None else np.asarray(p_wall)[nb.bk] / rho0**2
        weight = -np.asarray(psi, dtype=float)[nb.bk] * (over[nb.bi] + wall_over)
        a += wall_sum(nb, weight[:, None] * nb.bgw)
    return a


def viscosity_acceleration(nb: Neighbourhood, mass, rho, v, nu: float,
                           nu_wall: float = 0.0, psi=None, v_wall=None) -> np.ndarray:
    """Artificial viscosity (m/s², (N, dim)) of kinematic viscosity ``nu`` (m²/s) between
    fluid particles and ``nu_wall`` against the walls; ``v`` (N, dim) in m/s, ``v_wall``
    (K, dim) the wall particles' velocities (None: at rest)."""
    v = np.asarray(v, dtype=float)
    dim = v.shape[1]
    m = np.broadcast_to(np.asarray(mass, dtype=float), (nb.n,))
    rho = np.asarray(rho, dtype=float)
    eps = 0.01 * nb.h * nb.h
    a = np.zeros_like(v)
    if nu:
        vd = np.einsum("pk,pk->p", v[nb.i] - v[nb.j], nb.d)
        coef = 2 * (dim + 2) * nu * vd / (nb.r**2 + eps) * 2.0 / (rho[nb.i] + rho[nb.j])
        pair = coef[:, None] * nb.gw
        a += scatter(nb.i, nb.j, pair * m[nb.j, None], nb.n, -pair * m[nb.i, None])
    if nu_wall and len(nb.bi):
        rel = v[nb.bi] if v_wall is None else v[nb.bi] - np.asarray(v_wall, dtype=float)[nb.bk]
        vd = np.einsum("pk,pk->p", rel, nb.bd)
        coef = 2 * (dim + 2) * nu_wall * vd / (nb.br**2 + eps) / rho[nb.bi]
        a += wall_sum(nb, (coef * np.asarray(psi, dtype=float)[nb.bk])[:, None] * nb.bgw)
    return a

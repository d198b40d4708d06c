"""Case data of notebook 13's checks of IISPH's Jacobi solve and of the front's validation.

- :func:`jacobi_cases`: the pressure systems :func:`course_lib.check.nb13.jacobi` runs (the
  system of a real IISPH step, cold and warm started, and a small hand-made one whose
  solution needs the clamp ``p ≥ 0`` and has a particle without neighbours), and
  :func:`jacobi_variant`, the solve as the usual mistakes write it;
- :func:`front_cases`: runs' fronts for :func:`course_lib.check.nb13.front_errors` (uneven
  steps, a column of 2.25 in, a table that is not Martin & Moyce's) and
  :func:`front_variant`, what the usual mistakes make of them.

Imports NumPy and :mod:`course_lib.sph` (to build a real pressure system).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from ..sph import density, scenes
from ..sph.forces import viscosity_acceleration
from ..sph.operators import PressureOperator

_SEED = 1313


@cache
def _iisph_system() -> tuple:
    """The operator matrix, diagonal and source of IISPH's pressure solve for a 8 × 16
    column 0.1 s after its release, with an 8 ms step (dense, so that the check hands over
    plain NumPy)."""
    sim = scenes.dam_break_simulation(128, "iisph")
    sim.run(0.1)                                   # a collapsing column, not one at rest
    prm, wall = sim.params, sim.wall
    nb = density.neighbourhood(sim.x, prm.h, prm.kernel, wall)
    rho = density.summation_density(nb, prm.mass, wall.psi)
    dt = 8e-3
    op = PressureOperator(nb, prm.mass, rho, wall.psi, prm.gravity, prm.rho0)
    a_np = np.asarray(prm.gravity) + viscosity_acceleration(nb, prm.mass, rho, sim.v, prm.viscosity,
                                                            prm.wall_viscosity, wall.psi)
    rho_star = rho + dt * op.divergence(sim.v + dt * a_np)
    offset = dt * dt * op.divergence(op.accel(np.zeros(sim.n)))       # the walls' hydrostatic part
    A = np.stack([dt * dt * op.divergence(op.accel(e)) for e in np.eye(sim.n)], axis=1)
    A -= offset[:, None]
    return A, op.diagonal(dt), prm.rho0 - rho_star - offset, prm.rho0


def _hand_made() -> tuple:
    """A chain of 9 'particles' (negative diagonal, as IISPH's), one of them without
    neighbours (zero row and column), sources of both signs: the solution needs ``p ≥ 0``."""
    n = 9
    A = np.zeros((n, n))
    for k in range(n - 1):
        if 4 in (k, k + 1):
            continue
        A[k, k] -= 3.0
        A[k + 1, k + 1] -= 3.0
        A[k, k + 1] += 1.0
        A[k + 1, k] += 1.0
    source = np.array([-6.0, -2.0, 1.5, -4.0, 0.0, 2.0, -5.0, -1.0, 3.0])
    return A, np.diag(A).copy(), source, 1000.0


def jacobi_cases() -> list[tuple]:
    """``(what, A, a_ii, source, p0, rho0, omega, tolerance, max_sweeps)`` for each case."""
    A, diag, source, rho0 = _iisph_system()
    cold = np.zeros(len(diag))
    warm = 0.5 * jacobi_variant(A, diag, source, cold, rho0, 0.5, 1e-4, 500)[0]   # as IISPH does
    H, hdiag, hsource, hrho0 = _hand_made()
    return [
        ("IISPH's system of a collapsing 8 × 16 column, from p = 0", A, diag, source, cold,
         rho0, 0.5, 1e-4, 500),
        ("the same system from half its solution, ω = 0.6", A, diag, source, warm, rho0, 0.6,
         1e-4, 500),
        ("a chain of 9 with a particle that has no neighbours", H, hdiag, hsource,
         np.zeros(9), hrho0, 0.5, 1e-6, 500),
        ("the chain, stopped by max_sweeps = 4", H, hdiag, hsource, np.zeros(9), hrho0, 0.5,
         1e-12, 4),
    ]


def jacobi_variant(A, a_ii, source, p0, rho0, omega, tolerance, max_sweeps, *, clamp=True,
                   relax=True, test="compression", order="before", first=1, sign=1.0):
    """The solve with one usual mistake: no clamp, no relaxation (ω = 1), a stopping test on
    the mean ``|r|`` (``test="residual"``), the test on the residual after the update
    (``order="after"``), sweeps counted from 0 (``first=0``) or the update's sign flipped
    (``sign=-1``)."""
    active = a_ii < 0
    step = sign * np.divide(omega if relax else 1.0, a_ii, out=np.zeros(len(a_ii)), where=active)
    p = np.where(active, p0, 0.0)
    for sweep in range(1, max_sweeps + 1):  # noqa: B007 (the count is returned)
        r = source - A @ p
        p = p + step * r
        if clamp:
            p = np.maximum(p, 0.0)
        if order == "after":
            r = source - A @ p
        measure = np.mean(np.abs(r)) if test == "residual" else np.mean(np.maximum(-r, 0.0))
        if measure / rho0 <= tolerance:
            break
    return p, sweep - 1 + first


def front_cases() -> list[tuple]:
    """``(what, t, z, a, table, delay)``: fronts ``z`` (m) at uneven times ``t`` (s)."""
    rng = np.random.default_rng(_SEED)
    out = []
    for what, a, delay, n, table in (
            ("a column of a = 2.25 in, uneven steps, Martin & Moyce's table", 0.05715, 0.0, 400,
             scenes.MARTIN_MOYCE),
            ("the same run delayed by ΔT = 0.175", 0.05715, 0.175, 400, scenes.MARTIN_MOYCE),
            ("a = 1 m, 40 coarse steps, another table", 1.0, 0.1, 40,
             np.array([[2.9, 3.6], [0.7, 1.2], [1.6, 2.0], [3.4, 4.3], [2.2, 2.7]]))):
        T_end = 3.6
        steps = rng.uniform(0.5, 1.5, n)
        t = np.concatenate([[0.0], np.cumsum(steps)]) * T_end / steps.sum() * np.sqrt(a / (2 * 9.81))
        T = t * np.sqrt(2 * 9.81 / a)
        z = a * (1.0 + 0.05 * T + 0.32 * T**2 - 0.045 * T**3)        # starts slow, as a column does
        out.append((what, t, z, a, np.array(table, dtype=float), delay))
    return out


def front_variant(t, z, a, table, delay, *, g=9.81, time="2g/a", origin="wall", sign=-1.0,
                  relative="run", sample="linear"):
    """The front's errors with one usual mistake: ``time="g/a"`` (T = t√(g/a)), ``g``,
    ``origin="face"`` (Z = (z − a)/a), ``sign=+1`` (the delay added), ``relative="table"``
    (relative to the run) or ``"difference"``, ``sample="nearest"``."""
    T = t * np.sqrt((2.0 if time == "2g/a" else 1.0) * g / a)
    Z = (z - a) / a if origin == "face" else z / a
    at = table[:, 0] + sign * delay
    if sample == "nearest":
        run = Z[np.abs(T[None, :] - at[:, None]).argmin(axis=1)]
    else:
        run = np.interp(at, T, Z)
    if relative == "table":
        return table[:, 1] / run - 1.0
    if relative == "difference":
        return run - table[:, 1]
    return run / table[:, 1] - 1.0

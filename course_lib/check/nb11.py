"""Checks for notebook 11, cloth: one spring's Jacobian block, and the explicit step limit."""

from __future__ import annotations

import numpy as np

from .. import cloth, springs
from . import Checker, exercise

_SEED = 1111


def _spring_cases():
    rng = np.random.default_rng(_SEED)
    yield "a stretched spring", rng.normal(size=3), 50.0, 0.4
    yield "a compressed spring", rng.normal(size=3), 120.0, 3.0
    for n in range(2):
        yield f"a random spring ({n + 1})", rng.normal(size=3), float(rng.uniform(10, 500)), 1.0


@exercise
def spring_jacobian(ck: Checker, func) -> None:
    """``func(xi, xj, k, rest) -> (3, 3)``: ``∂F_i/∂x_i`` of one Hooke spring."""
    rng = np.random.default_rng(_SEED + 1)
    for what, d, k, rest in _spring_cases():
        xj = rng.normal(size=3)
        xi = xj + d
        net = springs.SpringNetwork([0], [1], [rest], [k], [0.0], 2)
        expected = springs.jacobian_x(net, np.stack((xi, xj))).toarray()[:3, :3]
        length = np.linalg.norm(d)
        u = d / length
        uu, side = np.outer(u, u), np.eye(3) - np.outer(u, u)
        mistakes = {
            "sign: moving x_i away from x_j along the spring makes F_i pull back harder, so "
            "∂F_i/∂x_i = -k[...] is negative along u": -expected,
            "you kept only the stiffness along the spring: a stretched spring also pulls a "
            "sideways displacement back, add (1 - L/ℓ)(I - u uᵀ)": -k * uu,
            "the sideways factor is (1 - L/ℓ), not L/ℓ": -k * (uu + rest / length * side),
            "the sideways factor is the dimensionless (1 - L/ℓ), not ℓ - L":
                -k * (uu + (length - rest) * side),
            "use the unit vector u = d/|d| in u uᵀ, not d itself":
                -k * (np.outer(d, d) + (1 - rest / length) * side),
        }
        got = np.asarray(func(xi.copy(), xj.copy(), k, rest), dtype=float)
        ck.close(got, expected, f"{what}: ℓ = {length:.3f} m, L = {rest:g} m, k = {k:g} N/m",
                 rtol=1e-9, atol=1e-9, mistakes=mistakes)
    # against central differences of the force
    xi, xj, k, rest = np.array([0.3, -0.2, 0.9]), np.array([-0.1, 0.4, 0.2]), 80.0, 0.5
    h = 1e-6
    fd = np.stack([(springs.spring_force_pair(xi + h * e, xj, k, rest)
                    - springs.spring_force_pair(xi - h * e, xj, k, rest)) / (2 * h) for e in np.eye(3)],
                  axis=1)
    got = np.asarray(func(xi.copy(), xj.copy(), k, rest), dtype=float)
    ck.close(got, fd, "matches central differences of the force", rtol=1e-6, atol=1e-6)
    ck.close(got, got.T, "symmetric", rtol=1e-12, atol=1e-12,
             hint="each term, u uᵀ and I - u uᵀ, is symmetric")


def _limit_cases():
    rng = np.random.default_rng(_SEED + 2)
    c = cloth.sheet(n=5, size=0.3, total_mass=0.02, k_struct=200.0)
    yield "5 × 5 cloth, equal masses", c, c.mass
    yield "5 × 5 cloth, masses from 0.3 to 3 g", c, rng.uniform(3e-4, 3e-3, c.n)
    x0, strand = springs.hair_chain(n=8, length=0.2, k_edge=900.0, k_bend=30.0)
    chain = cloth.Cloth(x0, strand, np.full(8, 1e-3), np.array([0]), (1, 8))
    yield "8-particle strand, root pinned, masses from 0.5 to 2 g", chain, rng.uniform(5e-4, 2e-3, 8)


@exercise
def explicit_limit(ck: Checker, func) -> None:
    """``func(K, mass) -> dt_max``: symplectic Euler's limit from a stiffness matrix."""
    for what, c, mass in _limit_cases():
        free = np.setdiff1d(np.arange(c.n), c.pinned)
        dofs = (free[:, None] * 3 + np.arange(3)).ravel()
        K = springs.stiffness_matrix(c.network, c.x0)[np.ix_(dofs, dofs)]
        m = mass[free]
        expected = 2.0 / springs.max_frequency(c.network, c.x0, mass, c.pinned)
        m3 = np.repeat(m, 3)
        lam = np.linalg.eigvalsh(K / np.sqrt(np.outer(m3, m3)))
        tiled = np.tile(m, 3)
        mistakes = {
            "include the masses: the frequencies solve K φ = ω² M φ, so use M^(-1/2) K M^(-1/2)":
                2.0 / np.sqrt(np.linalg.eigvalsh(K).max()),
            "with unequal masses one mass will not do: scale each row and column of K by "
            "1/√m of its own particle": 2.0 / np.sqrt(np.linalg.eigvalsh(K).max() / m.mean()),
            "the eigenvalues are ω², so take a square root: dt_max = 2/√λ_max": 2.0 / lam.max(),
            "symplectic Euler is stable for ω dt < 2: dt_max = 2/ω_max, not 1/ω_max":
                1.0 / np.sqrt(lam.max()),
            "each particle owns three rows in a row (x, y, z): np.repeat(mass, 3), not np.tile":
                2.0 / np.sqrt(np.linalg.eigvalsh(K / np.sqrt(np.outer(tiled, tiled))).max()),
        }
        got = func(K.copy(), m.copy())
        ck.close(got, expected, f"{what}: {K.shape[0]} unknowns", rtol=1e-8, mistakes=mistakes,
                 hint="the fastest mode sets the limit: the largest eigenvalue λ_max of "
                      "M^(-1/2) K M^(-1/2) is ω_max²")

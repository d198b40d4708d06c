"""Notebook 11 (cloth): the scenes and studies behind the notebook.

Holds the notebook's cloth (:func:`hanging`: 12 × 12 particles, 0.55 m, 0.1 kg, two
corners pinned) and the drape over a sphere (:func:`drape`); the checks of the
Baraff–Witkin ingredients (:func:`jacobian_check` against central differences,
:func:`damping_ratios` on a single spring, :func:`condition_numbers` and the CG bound
:func:`cg_bound`); the cloth at rest (:func:`rest_state`, an energy minimum found
independently of any run); the stretch of structural springs (:func:`strains`); and the
study of when large steps pay (:func:`large_steps`: cost and stretch against stiffness).
Built on :mod:`course_lib.cloth`, :mod:`course_lib.springs` and
:mod:`course_lib.baraff_witkin`; the drawings are in :mod:`course_lib.lessons.nb11_drawings`.
The core never imports this module.
"""

from __future__ import annotations

import time

import numpy as np

from .. import cloth, collisions, springs
from ..baraff_witkin import BaraffWitkin

#: The hanging cloth of the notebook (see :func:`course_lib.cloth.sheet`).
CLOTH = {"n": 12, "size": 0.55, "total_mass": 0.1, "k_struct": 300.0}
#: The drape: a 20 × 20 cloth of 0.9 m and 0.15 kg at y = 0.4 m, 0.15 m above the top of a
#: 0.25 m sphere centred at the origin and resting on the ground.
SPHERE_RADIUS, DRAPE_HEIGHT = 0.25, 0.4


def hanging(**changes) -> cloth.Cloth:
    """The notebook's cloth, optionally with some parameters changed."""
    return cloth.sheet(**{**CLOTH, **changes})


def frequency_and_limit(c: cloth.Cloth, x=None) -> tuple[float, float]:
    """``ω_max`` (rad/s) of the cloth about ``x`` (default: its rest shape) and the
    symplectic Euler limit ``2/ω_max`` (s)."""
    omega = springs.max_frequency(c.network, c.x0 if x is None else x, c.mass, c.pinned)
    return omega, 2.0 / omega


def jacobian_check(c: cloth.Cloth, seed: int = 2026, jiggle: float = 0.01, h: float = 1e-6):
    """Compare the analytic ``∂F/∂x`` with central differences of the forces at a randomly
    deformed state (every particle moved by ``jiggle`` m at random, normal). Returns the
    largest difference, the largest entry (both N/m) and the largest asymmetry of
    ``∂F/∂x`` and of ``∂F/∂v`` (the latter for the cloth with damping 0.01 N s/m)."""
    rng = np.random.default_rng(seed)
    x = c.x0 + jiggle * rng.normal(size=c.x0.shape)
    J = springs.jacobian_x(c.network, x).toarray()
    fd = np.empty_like(J)
    e = np.zeros(x.size)
    for a in range(x.size):
        e[a] = h
        step = e.reshape(x.shape)
        fd[:, a] = (c.network.forces(x + step) - c.network.forces(x - step)).ravel() / (2 * h)
        e[a] = 0.0
    damped = cloth.sheet(**{**CLOTH, "c": 0.01}).network
    Jv = springs.jacobian_v(damped, x).toarray()
    return (float(np.abs(J - fd).max()), float(np.abs(J).max()), float(np.abs(J - J.T).max()),
            float(np.abs(Jv - Jv.T).max()))


def damping_ratios(k: float = 100.0, m: float = 1.0, h: float = 0.1, steps: int = 5):
    """Energy after each Baraff–Witkin step divided by the energy before, for a mass on a
    spring (motion along the spring, where the step is exactly backward Euler)."""
    _, y0, net = springs.anchored_spring(k, m, stretch=0.1)
    solver = BaraffWitkin(net, m, pinned=[0])
    x, v = y0[0], y0[1]

    def energy(x, v):
        return 0.5 * m * np.sum(v[1] ** 2) + net.energy(x)

    ratios = []
    for _ in range(steps):
        before = energy(x, v)
        x, v = solver.step(x, v, h)
        ratios.append(energy(x, v) / before)
    return np.array(ratios)


def condition_numbers(c: cloth.Cloth, h: float) -> dict:
    """The condition number of Baraff and Witkin's matrix ``M + h² K`` (no damping) at the
    rest shape, over the free coordinates: ``kappa`` (eigenvalues of the dense matrix),
    ``jacobi`` (after the Jacobi scaling ``D^(-1/2) A D^(-1/2)`` that CG's preconditioner
    applies) and ``formula`` ``1 + h² ω_max²`` (equal masses, and a flat sheet has modes of
    zero stiffness, so the smallest eigenvalue is ``m``)."""
    free = np.setdiff1d(np.arange(c.n), c.pinned)
    dofs = (free[:, None] * 3 + np.arange(3)).ravel()
    K = np.asarray(springs.stiffness_matrix(c.network, c.x0))[np.ix_(dofs, dofs)]
    A = np.diag(np.repeat(c.mass[free], 3)) + h * h * K
    lam = np.linalg.eigvalsh(A)
    d = np.sqrt(np.diag(A))
    lam_j = np.linalg.eigvalsh(A / np.outer(d, d))
    omega, _ = frequency_and_limit(c)
    return {"kappa": float(lam.max() / lam.min()), "jacobi": float(lam_j.max() / lam_j.min()),
            "formula": float(1.0 + (h * omega) ** 2)}


def cg_bound(kappa: float, rtol: float, kappa_residual: float | None = None) -> int:
    """Iterations after which (preconditioned) conjugate gradients has surely reduced the
    error in the energy norm by ``rtol``: ``½ √κ ln(2/rtol)``, from the bound
    ``2 ((√κ − 1)/(√κ + 1))^k`` with ``κ`` that of the preconditioned matrix. With
    ``kappa_residual`` (``κ`` of the matrix itself), the bound for a stop on the relative
    residual ``|b − A x| <= rtol |b|`` from a zero start, as SciPy's ``cg`` stops: the
    residual is ``A e``, between ``√λ_min`` and ``√λ_max`` times the energy norm of the error
    ``e``, so its ratio may exceed the error's by ``√κ_residual``:
    ``½ √κ ln(2 √κ_residual / rtol)``."""
    factor = 1.0 if kappa_residual is None else np.sqrt(kappa_residual)
    return int(np.ceil(0.5 * np.sqrt(kappa) * np.log(2.0 * factor / rtol)))


def rest_state(c: cloth.Cloth, start=None, gravity=(0.0, -9.81, 0.0)):
    """The cloth hanging at rest: the minimum of its elastic plus gravitational energy over
    the free particles, found by a trust-region Newton method (SciPy's ``trust-krylov``)
    with the exact Hessian's products, from ``start`` (default: the end of 2 s of
    Baraff-Witkin steps, near rest). Returns the positions (N, 3) (m), the energy (J),
    the largest remaining force (N) and the smallest eigenvalue of the Hessian (N/m),
    positive at a minimum."""
    from scipy.optimize import minimize

    g = np.asarray(gravity, dtype=float)
    free = np.setdiff1d(np.arange(c.n), c.pinned)
    if start is None:
        start = cloth.simulate(c, "baraff_witkin", frames=60, rtol=1e-3).x[-1]

    def full(z):
        x = np.array(start, dtype=float)
        x[free] = z.reshape(-1, 3)
        return x

    def energy_and_gradient(z):
        x = full(z)
        force = c.network.forces(x) + c.mass[:, None] * g
        return c.network.energy(x) - np.sum(c.mass * (x @ g)), -force[free].ravel()

    linearized = {}        # the linearization at the current point, built once per point:
                           # trust-krylov asks for many products at each point it visits

    def hessian_product(z, p):
        key = z.tobytes()
        if key not in linearized:
            linearized.clear()
            linearized[key] = c.network.linearize(full(z), definite=False)
        q = np.zeros_like(start)
        q[free] = p.reshape(-1, 3)
        return linearized[key].product(q, stiffness=1.0)[free].ravel()

    found = minimize(energy_and_gradient, np.asarray(start)[free].ravel(), jac=True,
                     hessp=hessian_product, method="trust-krylov", options={"gtol": 1e-11})
    x = full(found.x)
    dofs = (free[:, None] * 3 + np.arange(3)).ravel()
    hessian = np.asarray(springs.stiffness_matrix(c.network, x))[np.ix_(dofs, dofs)]
    smallest = np.linalg.eigvalsh(hessian)[0]
    return x, float(found.fun), float(np.abs(found.jac).max()), float(smallest)


def strains(c: cloth.Cloth, x) -> np.ndarray:
    """Strain ``(ℓ − L)/L`` of every structural spring at positions ``x`` (``(..., N, 3)``,
    m): shape ``(..., S)``; positive when stretched."""
    s = c.network.select("struct")
    x = np.asarray(x, dtype=float)
    length = np.sqrt(np.sum((x[..., s.j, :] - x[..., s.i, :]) ** 2, axis=-1))
    return (length - s.rest) / s.rest


def large_steps(factors=(1, 10, 100), damping_ratio: float = 0.1, frames: int = 30,
                fps: float = 30.0, safety: float = 0.9):
    """For each stiffness factor (× the notebook's 300 N/m, damping ``damping_ratio`` of
    critical): symplectic Euler at ``safety`` × its measured limit against one
    Baraff-Witkin step per frame, over ``frames`` frames. Each row holds the measured
    limit (s), the substeps per frame, the mean CG iterations per step, the CPU time of
    each run (s), and the structural strain per frame of each run."""
    rows = []
    for factor in factors:
        c = hanging(k_struct=CLOTH["k_struct"] * factor, damping_ratio=damping_ratio)
        limit = cloth.explicit_dt_max(c)
        substeps = int(np.ceil(1.0 / (fps * safety * limit)))
        t0 = time.process_time()
        explicit = cloth.simulate(c, "symplectic_euler", frames=frames, fps=fps, substeps=substeps)
        t1 = time.process_time()
        implicit = cloth.simulate(c, "baraff_witkin", frames=frames, fps=fps)
        t2 = time.process_time()
        if not (explicit.stable and implicit.stable):
            raise AssertionError(f"a run of the large-steps study blew up at factor {factor}")
        rows.append({"factor": factor, "k": c.network.select("struct").k[0], "limit": limit,
                     "substeps": substeps, "iterations": float(implicit.iterations.mean()),
                     "explicit_s": t1 - t0, "implicit_s": t2 - t1,
                     "explicit_strain": strains(c, explicit.x).max(axis=1),
                     "implicit_strain": strains(c, implicit.x).max(axis=1)})
    return rows


def drape(frames: int = 40, fps: float = 30.0, substeps: int = 2, n: int = 20,
          friction: float = 0.5):
    """A 20 × 20 cloth (0.9 m, 0.15 kg, lightly damped) dropped flat from ``y = 0.4`` m, 0.15 m
    above the top of a sphere of radius 0.25 m centred at the origin and resting on the
    ground (``y = −0.25``), by Baraff–Witkin steps of 1/60 s.
    After every step particles inside the sphere (grown by 3 % for the cloth's thickness)
    or below the ground are put back on the surface and lose their inward velocity, with
    Coulomb friction. Returns the cloth and its :class:`~course_lib.cloth.ClothRun`."""
    c = cloth.sheet(n=n, size=0.9, total_mass=0.15, k_struct=300.0, c=0.01,
                    height=DRAPE_HEIGHT, pinned="none")
    contact = collisions.chain(
        collisions.sphere((0.0, 0.0, 0.0), 1.03 * SPHERE_RADIUS, restitution=0.0, friction=friction),
        collisions.plane((0.0, 1.0, 0.0), -SPHERE_RADIUS, restitution=0.0, friction=friction))
    run = cloth.simulate(c, "baraff_witkin", frames=frames, fps=fps, substeps=substeps,
                         post_step=contact, rtol=1e-3)
    return c, run

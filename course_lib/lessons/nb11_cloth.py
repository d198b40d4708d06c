"""Notebook 11 (cloth): the scenes and studies behind the notebook.

Holds the notebook's cloth (:func:`hanging`: 12 × 12 particles, 0.55 m, 0.1 kg, two
corners pinned) and the drape over a sphere (:func:`drape`); the checks of the
Baraff–Witkin ingredients (:func:`jacobian_check` against central differences,
:func:`damping_ratios` on a single spring); and the cost study (:func:`work_per_frame`).
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
#: The drape: a 20 × 20 cloth of 0.9 m and 0.15 kg, 0.4 m above a 0.25 m sphere on the ground.
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


def work_per_frame(k_values, frames: int = 15, fps: float = 30.0, safety: float = 0.95):
    """For each structural stiffness: the substeps an explicit run needs per frame
    (``safety × 2/ω_max``), the mean CG iterations of one Baraff–Witkin step per frame at
    ``rtol = 1e-2``, and the wall time (s) of ``frames`` frames of each."""
    rows = []
    for k in k_values:
        c = hanging(k_struct=k)
        _, limit = frequency_and_limit(c)
        substeps = int(np.ceil(1.0 / (fps * safety * limit)))
        t0 = time.perf_counter()
        explicit = cloth.simulate(c, "symplectic_euler", frames=frames, substeps=substeps)
        t1 = time.perf_counter()
        implicit = cloth.simulate(c, "baraff_witkin", frames=frames, rtol=1e-2)
        t2 = time.perf_counter()
        if not (explicit.stable and implicit.stable):
            raise AssertionError(f"a run of the cost study blew up at k = {k}")
        rows.append({"k": k, "substeps": substeps, "iterations": float(implicit.iterations.mean()),
                     "explicit_s": t1 - t0, "implicit_s": t2 - t1})
    return rows


def drape(frames: int = 40, fps: float = 30.0, substeps: int = 2, n: int = 20,
          friction: float = 0.5):
    """A 20 × 20 cloth (0.9 m, 0.15 kg, lightly damped) dropped from 0.4 m onto a sphere of
    radius 0.25 m resting on the ground (``y = −0.25``), by Baraff–Witkin steps of 1/60 s.
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

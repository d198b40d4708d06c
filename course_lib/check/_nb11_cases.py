"""Case data of notebook 11's checks: springs for the Jacobian block (:func:`spring_cases`),
small cloths and a strand for the explicit limit (:func:`limit_cases`), cloths in stretched,
crumpled, moving states for one Baraff-Witkin solve (:func:`solve_cases`), and runs whose
peak strain breaks the usual shortcuts (:func:`strain_cases`). Each generator is seeded, so
every check sees the same cases.

Imports NumPy and :mod:`course_lib.cloth` and :mod:`course_lib.springs` (the cloths).
"""

from __future__ import annotations

import numpy as np

from .. import cloth, springs

_SEED = 1111


def spring_cases():
    rng = np.random.default_rng(_SEED)
    yield "a stretched spring", rng.normal(size=3), 50.0, 0.4
    yield "a compressed spring", rng.normal(size=3), 120.0, 3.0
    for n in range(2):
        yield f"a random spring ({n + 1})", rng.normal(size=3), float(rng.uniform(10, 500)), 1.0

def limit_cases():
    rng = np.random.default_rng(_SEED + 2)
    c = cloth.sheet(n=5, size=0.3, total_mass=0.02, k_struct=200.0)
    yield "5 × 5 cloth, equal masses", c, c.mass
    yield "5 × 5 cloth, masses from 0.3 to 3 g", c, rng.uniform(3e-4, 3e-3, c.n)
    x0, strand = springs.hair_chain(n=8, length=0.2, k_edge=900.0, k_bend=30.0)
    chain = cloth.Cloth(x0, strand, np.full(8, 1e-3), np.array([0]), (1, 8))
    yield "8-particle strand, root pinned, masses from 0.5 to 2 g", chain, rng.uniform(5e-4, 2e-3, 8)

def solve_cases():
    """Small cloths in stretched, crumpled states with velocities: undamped, damped,
    unequal masses, stiff."""
    rng = np.random.default_rng(_SEED + 3)
    for what, k, c, masses, speed in [
            ("4 × 4 cloth, undamped, at rest", 200.0, 0.0, "equal", 0.0),
            ("4 × 4 cloth, undamped, moving", 200.0, 0.0, "equal", 0.3),
            ("4 × 4 cloth, damped (c = 0.5 N s/m), moving", 200.0, 0.5, "equal", 0.3),
            ("5 × 5 cloth, damped, masses from 1 to 5 g, moving", 300.0, 0.2, "unequal", 0.5),
            ("5 × 5 stiff cloth (k = 30000 N/m), damped, moving", 30000.0, 1.0, "unequal", 0.5)]:
        n = 4 if what.startswith("4") else 5
        sheet = cloth.sheet(n=n, size=0.3, total_mass=0.02, k_struct=k, c=c, pinned="none")
        x = sheet.x0 * 1.08 + 0.004 * rng.normal(size=sheet.x0.shape)     # stretched, crumpled
        v = speed * rng.normal(size=x.shape)
        mass = sheet.mass if masses == "equal" else rng.uniform(1e-3, 5e-3, sheet.n)
        yield what, sheet.network, x, v, mass

def strain_cases():
    """Runs of small cloths: a stretch early and a larger compression late (the largest
    strain, not |strain|, and not the last frame), a wandering cloth, a falling one, every
    spring family at once (rest lengths 5, 7 and 10 cm: one rest length will not do), and a
    cloth shrunk in every frame, most in the first (every strain negative: the largest is
    still a strain, and it is not measured from the first frame)."""
    rng = np.random.default_rng(_SEED + 4)
    sheet = cloth.sheet(n=4, size=0.3, total_mass=0.02)
    struct = sheet.network.select("struct")
    frames = np.repeat(sheet.x0[None], 5, axis=0)
    frames[2, 5] += [0.0, 0.0, 0.012]                  # a stretch in the middle of the run
    frames[4, 9] += [0.0, 0.0, -0.03]                  # a larger compression at the end
    yield "a 4 × 4 cloth: stretched at frame 2, compressed more at frame 4", frames, struct
    drift = sheet.x0[None] + np.cumsum(0.002 * rng.normal(size=(40, *sheet.x0.shape)), axis=0)
    yield "a 4 × 4 cloth wandering for 40 frames", drift, struct
    big = cloth.sheet(n=8, size=0.5, total_mass=0.05)
    run = cloth.simulate(big, "symplectic_euler", frames=12, substeps=40)
    yield "an 8 × 8 cloth falling for 12 frames", run.x, big.network.select("struct")
    wide = cloth.sheet(n=5, size=0.2, total_mass=0.02)
    wobble = wide.x0[None] + np.cumsum(0.001 * rng.normal(size=(12, *wide.x0.shape)), axis=0)
    wobble[0, 12] += [0.004, 0.0, 0.0]                 # the first frame stretches the most
    yield "a 5 × 5 cloth, every spring family (rest lengths 5 to 10 cm)", wobble, wide.network
    shrink = sheet.x0[None] * np.array([0.9, 0.97, 0.93, 0.95, 0.91, 0.96])[:, None, None]
    yield "a 4 × 4 cloth shrinking: every spring compressed in every frame", shrink, struct

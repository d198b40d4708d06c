"""Core costs: spring forces on a cloth and the per-step overhead of `integrate`.

Targets are generous ceilings that a Python loop over springs would miss by far (the
60×60 cloth has ~20,000 springs): they guard the vectorization, not the exact speed.
"""

import numpy as np

import course_lib as cl
from benchmarks.__main__ import Result, median_time
from course_lib import forces, springs
from course_lib.systems import NewtonianSystem, stack_state, sum_forces


def run() -> list[Result]:
    x0, net = springs.cloth_grid(60, 60, 0.02, c=0.5)
    rng = np.random.default_rng(0)
    x = x0 + 1e-3 * rng.normal(size=x0.shape)
    v = rng.normal(size=x0.shape)
    results = [Result(f"spring forces, 60x60 cloth ({net.n_springs} springs)",
                      median_time(lambda: net.forces(x, v)), 0.010)]

    xs, strand = springs.hair_chain(n=20, length=0.3, k_edge=2000.0, k_bend=50.0, c_edge=0.5)
    system = NewtonianSystem(sum_forces(forces.constant_gravity(np.full(20, 1e-3)), strand.force),
                             np.full(20, 1e-3), pinned=[0])
    y0 = stack_state(xs, np.zeros_like(xs))
    results.append(Result(
        "integrate 1000 symplectic Euler steps, 20-particle strand",
        median_time(lambda: cl.integrate(system, y0, (0.0, 0.1), 1e-4, "symplectic_euler"), repeat=5),
        0.5,
    ))
    return results

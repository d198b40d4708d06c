"""Core physics: a spring step on a cloth and on a long hair chain, and N-body gravity.

Each case runs course_lib, a naive Python loop and a compiled numba loop from the same
state, checks that they agree to 1e-10, then times them in interleaved rounds.
"""

from __future__ import annotations

import tracemalloc

import numpy as np

from benchmarks import reference as ref
from benchmarks.timing import Row, check_equal, interleaved
from course_lib import forces, springs

G = np.array([0.0, -9.81, 0.0])


def course_lib_step(net, x, v, mass, dt, pinned=()):
    """One symplectic Euler step with course_lib's fast path: forces into a preallocated
    buffer, then whole-array updates (no broadcasting along rows of three)."""
    F = np.empty_like(x)
    weight = np.repeat(mass, 3).reshape(x.shape) * G      # m g, per particle and component
    dt_over_m = dt / np.repeat(mass, 3).reshape(x.shape)
    dt_over_m[list(pinned)] = 0.0                         # pinned particles do not accelerate

    def step():
        net.forces(x, v, out=F)
        np.add(F, weight, out=F)
        np.multiply(F, dt_over_m, out=F)                  # = dt a
        np.add(v, F, out=v)
        np.multiply(v, dt, out=F)
        np.add(x, F, out=x)

    return step


def spring_case(name: str, x0, net, mass, dt, target_numba: float, target_naive: float | None,
                rounds: int) -> Row:
    rng = np.random.default_rng(0)
    x0 = x0 + 1e-3 * rng.normal(size=x0.shape)
    v0 = 0.1 * rng.normal(size=x0.shape)
    args = (net.i, net.j, net.rest, net.k, net.c, mass, G, dt)
    states = {name: (x0.copy(), v0.copy()) for name in ("course_lib", "naive", "numba")}
    impls = {"course_lib": course_lib_step(net, *states["course_lib"], mass, dt),
             "naive": lambda: ref.naive_spring_step(*states["naive"], *args)}
    compiled = ref.numba_spring_step()
    if compiled is not None:
        F = np.empty_like(x0)
        impls["numba"] = lambda: compiled(*states["numba"], *args, F)
    for f in impls.values():                              # one step each from the same state
        f()
    check_equal({k: np.stack(states[k]) for k in impls}, "course_lib")
    inner = {"course_lib": 20, "naive": 1, "numba": 20}
    t = interleaved(impls, rounds=rounds, inner=inner)
    ratio_numba = t.ratio("course_lib", "numba") if compiled else None
    ratio_naive = t.ratio("naive", "course_lib")
    ok = (ratio_numba is None or ratio_numba <= target_numba) and (
        target_naive is None or ratio_naive >= target_naive)
    parts = [f"{ratio_numba:.2f}× numba" if ratio_numba else "numba n/a",
             f"{ratio_naive:.0f}× faster than loop"]
    target = f"≤ {target_numba:g}× numba" + (f", ≥ {target_naive:g}× loop" if target_naive else "")
    return Row(name, t.median["course_lib"], target, ok, t.median["naive"],
               t.median.get("numba"), ", ".join(parts))


def nbody_case(n: int, rounds: int) -> list[Row]:
    rng = np.random.default_rng(1)
    x = rng.normal(size=(n, 3))
    mass = rng.uniform(0.5, 1.5, n)
    eps = 0.05
    impls = {"course_lib": lambda: forces.nbody_gravity_force(x, mass, 1.0, eps)}
    compiled = ref.numba_nbody()
    if compiled is not None:
        F = np.empty_like(x)
        impls["numba"] = lambda: compiled(x, mass, 1.0, eps, F)
    results = {k: np.array(f()) for k, f in impls.items()}
    results["naive"] = ref.naive_nbody(x, mass, 1.0, eps)
    check_equal(results, "course_lib")
    t = interleaved(impls, rounds=rounds, inner=3 if n >= 500 else 20)
    naive = interleaved({"naive": lambda: ref.naive_nbody(x, mass, 1.0, eps)},
                        rounds=1 if n >= 500 else 3, warmup=False).median["naive"]
    tracemalloc.start()
    forces.nbody_gravity_force(x, mass, 1.0, eps)
    peak = tracemalloc.get_traced_memory()[1] / 8          # floats
    tracemalloc.stop()
    ratio = t.ratio("course_lib", "numba") if compiled else None
    ok = (ratio is None or ratio <= 4.0) and peak <= 3 * n * n
    note = (f"{ratio:.2f}× numba" if ratio else "numba n/a") + \
        f", temporaries {peak / n**2:.3f} N² floats ({peak * 8 / 1e6:.2f} MB)"
    return [Row(f"N-body gravity, {n} bodies, softened: one force evaluation", t.median["course_lib"],
                "≤ 4× numba, temporaries ≤ 3 N² floats", ok, naive, t.median.get("numba"), note)]


def run(quick: bool = False) -> list[Row]:
    side, strand, bodies, rounds = (6, 60, 40, 2) if quick else (64, 10_000, 1000, 15)
    x0, cloth = springs.cloth_grid(side, side, 0.02, c=0.5)
    rows = [spring_case(
        f"symplectic Euler step, damped springs + gravity, cloth {side}×{side} "
        f"({cloth.n_springs} springs)", x0, cloth, np.full(side * side, 1e-3), 1e-4, 3.0, 25.0,
        rounds)]
    xs, hair = springs.hair_chain(strand, 10.0, k_edge=2000.0, k_bend=50.0, c_edge=0.5,
                                  c_bend=0.1, zigzag=0.2)
    rows.append(spring_case(
        f"same, hair chain of {strand} particles, edge + bending ({hair.n_springs} springs)",
        xs, hair, np.full(strand, 1e-4), 1e-5, 3.0, None, rounds))
    rows += nbody_case(bodies, rounds)
    return rows

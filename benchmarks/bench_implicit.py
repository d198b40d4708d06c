"""Implicit cloth: a Baraff–Witkin step against one explicit step of the same cloth, how
its cost grows with the cloth, and ``integrate``'s implicit methods with a sparse ``jac``.

The three "≤ 10× one explicit step" targets of issue 8 measured the wrong thing (per
step, not per simulated second) and are retired: these rows are informational, and the
targets live in :mod:`benchmarks.bench_largestep` (cost per simulated second against
symplectic Euler at its measured limit, strain and energy).

The cloth is the one of the explicit benchmark (spacing 2 cm, 1 g particles, damped
springs) hanging from its two top corners under gravity. The implicit step is
:data:`FACTOR` times the explicit stability limit ``2 / ω_max``; CG stops at relative
residual :data:`RTOL`, warm-started from the previous steps.
"""

from __future__ import annotations

import numpy as np

import course_lib as cl
from benchmarks import preconditioners
from benchmarks.bench_core import course_lib_step
from benchmarks.timing import Row, interleaved
from course_lib import springs
from course_lib.baraff_witkin import BaraffWitkin

G = np.array([0.0, -9.81, 0.0])
MASS = 1e-3
FACTOR = 10.0          # implicit step / explicit stability limit
RTOL = 1e-3
LIMIT_64 = None        # filled on first use: 2 / ω_max of the 64×64 cloth
LAST: dict = {}        # the largest cloth's solver and state after its timed steps


def cloth(side: int):
    x0, net = springs.cloth_grid(side, side, 0.02, c=0.5)
    return x0, net, [side * (side - 1), side * side - 1]


def explicit_limit(side: int) -> float:
    x0, net, pinned = cloth(side)
    return 2.0 / springs.max_frequency(net, x0, MASS, pinned)


def implicit_vs_explicit(side: int, dt: float, rounds: int):
    """Median BW step time, explicit step time, their per-round ratio and CG iterations."""
    x0, net, pinned = cloth(side)
    solver = BaraffWitkin(net, MASS, pinned=pinned, gravity=G, rtol=RTOL, check=False)
    state = [x0.copy(), np.zeros_like(x0)]
    iterations = []

    def implicit():
        state[0], state[1] = solver.step(state[0], state[1], dt)
        iterations.append(solver.info.iterations)

    xe, ve = x0.copy(), np.zeros_like(x0)
    explicit = course_lib_step(net, xe, ve, np.full(len(x0), MASS), dt / (10 * FACTOR), pinned)
    t = interleaved({"implicit": implicit, "explicit": explicit}, rounds=rounds,
                    inner={"implicit": 1, "explicit": 10})
    LAST.update(solver=solver, x=state[0], v=state[1], dt=dt)
    return t, float(np.median(iterations))


def run(quick: bool = False) -> list[Row]:
    sides, rounds = ((6, 8, 10), 3) if quick else ((16, 24, 32, 48, 64), 25)
    dt = FACTOR * explicit_limit(sides[-1])
    rows, times = [], []
    for side in sides:
        t, its = implicit_vs_explicit(side, dt, rounds)
        times.append(t.median["implicit"])
    ratio = t.ratio("implicit", "explicit")
    rows.append(Row(f"Baraff–Witkin implicit step, cloth {sides[-1]}×{sides[-1]}, dt = {FACTOR:g}× "
                    f"explicit limit, CG rtol {RTOL:g} (informational; issue 8's target retired)",
                    t.median["implicit"], "–", None, None, None,
                    f"{ratio:.1f}× explicit step ({t.median['explicit'] * 1e6:.0f} µs), "
                    f"{its:.0f} CG iterations"))
    rows.append(Row("same, cost per simulated second against symplectic Euler at its limit "
                    "(informational)", None, "–", None, None, None,
                    f"{ratio / FACTOR:.1f}× (implicit step / {FACTOR:g} explicit steps)"))
    rows.append(Row("same, with the preconditioners SciPy offers (informational; "
                    "benchmarks/preconditioners.py)", None, "–", None, None, None,
                    preconditioners.study(LAST["solver"], LAST["x"], LAST["v"], LAST["dt"],
                                          t.median["explicit"], RTOL)))
    n = np.array(sides, dtype=float) ** 2
    p = np.polyfit(np.log(n), np.log(times), 1)[0]
    rows.append(Row(f"Baraff–Witkin step cost ∝ N^p over {sides[0]}²…{sides[-1]}² "
                    f"(same dt)", None, "p ≤ 1.3", p <= 1.3, None, None,
                    f"p = {p:.2f}; " + ", ".join(f"{s}²: {1e3 * tt:.1f} ms"
                                                 for s, tt in zip(sides, times, strict=True))))
    rows += integrate_implicit(sides[-1], dt, quick)
    return rows


def integrate_implicit(side: int, dt: float, quick: bool) -> list[Row]:
    """``integrate``'s backward Euler and trapezoid on the cloth with the sparse analytic
    Jacobian (:func:`course_lib.springs.newtonian_jacobian`), one step each."""
    x0, net, pinned = cloth(side)
    mass = np.full(len(x0), MASS)
    system = cl.NewtonianSystem(cl.systems.sum_forces(net.force, cl.forces.constant_gravity(mass, G)),
                                mass, pinned=pinned)
    jac = springs.newtonian_jacobian(net, mass, pinned)
    y0 = cl.stack_state(x0, np.zeros_like(x0))
    xe, ve = x0.copy(), np.zeros_like(x0)
    explicit = course_lib_step(net, xe, ve, mass, dt / (10 * FACTOR), pinned)
    rows = []
    for method in ("backward_euler", "trapezoidal"):
        def implicit(m=method):
            return cl.integrate(system, y0, (0.0, dt), dt, m, jac=jac)
        try:
            traj = implicit()
        except Exception as exc:  # reported in the table
            rows.append(Row(f"integrate {method}, cloth {side}×{side}, sparse jac",
                            None, "–", None,
                            note=f"failed: {type(exc).__name__}: {exc}"[:120]))
            continue
        t = interleaved({"implicit": implicit, "explicit": explicit}, rounds=1 if quick else 3,
                        inner={"implicit": 1, "explicit": 10}, warmup=False)
        ratio = t.ratio("implicit", "explicit")
        rows.append(Row(f"integrate {method}, cloth {side}×{side}, sparse analytic jac, "
                        f"dt = {FACTOR:g}× explicit limit (informational)", t.median["implicit"],
                        "–", None if traj.stable else False, None, None,
                        f"{ratio:.0f}× explicit step, nfev {traj.nfev}"))
    return rows

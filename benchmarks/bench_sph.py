"""SPH liquids (notebook 13): the dam break at scale, and what the large steps buy.

Rows (issue 21):

- IISPH (Ihmsen et al. 2014) on Martin & Moyce's n² = 2 dam break with 4,050 particles
  (a 45 × 90 column, 1 m × 2 m, in a 6 m tank), 1 s of simulated time: CPU seconds
  against the target of 20 s on 2 cores (the run is serial);
- WCSPH (Becker & Teschner 2007) at its CFL step on the same dam break, timed over its
  first 0.05 s (its step, set by the speed of sound, hardly changes) and scaled to a
  simulated second; the ratio of the two costs per simulated second;
- the front of the IISPH run against Martin & Moyce's points for T ≤ 3.5 (target 10 %),
  the comparison of notebook 13's Section 8 at 4,050 particles: released at once (its
  lead at T = 1.19 grows with resolution as the artificial viscosity shrinks; 10 % at 450
  and 12 % at 800 particles in the notebook); with Adami et al.'s (2012) no-slip floor;
  released by a gate lifted at √(g a) (Lauber & Hager's criterion); and released at once
  but delayed by ΔT = 0.175 (the Lethe project's delay, a fit taken from another code).
  The front released at once is judged against the target (it misses it: notebook 13
  says why); the variants are reported beside it;
- the mean compression (target 1 %); the water column's pressure against ρgh (target 5 %).

Every computation row is on this thread's CPU time. ``quick`` runs 450 particles for a
tenth of the time (a smoke test).
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.timing import Row
from course_lib import sph
from course_lib.lessons import nb13_runs as runs
from course_lib.lessons import nb13_sph_liquids as nb13


def _run(n: int, method: str, t_end: float, fronts: list | None = None, **changes):
    sim = sph.dam_break_simulation(n, method, **changes)
    record = None if fronts is None else (lambda s: fronts.append((s.t, sph.scenes.front(
        s.x, s.params.spacing))))
    start = time.thread_time()
    sim.run(t_end, on_step=record)
    return sim, time.thread_time() - start


def run(quick: bool = False) -> list[Row]:
    n, t_end, t_wcsph = (450, 0.1, 0.01) if quick else (4050, 1.0, 0.05)
    fronts = [(0.0, 1.0)]
    sim, cpu = _run(n, "iisph", t_end, fronts)
    h = sim.history
    rows = [Row(f"SPH dam break, IISPH, {sim.n} particles, {t_end:g} s simulated", cpu, "≤ 20 s",
                bool(sim.stable and cpu <= 20.0),
                note=f"{sim.steps} steps, {np.mean(h['iterations']):.1f} Jacobi sweeps per step, "
                     f"mean dt {np.mean(h['dt']) * 1e3:.2f} ms")]
    wc, cpu_wc = _run(n, "wcsph", t_wcsph)
    per_iisph, per_wcsph = cpu / sim.t, cpu_wc / wc.t
    ratio = per_wcsph / per_iisph
    rows.append(Row("same, WCSPH at its CFL step (λ = 0.4), cost per simulated second", per_wcsph,
                    "IISPH cheaper", bool(ratio > 1.0), ratio=f"{ratio:.1f}× IISPH's",
                    note=f"steps {np.mean(wc.history['dt']) / np.mean(h['dt']):.3f}× IISPH's; "
                         f"timed over {wc.t:g} s ({wc.steps} steps)"))
    compression = float(np.mean(h["density_error"]))
    rows.append(Row("same IISPH run: mean compression over the steps", None, "≤ 1 %",
                    bool(compression <= 0.01),
                    note=f"{compression * 100:.2f} %, worst step {np.max(h['density_error']) * 100:.2f} %"))
    if not quick:
        t, z = np.array(fronts).T
        rows += _front_rows(n, t, z)
        column = nb13.hydrostatic_column()
        err = np.abs(column.p / column.exact - 1)[column.below_top].max()
        rows.append(Row("water column at rest (IISPH): pressure against ρgh below the top layer",
                        None, "within 5 %", bool(err <= 0.05), note=f"{err * 100:.1f} %"))
    return rows


def _front_row(label: str, rel: np.ndarray, judged: bool) -> Row:
    worst = float(np.abs(rel).max())
    T_mm = sph.MARTIN_MOYCE[:, 0]
    return Row(label, None, "within 10 %" if judged else "reported",
               bool(worst <= 0.10) if judged else None,
               note=f"largest {worst * 100:.1f} %, at T = {T_mm[np.argmax(np.abs(rel))]:.2f}; "
                    f"lead at T = {T_mm[2]:.2f}: {rel[2] * 100:+.1f} %")


def _front_rows(n: int, t, z) -> list[Row]:
    """Notebook 13's Section 8 at ``n`` particles: the front released at once (``t``, ``z``
    from the timed run), with a no-slip floor, released by a gate, and delayed."""
    rows = [_front_row(f"dam-break front vs Martin & Moyce (1952), T ≤ 3.5, {n} particles, "
                       "released at once", sph.front_errors(t, z, 1.0), True)]
    t_end = 3.5 / np.sqrt(2 * sph.scenes.G)
    for label, changes in (("with a no-slip floor (Adami et al. 2012)", {"wall_velocity": "no-slip"}),
                           (f"released by a gate lifted at √(ga) = {runs.gate_speed():.2f} m/s",
                            {"gate_speed": runs.gate_speed()})):
        fronts = [(0.0, 1.0)]
        _run(n, "iisph", t_end, fronts, **changes)
        rows.append(_front_row(f"same, {label}", sph.front_errors(*np.array(fronts).T, 1.0), False))
    rows.append(_front_row(f"same, released at once, delayed by ΔT = {runs.RELEASE_DELAY} (Lethe's)",
                           sph.front_errors(t, z, 1.0, delay=runs.RELEASE_DELAY), False))
    return rows

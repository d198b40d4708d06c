"""Large steps that pay off (issue 19): cost per simulated second, strain and energy.

The scene: a corner-pinned sheet (``cloth.sheet``: 0.55 m, 0.1 kg) falls under gravity for
1 s, springs damped at 10 % of one particle's critical damping on a structural spring
(``damping_ratio=0.1``), stiffness ×10, ×100, ×1000 the default 300 N/m. Symplectic
Euler runs at 0.9 × its limit *measured by bisection with that damping on*
(``cloth.explicit_dt_max``; with damping ``c`` the limit is below ``2/ω_max``:
``ω² dt² + 2 (c/m) dt < 4``). Every other method takes one call per 1/60 s frame with
its defaults. On 64² each (method, stiffness) is one run of 0.5 s (30 frames): its CPU
time, doubled, is the cost per simulated second, and the same run gives the peak
structural strain and the energy. The fidelity rows run 1 s on 32² against symplectic
Euler at half its limit ("converged"), as issue 19 defines them.
"""

from __future__ import annotations

import numpy as np

from benchmarks.timing import CPU, Row
from course_lib import cloth, springs

FACTORS = (10, 100, 1000)
METHODS = ("baraff_witkin", "fast_mass_spring", "xpbd")
#: Cost targets per simulated second against symplectic Euler (64², issue 19).
TARGETS = {("fast_mass_spring", 1000): 1 / 20, ("fast_mass_spring", 100): 1 / 5,
           ("xpbd", 1000): 1 / 5}
FIDELITY_PP = 0.5          # percentage points of peak structural strain, 32²


def scene(n: int, factor: float) -> cloth.Cloth:
    return cloth.sheet(n=n, k_struct=300.0 * factor, damping_ratio=0.1)


def one_second(c: cloth.Cloth, method: str, frames: int, **kw) -> dict:
    """One run (``frames`` frames at 60 fps): CPU time, peak structural strain, energy."""
    start = CPU()
    run = cloth.simulate(c, method, frames=frames, fps=60, **kw)
    seconds = CPU() - start
    strain = c.network.select("struct").strain(run.x[1:])
    energy = cloth.energies(c, run.x, run.v)["total"]
    return {"seconds": seconds, "stable": run.stable, "peak": float(np.nanmax(strain)),
            "energy": float(energy[-1] - energy[0]), "run": run}


def explicit(c: cloth.Cloth, frames: int, fraction: float = 0.9, **limit_options) -> dict:
    """Symplectic Euler at ``fraction`` × its limit measured with the damping on
    (``limit_options`` go to ``cloth.explicit_dt_max``)."""
    limit = cloth.explicit_dt_max(c, **limit_options)
    substeps = int(np.ceil(1.0 / (60 * fraction * limit)))
    out = one_second(c, "symplectic_euler", frames, substeps=substeps)
    out.update(limit=limit, substeps=substeps,
               undamped=2.0 / springs.max_frequency(c.network, c.x0, c.mass, c.pinned))
    return out


def run(quick: bool = False) -> list[Row]:
    # quick: a smoke test of every row (a few particles, one frame, a coarse limit)
    side, small, frames, long = (5, 5, 1, 1) if quick else (64, 32, 30, 60)
    limit_options = {"n_steps": 200, "rtol": 1e-2} if quick else {}
    rows, strain_notes = [], {}
    for factor in FACTORS:
        c = scene(side, factor)
        se = explicit(c, frames, **limit_options)
        rows.append(Row(f"symplectic Euler at 0.9× its measured limit, {side}², stiffness "
                        f"×{factor}, damping on: cost per simulated second",
                        se["seconds"] * 60 / frames, "–", None, note=(
                            f"limit {se['limit'] * 1e6:.2f} µs measured with damping "
                            f"(2/ω_max undamped {se['undamped'] * 1e6:.2f} µs), "
                            f"{se['substeps']} steps per frame")))
        notes = [f"symplectic Euler {100 * se['peak']:.3f} % / {se['energy'] * 1e3:+.1f} mJ"]
        for method in METHODS:
            r = one_second(c, method, frames)
            ratio = r["seconds"] / se["seconds"]
            target = TARGETS.get((method, factor))
            extra = ""
            if method == "fast_mass_spring":
                extra = f", {r['run'].iterations[0]} iterations per frame"
            rows.append(Row(
                f"{method}, {side}², stiffness ×{factor}, one call per 1/60 s frame: cost per "
                f"simulated second against symplectic Euler", r["seconds"] * 60 / frames,
                f"≤ 1/{round(1 / target)}" if target else "–",
                (ratio <= target and r["stable"]) if target else None,
                ratio=f"{ratio:.3f}×" + (f" (1/{1 / ratio:.0f})" if ratio < 1 else ""),
                note=f"peak strain {100 * r['peak']:.2f} %{extra}"))
            notes.append(f"{method} {100 * r['peak']:.2f} % / {r['energy'] * 1e3:+.1f} mJ")
        strain_notes[factor] = notes
    for factor, notes in strain_notes.items():
        rows.append(Row(f"peak structural strain over {frames / 60:g} s / energy change, {side}², "
                        f"stiffness ×{factor}", None, "–", None, note="; ".join(notes)))
    rows += fidelity(small, long, **limit_options)
    rows += xpbd_tradeoff(small, long)
    rows.append(frame_row(side))
    return rows


def xpbd_tradeoff(n: int, frames: int) -> list[Row]:
    """XPBD at ×1000 on 32² over 1 s, for the same or half the sweeps: more small steps
    against more sweeps per step (Macklin et al. 2019), and long range attachments (Kim,
    Chentanez & Müller 2012) on half the small steps (informational)."""
    from course_lib.largestep import LongRangeAttachments

    c = scene(n, 1000)
    default = cloth.XPBD_SUBSTEPS_PER_SECOND // 60
    rows = []
    for substeps, iterations, tethers in ((default, 1, False), (default // 2, 2, False),
                                          (default // 2, 1, False), (default // 2, 1, True)):
        options = {"substeps": substeps}
        if tethers:
            options["tethers"] = LongRangeAttachments(c.x0, c.pinned)
        r = one_second(c, "xpbd", frames, iterations=iterations, options=options)
        rows.append(Row(f"xpbd, {n}², stiffness ×1000, {substeps} small steps × {iterations} "
                        f"sweep{'s' if iterations > 1 else ''} per frame"
                        f"{', long range attachments' if tethers else ''}: peak structural "
                        f"strain over 1 s (informational)", r["seconds"] * 60 / frames, "–", None,
                        ratio=f"{100 * r['peak']:.3f} %"))
    return rows


def fidelity(n: int, frames: int, **limit_options) -> list[Row]:
    """Peak structural strain of the defaults within 0.5 pp of converged symplectic Euler
    (at half its limit, as issue 19 defines it)."""
    rows = []
    for factor in (100, 1000):
        c = scene(n, factor)
        se = explicit(c, frames, fraction=0.5, **limit_options)
        for method in ("fast_mass_spring", "xpbd"):
            r = one_second(c, method, frames)
            gap = 100 * abs(r["peak"] - se["peak"])
            rows.append(Row(f"{method} defaults, {n}², stiffness ×{factor}: peak structural "
                            f"strain over 1 s against converged symplectic Euler", None,
                            f"within {FIDELITY_PP:g} pp", gap <= FIDELITY_PP and r["stable"],
                            ratio=f"{gap:.2f} pp",
                            note=f"{100 * r['peak']:.3f} % against {100 * se['peak']:.3f} %"))
    return rows


def frame_row(side: int) -> Row:
    """One 1/60 s frame of fast_mass_spring at ×1000 (informational), and its factorizations."""
    from course_lib.largestep import FastMassSpring

    c = scene(side, 1000)
    solver = FastMassSpring(c.network, c.mass, pinned=c.pinned, gravity=cloth.G_EARTH)
    x, v = c.x0.copy(), np.zeros_like(c.x0)
    times = []
    for _ in range(12):
        start = CPU()
        x, v = solver.step(x, v, 1 / 60)
        times.append(CPU() - start)
    first, rest = times[0], float(np.median(times[1:]))
    return Row(f"one 1/60 s frame of fast_mass_spring, {side}², stiffness ×1000 (informational)",
               rest, "≤ 10 ms", None, note=(
                   f"{solver.cache.factorizations} factorization in 12 frames; the first frame "
                   f"(with it) {first * 1e3:.0f} ms"))

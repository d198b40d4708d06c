"""Notebook 12 (constraints and large steps): the scenes and studies behind the notebook.

Holds the notebook's cloth (:func:`scene`: a corner-pinned sheet, stiffness a multiple of
300 N/m, springs damped at 10 % of critical), the studies: PBD's and XPBD's stiffness
against the iteration count on a hanging chain (:func:`stiffness_study`), the objective of
one implicit step under local/global and L-BFGS iterations (:func:`convergence`), energy
lost per step on one spring (:func:`damping_ratios`), strain limiting
(:func:`strain_limit_study`), the measured comparison of the four methods
(:func:`comparison`) and the drape with self-collision (:func:`drape`); the widget's
computation is in :mod:`course_lib.lessons.nb12_frames`. Built on :mod:`course_lib.cloth`,
:mod:`course_lib.largestep` and :mod:`course_lib.collisions`; the drawings are in
:mod:`course_lib.lessons.nb12_drawings`. The core never imports this module.
"""

from __future__ import annotations

import time
from functools import lru_cache

import numpy as np

from .. import cloth, collisions, springs
from ..forces import G_EARTH
from ..largestep import PBD, XPBD, FastMassSpring

#: The cloth of the notebook: side, mass and damping ratio (see :func:`scene`).
SIZE, MASS, DAMPING_RATIO, K_DEFAULT = 0.55, 0.1, 0.1, 300.0
#: Stiffness multiples of the comparison, and its grid and length (frames at 60 fps).
FACTORS, TABLE_N, TABLE_FRAMES = (1, 100, 1000), 12, 12
#: Symplectic Euler's limit (s) on the table's sheet at ×1, measured once by bisection
#: with the damping on (``cloth.explicit_dt_max(scene(12))``, to 0.1 %; the tests measure
#: it again): :func:`explicit_limit` scales it to the other stiffnesses.
TABLE_LIMIT = 1.005e-3
#: Frames of the separate run that times XPBD per sheet (see :func:`comparison`).
TIMED_FRAMES = 1
METHOD_NAMES = {"symplectic_euler": "symplectic Euler", "baraff_witkin": "Baraff–Witkin",
                "fast_mass_spring": "fast mass-springs", "xpbd": "XPBD"}


def scene(n: int = 12, factor: float = 1.0, **changes) -> cloth.Cloth:
    """A sheet of ``n × n`` particles (0.55 m, 0.1 kg), structural stiffness ``factor`` ×
    300 N/m, springs damped at 10 % of one particle's critical damping."""
    return cloth.sheet(**{"n": n, "size": SIZE, "total_mass": MASS,
                          "k_struct": K_DEFAULT * factor, "damping_ratio": DAMPING_RATIO,
                          **changes})


def chain(n: int = 5, k: float = 50.0, rest: float = 0.1):
    """A chain of ``n`` particles hanging straight down from particle 0 (rest shape)."""
    x0 = np.zeros((n, 3))
    x0[:, 1] = -rest * np.arange(n)
    return x0, springs.SpringNetwork(np.arange(n - 1), np.arange(1, n), rest, k, 0.0, n)


def settled_sag(solver, x0, steps: int = 120, h: float = 0.01, drag: float = 0.85) -> float:
    """How far the last particle hangs below its rest position (m) once at rest (the
    velocity is scaled by ``drag`` after every step, so the chain settles)."""
    x, v = x0.copy(), np.zeros_like(x0)
    for _ in range(steps):
        x, v = solver.step(x, v, h)
        v *= drag
    return float(x0[-1, 1] - x[-1, 1])


def stiffness_study(iterations=(1, 2, 4, 8, 16), n: int = 5, k: float = 50.0, m: float = 0.01,
                    pbd_stiffness: float = 0.5):
    """Effective stiffness ``k · exact sag / measured sag`` (N/m) of a hanging chain under
    PBD and XPBD for each iteration count; ``exact`` is the static sag of springs ``k``."""
    x0, net = chain(n, k)
    exact = float(np.sum(m * 9.81 * np.arange(n - 1, 0, -1) / k))
    out = {"iterations": list(iterations), "k": k, "exact_sag": exact, "pbd": [], "xpbd": []}
    for its in iterations:
        common = {"pinned": [0], "gravity": G_EARTH, "iterations": its}
        out["pbd"].append(k * exact / settled_sag(PBD(net, m, stiffness=pbd_stiffness, **common), x0))
        out["xpbd"].append(k * exact / settled_sag(XPBD(net, m, **common), x0))
    return out


@lru_cache(maxsize=8)
def swinging_state(n: int, factor: float, frames: int = 15):
    """The notebook's cloth after ``frames`` frames of 1/60 s (fast mass-springs, 60
    L-BFGS iterations per frame: close to converged implicit Euler): ``(cloth, x, v)``."""
    c = scene(n, factor)
    run = cloth.simulate(c, "fast_mass_spring", frames=frames, fps=60, iterations=60)
    return c, run.x[-1], run.v[-1]


def convergence(n: int = 16, factor: float = 100.0, iterations: int = 40, h: float = 1 / 60):
    """The objective ``g`` of one implicit Euler step from the swinging cloth after each
    local/global iteration and each L-BFGS iteration, and its minimum (J)."""
    c, x, v = swinging_state(n, factor)
    out = {}
    for name, memory, its in (("local/global", 0, iterations), ("L-BFGS", 5, iterations),
                              ("reference", 8, 300)):
        solver = FastMassSpring(c.network, c.mass, pinned=c.pinned, gravity=G_EARTH,
                                iterations=its, memory=memory, record=True)
        solver.step(x, v, h)
        out[name] = np.array(solver.info.objective)
        out[f"{name} factorizations"] = solver.cache.factorizations
    out["minimum"] = float(out.pop("reference").min())
    out.pop("reference factorizations")
    return out


def damping_ratios(k: float = 100.0, m: float = 1.0, h: float = 0.1, steps: int = 5):
    """Energy after / before each fast mass-spring step of a mass on a spring moving along
    it (undamped): there the step is backward Euler's, ``1/(1 + ω² h²)``."""
    _, y0, net = springs.anchored_spring(k, m, stretch=0.1)
    solver = FastMassSpring(net, m, pinned=[0], iterations=3, memory=0)
    x, v = y0[0], y0[1]
    ratios = []
    for _ in range(steps):
        before = 0.5 * m * np.sum(v[1] ** 2) + net.energy(x)
        x, v = solver.step(x, v, h)
        ratios.append((0.5 * m * np.sum(v[1] ** 2) + net.energy(x)) / before)
    return np.array(ratios)


def peak_strain(c: cloth.Cloth, run) -> float:
    """Largest structural strain over the run's frames (a fraction)."""
    return float(np.nanmax(c.network.select("struct").strain(run.x[1:])))


def strain_limit_study(rows, factor: float = 100.0, limit: float = 0.005):
    """Peak structural strain of Baraff–Witkin (one step per 1/60 s) with a ``limit`` on
    every spring's strain, beside its peak without one and converged symplectic Euler's
    (both from the :func:`comparison` ``rows``)."""
    pick = {r["method"]: r["peak"] for r in rows if r["factor"] == factor}
    c = scene(TABLE_N, factor)
    run = cloth.simulate(c, "baraff_witkin", frames=TABLE_FRAMES, fps=60, strain_limit=limit)
    return {"limit": limit, "with": peak_strain(c, run), "without": pick["baraff_witkin"],
            "explicit": pick["symplectic_euler"]}


def explicit_substeps(c: cloth.Cloth, fps: float = 60.0, limit: float | None = None) -> int:
    """Substeps per frame of symplectic Euler at 0.9 × its limit measured with damping on
    (``limit`` in s, measured here if not given)."""
    limit = cloth.explicit_dt_max(c) if limit is None else limit
    return int(np.ceil(1.0 / (fps * 0.9 * limit)))


@lru_cache(maxsize=4)
def explicit_limit(n: int, factor: float) -> float:
    """Symplectic Euler's limit (s) on the notebook's cloth, measured by bisection at ×1
    (:data:`TABLE_LIMIT` on the table's grid) and scaled by ``1/√factor``: every stiffness
    is ``factor`` times larger and every damping coefficient (``c = ζ 2 √(k m)``)
    ``√factor`` times, so the linear motion about the rest shape is the same in the time
    ``t √factor`` and so is its limit."""
    base = TABLE_LIMIT if n == TABLE_N else cloth.explicit_dt_max(scene(n, 1.0))
    return base / np.sqrt(factor)


def side_by_side(sheets) -> cloth.Cloth:
    """The sheets (same grid) as one cloth: particles numbered sheet after sheet, no
    spring between two sheets, every sheet's pins. Each sheet moves as it would alone;
    with XPBD only the order in which its springs are swept may differ (the independent
    sets are cut from the whole numbering)."""
    n = sheets[0].n
    nets = [c.network for c in sheets]
    net = springs.SpringNetwork(
        *(np.concatenate([getattr(m, a) + (k * n if a in "ij" else 0) for k, m in enumerate(nets)])
          for a in ("i", "j", "rest", "k", "c")), n * len(sheets),
        np.concatenate([m.kind for m in nets]))
    return cloth.Cloth(np.concatenate([c.x0 for c in sheets]), net,
                       np.concatenate([c.mass for c in sheets]),
                       np.concatenate([c.pinned + k * n for k, c in enumerate(sheets)]),
                       (len(sheets) * sheets[0].shape[0], sheets[0].shape[1]))


def one_sheet(run, k: int, n: int):
    """Sheet ``k`` (of ``n`` particles) of a :func:`side_by_side` run."""
    part = slice(k * n, (k + 1) * n)
    return cloth.ClothRun(run.t, run.x[:, part], run.v[:, part], run.dt, run.stable, run.message,
                          run.iterations)


def work_per_second(method: str, run, substeps: int, fps: float = 60.0) -> float:
    """Force-sized evaluations per simulated second: explicit steps, CG iterations, L-BFGS
    iterations, or XPBD sweeps (one sweep corrects every spring once)."""
    if method == "symplectic_euler":
        return substeps * fps
    return float(run.iterations.sum()) * fps / (len(run.t) - 1)


def comparison(n: int = TABLE_N, factors=FACTORS, frames: int = TABLE_FRAMES):
    """Each method at each stiffness, one call per 1/60 s frame (symplectic Euler at 0.9 ×
    its measured limit): peak structural strain, energy change (J), work and CPU time per
    simulated second. Returns a list of dicts.

    XPBD's sheets run side by side as one cloth (:func:`side_by_side`): on a small sheet
    its 288 small steps cost mostly the overhead of each array operation, which the three
    sheets then share. Its CPU time is measured on each sheet alone, over
    :data:`TIMED_FRAMES` frames (every frame costs the same)."""
    scenes = [scene(n, factor) for factor in factors]
    together = cloth.simulate(side_by_side(scenes), "xpbd", frames=frames, fps=60)
    rows = []
    for k, (factor, c) in enumerate(zip(factors, scenes, strict=True)):
        substeps = explicit_substeps(c, limit=explicit_limit(n, factor))
        for method in METHOD_NAMES:
            start = time.process_time()
            if method == "xpbd":
                cloth.simulate(c, method, frames=TIMED_FRAMES, fps=60)
                seconds = (time.process_time() - start) * 60 / TIMED_FRAMES
                run = one_sheet(together, k, c.n)
            else:
                run = cloth.simulate(c, method, frames=frames, fps=60,
                                     substeps=substeps if method == "symplectic_euler" else 1)
                seconds = (time.process_time() - start) * 60 / frames
            energy = cloth.energies(c, run.x, run.v)["total"]
            rows.append({"factor": factor, "method": method, "stable": run.stable,
                         "peak": peak_strain(c, run), "energy": float(energy[-1] - energy[0]),
                         "work": work_per_second(method, run, substeps), "seconds": seconds})
    return rows


#: The drape: a 22 × 22 cloth of 0.9 m and 0.15 kg, 0.35 m above a 0.2 m sphere on the ground.
DRAPE = {"n": 22, "size": 0.9, "total_mass": 0.15, "radius": 0.2, "height": 0.35}


def drape(frames: int = 48, fps: float = 30.0, factor: float = 10.0, self_collision: bool = True):
    """The drape (see :data:`DRAPE`): fast mass-springs at 1/60 s per step; after every
    step particle self-collision at 60 % of the grid spacing, then contact with the sphere
    (grown by 3 % for thickness) and the ground (friction 0.5), so that no particle ends a
    step inside either. Returns ``(cloth, run, thickness)``."""
    n, size = DRAPE["n"], DRAPE["size"]
    c = cloth.sheet(n=n, size=size, total_mass=DRAPE["total_mass"], k_struct=K_DEFAULT * factor,
                    damping_ratio=DAMPING_RATIO, height=DRAPE["height"], pinned="none")
    radius = DRAPE["radius"]
    thickness = 0.6 * size / (n - 1)
    steps = [collisions.self_contact(thickness)] if self_collision else []
    steps += [collisions.sphere((0.0, 0.0, 0.0), 1.03 * radius, friction=0.5),
              collisions.plane((0.0, 1.0, 0.0), -radius, restitution=0.0, friction=0.5)]
    run = cloth.simulate(c, "fast_mass_spring", frames=frames, fps=fps,
                         substeps=max(1, round(60 / fps)), post_step=collisions.chain(*steps))
    return c, run, thickness


def close_pairs(x, thickness: float) -> int:
    """How many pairs of particles are closer than ``thickness`` (less a part in 10⁹)."""
    from scipy.spatial import cKDTree

    return len(cKDTree(x).query_pairs(thickness * (1 - 1e-9), output_type="ndarray"))

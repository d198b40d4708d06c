"""Notebook 13 (SPH liquids): the runs of Sections 5 to 8, time steps and the dam break.

Holds a dam-break state to step from (:func:`dam_state`), the step each method allows
(:func:`step_study`, summarised by :func:`step_table`), how far IISPH's first-order density
prediction is from the density reached (:func:`prediction_study`), the dam break against
Martin & Moyce (:func:`dam_run`, :func:`front_errors`, :func:`best_shift`) and how its front
depends on resolution, viscosity, the floor and the release (:func:`front_study`: at once,
or by a gate lifted at :data:`GATE_SPEED`). Built on :mod:`course_lib.sph`.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import sph
from ..sph import density, iisph, scenes

#: The notebook's dam break: about 800 particles (20 × 40), IISPH.
N_DAM = 800
#: The step study's dam break (15 × 30 particles), up to T = 1.5 (0.34 s).
N_STUDY, T_STUDY = 450, 1.5
#: The (method, Courant number λ) pairs of the step study; both λ count lattice spacings.
STUDY_RUNS = (("wcsph", 0.4), ("wcsph", 2.0), ("wcsph", 2.4), ("wcsph", 2.8),
              ("iisph", 0.4), ("iisph", 1.2), ("iisph", 1.6))
#: The release delay ΔT that the Lethe project's Martin & Moyce example adds to its
#: simulated times (``examples/multiphysics/dam-break``, chaos-polymtl/lethe): chosen for
#: another solver (volume of fluid), not fitted to ours.
RELEASE_DELAY = 0.175
#: Delays ΔT tried by :func:`best_shift`.
SHIFTS = np.round(np.arange(0.0, 0.305, 0.01), 2)
#: The speed of the notebook's gate, in units of √(g a): a gate lifted at √(g a) clears
#: the column's height h₀ = 2a in √(2 h₀/g), the fall time that Lauber & Hager (1998) allow
#: the barrier of an instantaneous dam break.
GATE_SPEED = 1.0
#: The front study's runs besides the notebook's own (800 particles, our ν, released at
#: once): label -> (particles, changes to :func:`course_lib.sph.scenes.liquid` or the scene).
FRONT_RUNS = {"450 particles": (450, {}),
              "800, ν = 0": (N_DAM, {"viscosity": 0.0, "wall_viscosity": 0.0}),
              "800, no-slip floor": (N_DAM, {"wall_velocity": "no-slip"}),
              "800, gate at √(ga)": (N_DAM, {"gate_speed": GATE_SPEED})}


class _MartinMoyce:
    """Martin & Moyce's (1952) normalisation of a front ``z`` (m) at times ``t`` (s) for a
    column of width ``a`` (m): ``T = t √(2g/a)`` and ``Z = z / a``."""

    @property
    def T(self) -> np.ndarray:
        """Martin & Moyce's time ``t √(2g/a)``."""
        return self.t * np.sqrt(2 * scenes.G / self.a)

    @property
    def Z(self) -> np.ndarray:
        """Martin & Moyce's front ``z / a``."""
        return self.z / self.a


@dataclass
class DamRun(_MartinMoyce):
    """A dam break of column width ``a`` (m): times ``t`` (s) and fronts ``z`` (m) at the
    start and after every step, the frames, the CPU time (s) and the simulation."""

    t: np.ndarray
    z: np.ndarray
    a: float
    frames: sph.Frames | None
    cpu: float
    sim: sph.Simulation


    @property
    def viscosity(self) -> float:
        """The run's artificial viscosity ν (m²/s)."""
        return float(self.sim.params.viscosity)

    @property
    def cost_per_second(self) -> float:
        """CPU seconds per simulated second."""
        return self.cpu / self.sim.t

    @property
    def steps_per_second(self) -> float:
        """Steps per simulated second."""
        return self.sim.steps / self.sim.t


def dam_run(n_particles: int = N_DAM, method: str = "iisph", T_end: float = 3.5,
            frames: int = 0, a: float = 1.0, **changes) -> DamRun:
    """Martin & Moyce's dam break up to ``T_end``, saving ``frames`` evenly spaced frames
    (0: none); ``changes`` go to :func:`course_lib.sph.scenes.liquid`."""
    sim = scenes.dam_break_simulation(n_particles, method, a, **changes)
    t_end = T_end * np.sqrt(a / (2 * scenes.G))
    fronts = [scenes.front(sim.x, sim.params.spacing)]
    start = time.process_time()
    saved = sim.run(t_end, frame_dt=t_end / frames if frames else None,
                    on_step=lambda s: fronts.append(scenes.front(s.x, s.params.spacing)))
    cpu = time.process_time() - start
    t = np.concatenate([[0.0], sim.history["t"]])
    return DamRun(t, np.array(fronts), a, saved if frames else None, cpu, sim)


def front_errors(run: DamRun, delay: float = 0.0) -> np.ndarray:
    """``Z / Z_MM - 1`` at Martin & Moyce's 15 times, the run delayed by ``delay`` (in T)."""
    return scenes.front_errors(run.t, run.z, run.a, delay=delay)


def best_shift(run: DamRun, shifts=SHIFTS) -> tuple[float, float]:
    """The delay ``ΔT`` that brings the run's front closest to Martin & Moyce's (smallest
    largest relative error), and that error."""
    errors = [np.max(np.abs(front_errors(run, s))) for s in shifts]
    k = int(np.argmin(errors))
    return float(shifts[k]), float(errors[k])


def gate_speed(a: float = 1.0, froude: float = GATE_SPEED) -> float:
    """The gate's lifting speed (m/s) for a column of width ``a`` (m): ``froude · √(g a)``."""
    return froude * float(np.sqrt(scenes.G * a))


def front_study(main: DamRun | None = None, runs=None) -> dict[str, DamRun]:
    """The notebook's dam break (``main``, or a new run of :data:`N_DAM` particles) and the
    variants of ``runs`` (default :data:`FRONT_RUNS`), by label; the first is ``"800
    particles"``. A ``gate_speed`` change is in units of √(g a)."""
    out = {f"{N_DAM} particles": main if main is not None else dam_run()}
    for label, (n, changes) in (FRONT_RUNS if runs is None else runs).items():
        changes = dict(changes)
        if "gate_speed" in changes:
            changes["gate_speed"] = gate_speed(1.0, changes["gate_speed"])
        out[label] = dam_run(n, **changes)
    return out


#: The front study's variants (:data:`FRONT_RUNS`) as :func:`make_stored_fronts` saved them:
#: four dam breaks, about 5 s of CPU, that the notebook loads instead of running
#: (``tests/test_nb13_sph_liquids.py`` runs them again and fails if they drift).
STORED_FRONTS = Path(__file__).with_name("nb13_fronts.npz")


@dataclass
class StoredFront(_MartinMoyce):
    """A stored dam-break front: times ``t`` (s) and fronts ``z`` (m) after every step,
    column width ``a`` (m) and viscosity ν (m²/s); ``T``, ``Z`` as in :class:`DamRun`."""

    t: np.ndarray
    z: np.ndarray
    a: float
    viscosity: float


def make_stored_fronts(path: Path | None = STORED_FRONTS) -> dict[str, StoredFront]:
    """Run the variants of :data:`FRONT_RUNS` (:func:`front_study` without the notebook's
    own run) and save their fronts to ``path`` (``None``: do not save)."""
    fresh = front_study(main=StoredFront(np.zeros(1), np.zeros(1), 1.0, 0.0))
    out = {label: StoredFront(run.t, run.z, run.a, run.viscosity)
           for label, run in list(fresh.items())[1:]}
    if path is not None:
        arrays = {"labels": np.array(list(out))}
        for k, run in enumerate(out.values()):
            arrays.update({f"t{k}": run.t, f"z{k}": run.z, f"a{k}": run.a, f"nu{k}": run.viscosity})
        np.savez_compressed(path, **arrays)
    return out


def stored_front_study(main: DamRun) -> dict:
    """:func:`front_study` with the notebook's run ``main`` and the stored variants
    (:data:`STORED_FRONTS`), by label."""
    with np.load(STORED_FRONTS) as f:
        stored = {str(label): StoredFront(f[f"t{k}"], f[f"z{k}"], float(f[f"a{k}"]), float(f[f"nu{k}"]))
                  for k, label in enumerate(f["labels"])}
    return {f"{N_DAM} particles": main, **stored}


def step_study(n_particles: int = N_STUDY, T_end: float = T_STUDY, runs=STUDY_RUNS) -> dict:
    """The dam break with each method at several Courant numbers: ``{(method, λ): DamRun}``."""
    return {(method, cfl): dam_run(n_particles, method, T_end, cfl=cfl) for method, cfl in runs}


def step_table(study: dict) -> list[dict]:
    """One row per run of :func:`step_study`: ``method``, ``cfl``, ``stable``, ``message``,
    ``steps``, ``dt`` (mean, s), ``sound`` (largest ``c Δt/Δx``), ``flow`` (largest
    ``|v|max Δt/Δx``, the fastest particle's move in one step), ``sweeps`` and
    ``max_sweeps`` (mean and largest, IISPH), ``mean`` (the mean compression at the worst
    step), ``max`` (the largest compression of any particle) and ``Z`` (the last front)."""
    rows = []
    for (method, cfl), run in study.items():
        h, prm = run.sim.history, run.sim.params
        dt = np.array(h["dt"])
        rows.append({"method": method, "cfl": cfl, "stable": run.sim.stable, "steps": run.sim.steps,
                     "message": run.sim.message, "dt": float(np.mean(dt)),
                     "sound": float(np.max(dt) * prm.sound_speed / prm.spacing),
                     "flow": float(np.max(np.array(h["speed"]) * dt, initial=0.0) / prm.spacing),
                     "sweeps": float(np.mean(h["iterations"])), "max_sweeps": int(np.max(h["iterations"])),
                     "mean": float(np.max(h["density_error"])), "max": float(np.max(h["max_density_error"])),
                     "Z": float(run.Z[-1])})
    return rows


def dam_state(T: float = 0.8, n_particles: int = N_STUDY) -> sph.Simulation:
    """The IISPH dam break of :func:`step_study` advanced to ``T``: a state to step from."""
    sim = scenes.dam_break_simulation(n_particles, "iisph")
    sim.run(T * np.sqrt(1.0 / (2 * scenes.G)))
    return sim


def prediction_study(sim: sph.Simulation, cfls=(0.4, 1.2, 1.6)) -> list[dict]:
    """One IISPH step from the state of ``sim`` at each Courant number: ``dt`` (s), ``flow``
    (``|v|max Δt/Δx``), ``sweeps``, the largest compression predicted (``ρ* + A p``, what the
    solve drives to ρ₀ on average) and reached (by summation at the new positions), and the
    largest ``|reached - predicted|/ρ₀``."""
    rows = []
    v_max = float(np.max(np.linalg.norm(sim.v, axis=1)))
    for cfl in cfls:
        prm = dataclasses.replace(sim.params, cfl=cfl,
                                  max_dt=cfl * sim.params.spacing / np.sqrt(2 * scenes.G))
        dt = iisph.cfl_step(prm, v_max, scenes.G)
        x, _, info = iisph.step(sim.x, sim.v, prm, sim.wall, dt, p_last=sim.p)
        nb = density.neighbourhood(x, prm.h, prm.kernel, sim.wall)
        reached = density.summation_density(nb, prm.mass, sim.wall.psi)
        rows.append({"cfl": cfl, "dt": dt, "flow": v_max * dt / prm.spacing,
                     "sweeps": info["iterations"],
                     "predicted": float(np.max(info["predicted"])) / prm.rho0 - 1.0,
                     "reached": float(np.max(reached)) / prm.rho0 - 1.0,
                     "gap": float(np.max(np.abs(reached - info["predicted"]))) / prm.rho0})
    return rows


def front_rules(frames: sph.Frames, spacing: float) -> dict[str, np.ndarray]:
    """The front (m) of each frame by three rules: the rightmost particle, the rightmost
    particle with a neighbour closer than 1.5 spacings (a lone droplet does not count), and
    the right edge of the last column of width Δx that holds two particles (water at least
    two particles deep); each plus half a spacing."""
    from scipy.spatial import cKDTree

    out = {"rightmost": [], "with a neighbour": [], "two deep": []}
    for x in frames.x:
        out["rightmost"].append(scenes.front(x, spacing))
        close = cKDTree(x).query_pairs(1.5 * spacing, output_type="ndarray").ravel()
        out["with a neighbour"].append(scenes.front(x[np.unique(close)], spacing))
        cells = np.clip(np.floor(x[:, 0] / spacing).astype(int), 0, None)
        deep = np.flatnonzero(np.bincount(cells) >= 2)
        out["two deep"].append((deep.max() + 1) * spacing)
    return {k: np.array(v) for k, v in out.items()}

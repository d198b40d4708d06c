"""Notebook 13 (SPH liquids): the studies of Sections 1 to 4 and the showcase clip.

Holds the kernels' normalisation by quadrature (:func:`normalisation_errors`), the pair
count against N (:func:`pair_counts`), the density at a wall (:func:`wall_density`), the
total force of a symmetric and a naive pressure force (:func:`momentum_study`), the water
column at rest (:func:`hydrostatic_column`) and the clip of the dam break
(:func:`showcase_animation`). The runs of Sections 5 to 8 (time steps, the dam break
against Martin & Moyce) are in :mod:`course_lib.lessons.nb13_runs`, the drawings in
:mod:`course_lib.lessons.nb13_drawings`. Built on :mod:`course_lib.sph`; the core never
imports this module.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad

from .. import sph
from ..sph import boundary, density, forces, kernels, scenes

_SHELL = {1: lambda r: 2.0, 2: lambda r: 2 * np.pi * r, 3: lambda r: 4 * np.pi * r * r}


def normalisation_errors(h: float = 0.1) -> dict[tuple[str, int], float]:
    """``∫ W dV - 1`` of every kernel in 1, 2 and 3 dimensions, by adaptive quadrature
    over the radius (``2πr dr`` in 2D, ``4πr² dr`` in 3D, both sides in 1D)."""
    out = {}
    for name, W in kernels.KERNELS.items():
        for dim in kernels.DIMS:
            shell = _SHELL[dim]
            value, _ = quad(lambda r, W=W, dim=dim, shell=shell: W(r, h, dim) * shell(r), 0.0,
                            kernels.SUPPORT[name] * h, points=[h] if name == "cubic" else None,
                            epsabs=0.0, epsrel=1e-13, limit=200)
            out[name, dim] = value - 1.0
    return out


def jittered_block(n_side: int, spacing: float = 1.0, jitter: float = 0.1, seed: int = 2026):
    """An ``n_side × n_side`` lattice block, each particle moved by up to ``jitter`` Δx."""
    rng = np.random.default_rng(seed)
    x = scenes.lattice(n_side * spacing, n_side * spacing, spacing)
    return x + rng.uniform(-jitter, jitter, x.shape) * spacing


def pair_counts(sides=(10, 20, 40, 80, 160), support_ratio: float = 2.4):
    """For square blocks of ``side²`` particles: N, the pairs within the support (each once,
    by :func:`course_lib.neighbors.pairs`) and the search's CPU time (s, best of 3)."""
    from .. import neighbors

    rows = []
    for side in sides:
        x = jittered_block(side)
        best = np.inf
        for _ in range(3):
            start = time.process_time()
            found = neighbors.pairs(x, support_ratio, sort=False)
            best = min(best, time.process_time() - start)
        rows.append((len(x), len(found), best))
    return np.array(rows)


def wall_density(rows: int = 3, spacing: float = 1.0, support_ratio: float = 2.4):
    """Density / ρ₀ of the first fluid ``rows`` above a flat floor of a wide lattice, with
    our walls (two lattice rows, each of a fluid particle's weight) and with Akinci's
    single layer of particles on the wall's surface (``ψ`` from :func:`boundary.akinci_psi`)."""
    h = support_ratio * spacing / kernels.SUPPORT["cubic"]
    fluid = scenes.lattice(61 * spacing, 8 * spacing, spacing, origin=(-30.5 * spacing, 0.0))
    xs = (np.arange(-40, 41)) * spacing
    layered = np.concatenate([np.stack([xs, np.full_like(xs, -(k + 0.5) * spacing)], axis=1)
                              for k in range(boundary.layers_needed(spacing, h))])
    single = np.stack([xs, np.zeros_like(xs)], axis=1)
    mass = boundary.lattice_volume(spacing, h)                 # ρ₀ = 1
    walls = {"lattice rows (ours)": boundary.Boundary(layered, mass),
             "Akinci single layer": boundary.Boundary(single, boundary.akinci_psi(single, 1.0, h))}
    column = np.flatnonzero(np.abs(fluid[:, 0]) < 0.25 * spacing)       # the x = 0 column
    probe = column[np.argsort(fluid[column, 1])][:rows]                   # bottom up
    out = {}
    for label, wall in walls.items():
        nb = density.neighbourhood(fluid, h, "cubic", wall)
        out[label] = density.summation_density(nb, mass, wall.psi)[probe]
    return out


def naive_pressure_acceleration(nb, mass: float, rho, p) -> np.ndarray:
    """``a_i = -(1/ρ_i) Σ_j m_j (p_j/ρ_j) ∇_i W_ij``: the plain SPH estimate of ``-∇p/ρ``
    (not symmetric in the pair: it does not conserve momentum)."""
    rho, p = np.asarray(rho, dtype=float), np.asarray(p, dtype=float)
    f_i = (mass * p[nb.j] / rho[nb.j])[:, None] * nb.gw
    f_j = -(mass * p[nb.i] / rho[nb.i])[:, None] * nb.gw
    return -density.scatter(nb.i, nb.j, f_i, nb.n, f_j) / rho[:, None]


def momentum_study(side: int = 20, steps: int = 100, seed: int = 2026):
    """A squeezed blob (spacing 0.9 Δx, jittered) expanding in empty space, no gravity, with
    WCSPH's symmetric force and with the naive one. Returns ``{name: (|P| after each step,
    Σ m|v| after each step (both kg m/s), bound)}``: the total momentum starts at 0, and
    round-off alone can move it by at most ``Σ_steps dt Σ m|a| · 64 ε`` (64 ε: generous
    for sums of about 20 pair terms per particle), the bound."""
    spacing = 0.02
    params = sph.Params(spacing=spacing, gravity=(0.0, 0.0), sound_speed=20.0)
    x0 = 0.9 * jittered_block(side, spacing, seed=seed)
    out = {}
    for name in ("symmetric", "naive"):
        x, v, m = x0.copy(), np.zeros_like(x0), params.mass
        momentum, scale, bound = [np.zeros(2)], [0.0], 0.0
        for _ in range(steps):
            nb = density.neighbourhood(x, params.h, params.kernel)
            rho = density.summation_density(nb, m)
            p = forces.tait_pressure(rho, params.rho0, params.sound_speed)
            a = (forces.pressure_acceleration(nb, m, rho, p) if name == "symmetric"
                 else naive_pressure_acceleration(nb, m, rho, p))
            dt = sph.wcsph.cfl_step(params, float(np.abs(v).max()), float(np.abs(a).max()))
            v = v + dt * a
            x = x + dt * v
            momentum.append(m * v.sum(axis=0))
            scale.append(m * np.sum(np.linalg.norm(v, axis=1)))
            bound += dt * m * np.sum(np.linalg.norm(a, axis=1)) * 64 * np.finfo(float).eps
        out[name] = (np.linalg.norm(np.array(momentum), axis=1), np.array(scale), bound)
    return out


@dataclass
class Column:
    """The water column at rest: row heights ``y`` (m), the row means of the time-averaged
    pressure ``p`` and of ``ρ₀ g (H - y)`` (Pa), the depth ``H``, support and spacing (m),
    the mean and largest compression over the average, the time-averaged mean vertical
    velocity (m/s) of the particles within two spacings of a side wall and of the others,
    and the simulation."""

    y: np.ndarray
    p: np.ndarray
    exact: np.ndarray
    depth: float
    support: float
    spacing: float
    density_error: float
    max_density_error: float
    side_vy: float
    middle_vy: float
    sim: sph.Simulation

    @property
    def below_top(self) -> np.ndarray:
        """Rows below the top layer: the top layer holds the particles whose kernel reaches
        the centres of the surface row (half a spacing below the surface), whose own
        neighbourhood is cut by the surface."""
        return self.depth - self.y >= self.support + 0.5 * self.spacing


def hydrostatic_column(t_end: float = 1.2, average: float = 0.2, method: str = "iisph",
                       **changes) -> Column:
    """A 0.5 m column of water in a 0.5 m box (spacing 25 mm, 400 particles), run to
    ``t_end`` (s); its pressure and density are averaged over the last ``average`` s and
    binned into the lattice's rows. ``changes`` go to :func:`course_lib.sph.water_column`
    (e.g. ``wall_pressure="mirrored"``)."""
    sim = sph.water_column(method=method, **changes)
    sim.run(t_end - average)
    first = sim.steps
    dx, width, depth = sim.params.spacing, 0.5, 0.5
    p_sum, x_sum, count, vy = np.zeros(sim.n), np.zeros_like(sim.x), [0], np.zeros(2)

    def add(s):
        p_sum[:] += s.p
        x_sum[:] += s.x
        count[0] += 1
        side = np.minimum(s.x[:, 0], width - s.x[:, 0]) < 2 * dx
        vy[:] += s.v[side, 1].mean(), s.v[~side, 1].mean()

    sim.run(t_end, on_step=add)
    p, y = p_sum / count[0], x_sum[:, 1] / count[0]
    row = np.clip(np.floor(y / dx).astype(int), 0, None)
    used = np.unique(row)
    mean = lambda a: np.array([a[row == k].mean() for k in used])   # noqa: E731
    exact = sim.params.rho0 * scenes.G * (depth - y)
    return Column(mean(y), mean(p), mean(exact), depth, sim.params.support, dx,
                  float(np.mean(sim.history["density_error"][first:])),
                  float(np.max(sim.history["max_density_error"][first:])),
                  *(vy / count[0]).tolist(), sim)


def showcase_animation(n_particles: int = 1800, seconds: float = 8.0, fps: float = 30.0,
                       simulated: float = 2.4):
    """The dam break as a 16:9 clip (``seconds`` at ``fps``, at most 10 s, showing
    ``simulated`` s in slow motion): the column collapses, runs along a 4 m tank, climbs
    the far wall and falls back; coloured by speed. Returns a
    ``matplotlib.animation.FuncAnimation``."""
    from .nb13_drawings import dam_animation

    if not 0 < seconds * fps <= 300:
        raise ValueError(f"a clip holds 1 to 300 frames (10 s at 30 fps), got {seconds} s at {fps} fps")
    n = round(seconds * fps)
    sim = scenes.dam_break_simulation(n_particles, "iisph", tank=4.0)
    frames = sim.run(simulated, frame_dt=simulated / max(n - 1, 1))
    return dam_animation(frames, sim, fps=fps, size=(6.4, 3.6), tank=4.0, dpi=150)

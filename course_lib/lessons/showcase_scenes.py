"""One showcase animation per notebook 01-11: the picture a clip of that notebook shows.

Each ``nbNN()`` builds a ``matplotlib.animation.FuncAnimation`` from the notebook's own
lesson module (its runners and drawings, used as they are) and the core, with the
numerical answer beside the exact one where the notebook has one. Each frame function
returns the artists it changes, so a clip draws only those (see :mod:`course_lib.clips`);
notebook 01's redraws its axes, so its clip draws every frame in full. ``frames`` sets the
number of frames (each builder has a default of a few seconds at its frame rate).
:mod:`.showcase` registers them and renders them into clips.
"""

from __future__ import annotations

from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation

from .. import boids, fields
from ..integrators import integrate
from ..plotting import EXACT_STYLE, METHOD_COLORS, METHOD_LABELS, use_course_style


def _figure(size=(6.4, 3.6)):
    use_course_style()
    fig = plt.figure(figsize=size, dpi=100, layout="constrained")
    plt.close(fig)  # a clip is drawn off screen; pyplot must not show it
    return fig


def _steps(total: int, frames: int) -> np.ndarray:
    return np.linspace(0, total, frames).round().astype(int)


def nb01(frames: int = 90) -> FuncAnimation:
    """Notebook 01: boids in a box align into a flock (the notebook's flocking demo)."""
    from . import nb01_vector_fields as lesson

    flock = lesson.run_flock(n=80, steps=450)
    fig = _figure((4.8, 4.8))
    ax = fig.add_subplot()
    steps = _steps(450, frames)

    def draw(j):
        ax.clear()
        lesson.draw_flock(ax, flock, steps[j])

    return FuncAnimation(fig, draw, frames=frames, interval=1000 / 30)


def _orbit_movie(runs: dict, title: str, frames: int, reach: float = 3.0) -> FuncAnimation:
    """Points moving on the vortex field, one per method, beside the exact unit circle, in
    a window ``reach`` (m) wide on each side (a method that spirals out leaves it)."""
    fig = _figure((4.8, 4.8))
    ax = fig.add_subplot()
    circle = np.linspace(0, 2 * np.pi, 400)
    ax.plot(np.cos(circle), np.sin(circle), **EXACT_STYLE, label="exact path (r = 1 m)")
    n = min(len(r.t) for r in runs.values())
    steps = _steps(n - 1, frames)
    artists = {}
    for name, r in runs.items():
        color = METHOD_COLORS.get(name, "C0")
        (line,) = ax.plot([], [], "-", color=color, lw=1.2, alpha=0.8)
        (dot,) = ax.plot([], [], "o", color=color, ms=7, label=METHOD_LABELS.get(name, name))
        artists[name] = (line, dot, r.y)
    ax.set(xlim=(-reach, reach), ylim=(-reach, reach), aspect="equal", xlabel="x (m)", ylabel="y (m)")
    ax.legend(loc="upper right", fontsize=8)
    head = ax.set_title(title, fontsize=10)
    t = next(iter(runs.values())).t

    def draw(j):
        k = steps[j]
        for line, dot, y in artists.values():
            line.set_data(y[: k + 1, 0], y[: k + 1, 1])
            dot.set_data([y[k, 0]], [y[k, 1]])
        head.set_text(f"{title}, t = {t[k]:.1f} s")
        return [a for line, dot, _ in artists.values() for a in (line, dot)] + [head]

    return FuncAnimation(fig, draw, frames=frames, interval=1000 / 15)


def nb02(frames: int = 60) -> FuncAnimation:
    """Notebook 02: forward Euler spirals out of the vortex's circle, by √(1 + dt²) a step."""
    run = integrate(fields.vortex, [1.0, 0.0], (0.0, 4 * np.pi), 0.25, "forward_euler")
    return _orbit_movie({"forward_euler": run}, "forward Euler, dt = 0.25 s", frames, reach=2.5)


def nb03(frames: int = 40) -> FuncAnimation:
    """Notebook 03: dx/dt = -x by forward Euler on both sides of the limit dt = 2 s."""
    fig = _figure()
    ax = fig.add_subplot()
    t_end = 24.0
    fine = np.linspace(0, t_end, 400)
    ax.plot(fine, np.exp(-fine), **EXACT_STYLE, label="exact e^(-t)")
    runs = {dt: integrate(lambda t, x: -x, [1.0], (0.0, t_end), dt, "forward_euler") for dt in (1.5, 2.2)}
    lines = {dt: ax.plot([], [], "o-", ms=4, label=f"forward Euler, dt = {dt} s "
                         f"({'stable' if dt < 2 else 'unstable'})")[0] for dt in runs}
    ax.set(xlim=(0, t_end), ylim=(-6, 6), xlabel="t (s)", ylabel="x")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title("|1 - dt| < 1 decays; dt > 2 s grows (notebook 03)", fontsize=10)

    def draw(j):
        now = t_end * (j + 1) / frames
        for dt, r in runs.items():
            keep = r.t <= now
            lines[dt].set_data(r.t[keep], r.y[keep, 0])
        return list(lines.values())

    return FuncAnimation(fig, draw, frames=frames, interval=1000 / 10)


def nb04(frames: int = 75) -> FuncAnimation:
    """Notebook 04: forward Euler, midpoint and RK4 on the vortex at the same step."""
    runs = {m: integrate(fields.vortex, [1.0, 0.0], (0.0, 4 * np.pi), 0.5, m)
            for m in ("forward_euler", "midpoint", "rk4")}
    return _orbit_movie(runs, "dt = 0.5 s", frames, reach=2.0)


def nb05(frames: int = 75) -> FuncAnimation:
    """Notebook 05: a unit oscillator in the phase plane; forward Euler gains energy, the
    symplectic methods stay on a band around the exact circle."""
    def f(t, y):
        return np.stack((y[1], -y[0]))

    runs = {}
    for m in ("forward_euler", "symplectic_euler", "velocity_verlet"):
        r = integrate(f, [[1.0], [0.0]], (0.0, 6 * np.pi), 0.3, m)
        runs[m] = SimpleNamespace(t=r.t, y=r.y[:, :, 0])  # (steps, 2): position and velocity
    movie = _orbit_movie(runs, "x'' = -x, dt = 0.3 s", frames, reach=2.5)
    movie._fig.axes[0].set(xlabel="x (m)", ylabel="v (m/s)")
    return movie


def nb06(frames: int = 90) -> FuncAnimation:
    """Notebook 06: a small star cluster under softened gravity (symplectic Euler)."""
    from . import nb06_forces as lesson

    mass, y0 = lesson.cluster(n=8)
    f = lesson.cluster_gravity(mass)
    run = integrate(f, y0[:, None], (0.0, 12.0), 0.01, "symplectic_euler")
    x = run.y[:, 0, 0]  # (steps, N, 2)
    fig = _figure((4.8, 4.8))
    ax = fig.add_subplot()
    steps = _steps(len(run.t) - 1, frames)
    trails = [ax.plot([], [], "-", lw=0.8, alpha=0.6)[0] for _ in range(x.shape[1])]
    dots = ax.scatter(x[0, :, 0], x[0, :, 1], s=30, c=[f"C{i}" for i in range(x.shape[1])], zorder=3)
    ax.set(xlim=(-1.6, 1.6), ylim=(-1.6, 1.6), aspect="equal", xlabel="x", ylabel="y")
    head = ax.set_title("", fontsize=10)

    def draw(j):
        k = steps[j]
        for i, line in enumerate(trails):
            line.set_data(x[: k + 1, i, 0], x[: k + 1, i, 1])
        dots.set_offsets(x[k])
        head.set_text(f"8 bodies, softened gravity (G = 1), t = {run.t[k]:.1f}")
        return [*trails, dots, head]

    return FuncAnimation(fig, draw, frames=frames, interval=1000 / 30)


def nb07(frames: int = 90) -> FuncAnimation:
    """Notebook 07: a damped mass on a spring, the numerical stretch beside the exact one."""
    from . import nb07_spring_runs as lesson

    run = lesson.run_spring(k=10.0, c=0.4, dt=0.05, t_end=12.0)
    fig = _figure()
    box, ax = fig.subplots(1, 2, gridspec_kw={"width_ratios": (1, 2.4)})
    ax.plot(run.t_fine, run.exact_fine, **EXACT_STYLE, label="exact")
    (trace,) = ax.plot([], [], color=METHOD_COLORS.get("symplectic_euler", "C1"),
                       label="symplectic Euler, dt = 0.05 s")
    ax.set(xlim=(0, run.t[-1]), ylim=(-0.12, 0.12), xlabel="t (s)", ylabel="stretch x (m)")
    ax.legend(loc="upper right", fontsize=8)
    (coil,) = box.plot([], [], color="0.3", lw=1.2)
    block = box.scatter([0], [0], s=500, marker="s", color="C0", zorder=3)
    box.set(xlim=(-0.5, 0.5), ylim=(-1.2, 0.15), xticks=[], ylabel="height (m)")
    box.axhline(0.0, color="0.2", lw=3)
    steps = _steps(len(run.t) - 1, frames)
    zig = np.linspace(0, 1, 41)

    def draw(j):
        k = steps[j]
        bottom = -0.8 - 2 * run.x[k]  # drawn at twice the stretch, to be seen
        coil.set_data(0.12 * np.sign(np.sin(zig * 20 * np.pi)) * (0 < zig) * (zig < 1), bottom * zig)
        block.set_offsets([[0.0, bottom]])
        trace.set_data(run.t[: k + 1], run.x[: k + 1])
        return coil, block, trace

    return FuncAnimation(fig, draw, frames=frames, interval=1000 / 30)


def nb08(frames: int = 60) -> FuncAnimation:
    """Notebook 08: a 16-particle strand swinging under gravity (the notebook's movie)."""
    from .. import hair, springs
    from . import nb08_hair_chains as lesson

    x0, net = springs.hair_chain(**hair.STRAND)
    run = hair.simulate(x0, net, frames=frames - 1, substeps=160)  # the start is a frame too
    return lesson.animate(run.frames, net, size=(4.6, 3.3), xlim=(-0.32, 0.34), ylim=(-0.34, 0.06),
                          title="a hair strand, edge springs only")


def nb09(frames: int = 20) -> FuncAnimation:
    """Notebook 09: the Genesis ring of particles (Reeves 1983), every third frame of the run."""
    from . import nb09_drawings as drawings
    from . import nb09_particle_systems as lesson

    total = 3 * frames + 2
    run = lesson.run(lesson.genesis(), lesson.gravity_bounce(0.3), total,
                     snapshot_frames=range(2, total, 3))
    return drawings.animate_genesis(run.snapshots, lesson.DT)


def nb10(frames: int = 100) -> FuncAnimation:
    """Notebook 10: Reynolds' boids in groups, found by the k-d tree."""
    from . import nb10_flocking as lesson

    rules = boids.Rules(box=lesson.BOX)
    x, v = boids.random_flock(lesson.N_BOIDS, lesson.BOX, 1.0, np.random.default_rng(2026))
    fig = _figure((4.8, 4.8))
    ax = fig.add_subplot()
    arrows = ax.quiver(x[:, 0], x[:, 1], v[:, 0], v[:, 1], np.arctan2(v[:, 1], v[:, 0]), cmap="hsv",
                       clim=(-np.pi, np.pi), angles="xy", scale_units="xy", scale=1.4, width=0.007)
    ax.set(xlim=(0, lesson.BOX), ylim=(0, lesson.BOX), aspect="equal", xlabel="x (m)", ylabel="y (m)")
    head = ax.set_title("", fontsize=10)
    state = {"x": x, "v": v}

    def draw(j):
        for _ in range(2):
            state["x"], state["v"] = boids.step(state["x"], state["v"], lesson.DT, rules)
        x, v = state["x"], state["v"]
        arrows.set_offsets(x)
        arrows.set_UVC(v[:, 0], v[:, 1], np.arctan2(v[:, 1], v[:, 0]))
        head.set_text(f"{lesson.N_BOIDS} boids, t = {2 * (j + 1) * lesson.DT:.1f} s (colour: heading)")
        return arrows, head

    return FuncAnimation(fig, draw, frames=frames, interval=1000 / 30)


def nb11(frames: int = 31) -> FuncAnimation:
    """Notebook 11: a cloth draped on a sphere, Baraff & Witkin's implicit step."""
    from . import nb11_cloth as lesson
    from . import nb11_drawings as drawings

    cloth, run = lesson.drape(frames=max(frames - 1, 1))
    return drawings.animate_drape(run, cloth.shape, lesson.SPHERE_RADIUS, fps=15.0, frames=frames)

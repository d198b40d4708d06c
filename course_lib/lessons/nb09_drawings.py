"""Notebook 09 (particle systems): the drawings and the kernel-free animation.

Holds one function per picture of the notebook (emitter shapes, fountain, fire and smoke,
the Genesis ring, particles in notebook 01's fields, the population against theory) and
:func:`animate_genesis`. Imports matplotlib, the core and the scenes of
:mod:`course_lib.lessons.nb09_particle_systems`; the core never imports this module.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import LinearSegmentedColormap

from .. import fields
from ..plotting import EXACT_STYLE

#: Colour of a gas particle by temperature: grey smoke when cold, through dark red and
#: orange, to a pale yellow flame at 1600 K. An artistic ramp, not physics: a real glowing
#: body at 1600 K looks orange (blackbody sRGB about (255, 115, 0)).
TEMPERATURE_COLORS = LinearSegmentedColormap.from_list("fire", [
    (0.0, (0.55, 0.55, 0.55)), (0.12, (0.35, 0.3, 0.3)), (0.3, (0.55, 0.05, 0.0)),
    (0.55, (0.95, 0.35, 0.0)), (0.8, (1.0, 0.75, 0.2)), (1.0, (1.0, 1.0, 0.8))])
T_RANGE = (300.0, 1600.0)
#: Colour by age for sparks: pale yellow when young, orange, red, then a light violet when
#: old: every age stays bright on the dark sky of the Genesis views.
AGE_CMAP = LinearSegmentedColormap.from_list("sparks", [
    (0.0, (1.0, 1.0, 0.65)), (0.3, (1.0, 0.65, 0.1)), (0.6, (0.95, 0.25, 0.2)),
    (1.0, (0.8, 0.55, 1.0))])
#: Background of the Genesis views (a night sky).
SKY = "0.12"


def oblique(x, elevation: float = 15.0) -> tuple[np.ndarray, np.ndarray]:
    """Screen coordinates of 3D points seen from the front and ``elevation`` degrees
    above: ``(x, y cos e + z sin e)`` (m); points with larger z appear higher."""
    e = np.radians(elevation)
    return x[:, 0], x[:, 1] * np.cos(e) + x[:, 2] * np.sin(e)


def draw_shapes(samples: dict, radius: float):
    """The four generation shapes seen from above: ``samples`` maps a shape to points."""
    fig, axes = plt.subplots(1, len(samples), figsize=(11, 3.0), constrained_layout=True)
    for ax, (name, x) in zip(axes, samples.items(), strict=True):
        ax.scatter(x[:, 0], x[:, 2], s=3, color="C0", alpha=0.6, linewidths=0)
        ax.set(title=f"{name} ({len(x)} points)", xlabel="x (m)", aspect="equal",
               xlim=(-1.2 * radius, 1.2 * radius), ylim=(-1.2 * radius, 1.2 * radius))
    axes[0].set_ylabel("z (m)")
    return fig


def draw_disc_radii(good: np.ndarray, naive: np.ndarray, radius: float):
    """Histogram of the distance to the centre of disc samples, right and naive."""
    fig, ax = plt.subplots(figsize=(6.5, 3.4))
    bins = np.linspace(0.0, radius, 21)
    ax.hist(naive, bins=bins, density=True, color="C3", alpha=0.5, label=r"naive $r = R\,u$")
    ax.hist(good, bins=bins, density=True, color="C0", alpha=0.6, label=r"$r = R\sqrt{u}$")
    r = np.linspace(0.0, radius, 100)
    ax.plot(r, 2 * r / radius**2, **EXACT_STYLE, label=r"uniform by area: $2r/R^2$")
    ax.set(xlabel="distance from the centre r (m)", ylabel="density (1/m)",
           title=f"{len(good)} points on a disc of radius {radius:g} m")
    ax.legend(loc="upper left")
    return fig


def draw_fountain(snap: dict, restitution: float):
    """Side view of a fountain snapshot, coloured by age."""
    fig, ax = plt.subplots(figsize=(8.5, 3.6), constrained_layout=True)
    sc = ax.scatter(snap["x"][:, 0], snap["x"][:, 1], c=snap["age"], s=4, cmap="viridis",
                    linewidths=0)
    ax.axhline(0.0, color="0.3", lw=1)
    fig.colorbar(sc, ax=ax, label="age (s)", pad=0.01, shrink=0.75)
    ax.set(xlabel="x (m)", ylabel="height y (m)", aspect="equal", ylim=(-0.1, 2.2),
           title=f"fountain: {len(snap['age'])} particles, ground restitution {restitution:g}")
    return fig


def draw_fountain_offset(age: np.ndarray, drop: np.ndarray, predicted: np.ndarray):
    """Height below the exact parabola against age (the formula as a thin dashed line under
    the measured dots), and what is left of it once the formula is taken away."""
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 3.5), constrained_layout=True)
    order = np.argsort(age)
    ax1.plot(age[order], 100 * predicted[order], **{**EXACT_STYLE, "linewidth": 1.0}, zorder=1,
             label=r"$\frac{1}{2} g\,dt\,t$")
    ax1.plot(age, 100 * drop, "o", ms=3, mfc="none", mew=0.6, color="C0", zorder=2,
             label=f"each of {len(age)} drops (symplectic Euler)")
    ax1.set(xlabel="age t (s)", ylabel="below the parabola (cm)",
            title="the fountain without a ground, dt = 1/30 s")
    ax1.legend(loc="upper left")
    ax2.plot(age, 1e15 * (drop - predicted), ".", ms=3, color="C0")
    ax2.axhline(0.0, color="0.4", lw=0.8)
    ax2.set(xlabel="age t (s)", ylabel=r"residual ($10^{-15}$ m)",
            title=r"drop $-\ \frac{1}{2} g\,dt\,t$: what the formula leaves is round-off")
    return fig


def draw_population(t, population, expected, *, given=None, little=None, title: str = "",
                    zoom_from: float | None = None):
    """Live particles per frame beside the exact expectation, the expectation given the
    counts the run actually emitted (``given``), and Little's law; with ``zoom_from`` (s),
    a second panel shows the frames from then on at a scale where the curves part."""
    panels = {"ncols": 1, "figsize": (7.5, 3.5)} if zoom_from is None else \
        {"ncols": 2, "figsize": (11.0, 3.5), "width_ratios": (1.2, 1.0)}
    fig, axes = plt.subplots(1, squeeze=False, constrained_layout=True, **panels)
    for k, ax in enumerate(axes[0]):
        shown = slice(None) if k == 0 else np.asarray(t) >= zoom_from
        ax.plot(t[shown], population[shown], color="C0", lw=1, label="measured")
        ax.plot(t[shown], expected[shown], **EXACT_STYLE, label="expected (exact)")
        if given is not None:
            ax.plot(t[shown], given[shown], color="C1", lw=1.2, alpha=0.9,
                    label="expected, given the counts emitted")
        if little is not None:
            ax.axhline(little, color="C3", lw=1, ls=":", label=f"rate × mean lifetime = {little:g}")
        ax.set(xlabel="t (s)", ylabel="live particles")
    axes[0, 0].set(title=title, ylim=(0, None))
    axes[0, 0].legend(loc="lower right")
    if zoom_from is not None:
        axes[0, 1].set_title(f"from {zoom_from:g} s on, enlarged")
    return fig


def draw_fire(snap: dict, ambient: float = 300.0, tau: float = 0.4, t0: float = 1600.0):
    """Fire and smoke coloured by temperature, and temperature against age."""
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4.6), width_ratios=(1, 1.4),
                                   constrained_layout=True)
    order = np.argsort(snap["temperature"])          # hot particles drawn last, on top
    x, temp, age = snap["x"][order], snap["temperature"][order], snap["age"][order]
    ax1.set_facecolor("0.08")
    sc = ax1.scatter(x[:, 0], x[:, 1], c=temp, cmap=TEMPERATURE_COLORS, vmin=T_RANGE[0],
                     vmax=T_RANGE[1], s=14, alpha=0.5, linewidths=0)
    fig.colorbar(sc, ax=ax1, label="temperature (K)", orientation="horizontal", location="bottom",
                 shrink=0.9, aspect=30)
    ax1.set(xlabel="x (m)", ylabel="height y (m)", aspect="equal", xlim=(-1.0, 1.0),
            title=f"{len(temp)} particles")
    ax1.grid(False)
    a = np.linspace(0.0, age.max(), 200)
    ax2.plot(age, temp, ".", ms=3, color="C1", label="every particle")
    ax2.plot(a, ambient + (t0 - ambient) * np.exp(-a / tau), **EXACT_STYLE,
             label=r"$T_a + (T_0 - T_a)\,e^{-t/\tau}$")
    ax2.set(xlabel="age t (s)", ylabel="temperature (K)", title="cooling")
    ax2.legend()
    return fig


def draw_genesis(snap: dict, radius: float):
    """The Genesis ring from above and from a low oblique view, coloured by age."""
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.3), width_ratios=(1, 1.6),
                                   constrained_layout=True)
    x, age = snap["x"], snap["age"]
    order = np.argsort(-age)
    kw = dict(c=age[order], cmap=AGE_CMAP, vmin=0.0, vmax=1.6, s=3, linewidths=0)
    ax1.set_facecolor(SKY)
    ax1.grid(False)
    ax1.scatter(x[order, 0], x[order, 2], **kw)
    phi = np.linspace(0, 2 * np.pi, 200)
    ax1.plot(radius * np.cos(phi), radius * np.sin(phi), color="deepskyblue", lw=1.2, ls="--",
             zorder=3, label="front R(t)")     # above the sparks, in a colour none of them has
    ax1.set(xlabel="x (m)", ylabel="z (m)", aspect="equal", title="from above")
    ax1.legend(loc="upper right", fontsize=8, facecolor="0.3", labelcolor="white", edgecolor="none")
    sx, sy = oblique(x[order])
    ax2.set_facecolor(SKY)
    ax2.grid(False)
    sc = ax2.scatter(sx, sy, **kw)
    ax2.set(xlabel="x (m)", ylabel="screen height (m)", aspect="equal",
            title="seen from 15° above the ground")
    fig.colorbar(sc, ax=ax2, label="age (s)", shrink=0.8)
    return fig


def animate_genesis(snaps: dict, dt: float, extent: float = 4.5):
    """A ``FuncAnimation`` of the Genesis ring (oblique view) from ``snaps`` by frame."""
    from matplotlib.animation import FuncAnimation

    keys = sorted(snaps)
    fig, ax = plt.subplots(figsize=(4.4, 3.0))
    ax.set_facecolor(SKY)
    ax.grid(False)
    sc = ax.scatter([], [], s=2, c=[], cmap=AGE_CMAP, vmin=0.0, vmax=1.6, linewidths=0)
    ax.set(xlim=(-extent, extent), ylim=(-0.3 * extent, 0.7 * extent),
           xlabel="x (m)", ylabel="screen height (m)")
    title = ax.set_title("Genesis ring, t = 0.00 s, 0000 particles", fontsize=9)
    fig.tight_layout()                    # once: a layout engine would rerun every frame

    def update(k):
        s = snaps[keys[k]]
        order = np.argsort(-s["age"])
        sc.set_offsets(np.column_stack(oblique(s["x"][order])))
        sc.set_array(s["age"][order])
        title.set_text(f"Genesis ring, t = {(keys[k] + 1) * dt:.2f} s, {len(order)} particles")
        return sc, title

    return FuncAnimation(fig, update, frames=len(keys), interval=1000 * dt * (keys[1] - keys[0]))


def draw_fields(runs: dict, extent: float = 2.2):
    """Particles carried by notebook 01's fields, over faint streamlines, coloured by age."""
    fig, axes = plt.subplots(1, len(runs), figsize=(12, 3.5), constrained_layout=True)
    Xs, Ys = fields.grid(extent, 40)
    for ax, (name, (field, snap)) in zip(axes, runs.items(), strict=True):
        U, V = fields.sample(field, Xs, Ys)
        ax.streamplot(Xs, Ys, U, V, color="0.85", linewidth=0.7, density=0.8, arrowsize=0.6)
        sc = ax.scatter(snap["x"][:, 0], snap["x"][:, 1], c=snap["age"], s=4,
                        cmap="viridis", vmin=0.0, vmax=4.0, linewidths=0)
        ax.set(title=name, xlabel="x (m)", aspect="equal", xlim=(-extent, extent),
               ylim=(-extent, extent))
    axes[0].set_ylabel("y (m)")
    fig.colorbar(sc, ax=axes, label="age (s)", shrink=0.8)
    return fig

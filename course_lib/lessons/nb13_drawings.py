"""Notebook 13 (SPH liquids): the figures and the kernel-free dam-break animation.

Holds the three kernels and their slopes (:func:`draw_kernels`), the pair count against N
(:func:`draw_pairs`), the water column's pressure against ρgh (:func:`draw_hydrostatic`),
the surge front and its error against Martin & Moyce and Ritter (:func:`draw_front`) and the animation
coloured by speed (:func:`dam_animation`). Imports matplotlib and the core.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ..plotting import EXACT_STYLE
from ..sph import GRADIENTS, KERNELS, MARTIN_MOYCE, SUPPORT, ritter_front

KERNEL_COLORS = {"cubic": "C0", "poly6": "C1", "spiky": "C2"}
RUN_COLORS = {"iisph": "C0", "wcsph": "C3"}
#: The front study's runs, in order: the notebook's own first.
FRONT_COLORS = ("C0", "C1", "C4", "C5", "C3")


def draw_kernels(radius: float = 1.0):
    """W(r) and dW/dr of the three kernels in 2D, all with the support ``radius`` (m), and
    the distance Δx of the nearest lattice neighbours for our support of 2.4 Δx."""
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(9.0, 3.4))
    r = np.linspace(0.0, 1.1 * radius, 400)
    for name, W in KERNELS.items():
        h = radius / SUPPORT[name]
        ax.plot(r, W(r, h, 2), color=KERNEL_COLORS[name], label=f"{name} (h = {h:g} m)")
        ax2.plot(r, GRADIENTS[name](r, h, 2), color=KERNEL_COLORS[name], label=name)
    for axis in (ax, ax2):        # where the nearest neighbours sit with our support of 2.4 Δx
        axis.axvline(radius / 2.4, color="gray", ls=":", lw=1)
    ax2.text(radius / 2.4, ax2.get_ylim()[0] * 0.9, " r = Δx\n (support 2.4 Δx)", fontsize=7,
             color="gray", va="bottom")
    ax.set(xlabel="distance r (m)", ylabel="W (1/m²)", title="kernels in 2D, support 1 m")
    ax2.set(xlabel="distance r (m)", ylabel="dW/dr (1/m³)", title="their slopes")
    ax.legend(fontsize=8)
    ax2.legend(fontsize=8)
    fig.tight_layout()
    return fig


def draw_pairs(rows):
    """Pairs within the support against N (log-log), with the line of constant pairs per
    particle."""
    n, pairs, _ = rows.T
    fig, ax = plt.subplots(figsize=(5.0, 3.4))
    ax.loglog(n, pairs, "o-", label="pairs found (k-d tree)")
    per = pairs[-1] / n[-1]
    ax.loglog(n, per * n, **EXACT_STYLE, label=f"{per:.1f} N (pairs ∝ N)")
    ax.loglog(n, n * (n - 1) / 2, ":", color="gray", label="all N(N−1)/2 pairs")
    ax.set(xlabel="particles N", ylabel="pairs", title="neighbour pairs against N")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def draw_hydrostatic(col):
    """Row means of the time-averaged pressure against ρ₀ g (H − y), and their errors."""
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(9.0, 3.4))
    depth = col.depth - col.y
    ax.plot(col.exact / 1e3, depth, **EXACT_STYLE, label="ρ₀ g (H − y)")
    ax.plot(col.p / 1e3, depth, "o", ms=4, label="IISPH, row means")
    ax.invert_yaxis()
    ax.set(xlabel="pressure (kPa)", ylabel="depth H − y (m)", title="water column at rest")
    ax.legend(fontsize=8)
    err = 100 * (col.p / col.exact - 1)
    ax2.plot(depth[col.below_top], err[col.below_top], "o-", ms=4, label="below the top layer")
    ax2.plot(depth[~col.below_top], err[~col.below_top], "x", color="gray",
             label="top layer (the kernel reaches the surface row)")
    ax2.axhspan(-5, 5, color="C2", alpha=0.12, label="±5 %")
    ax2.set(xlabel="depth H − y (m)", ylabel="error (%)", ylim=(-60, 60),
            title="pressure / ρ₀gh − 1")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    return fig


def draw_front(runs: dict, delay: float, T_max: float = 3.5):
    """Left: Z against T of each run (``{label: DamRun}``; the first, the notebook's own,
    also delayed by ``delay``) with Martin & Moyce's points and Ritter's line. Right: each
    run's relative error at Martin & Moyce's times (the first also delayed, dashed), and
    the target band of ±10 %."""
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10.0, 4.0))
    T = np.linspace(0.0, T_max, 50)
    T_mm, Z_mm = MARTIN_MOYCE.T
    ax.plot(T, ritter_front(T), **EXACT_STYLE, label="Ritter (1892): Z = 1 + 2T")
    first_label, first = next(iter(runs.items()))
    for k, (label, run) in enumerate(runs.items()):
        color = FRONT_COLORS[k % len(FRONT_COLORS)]
        ax.plot(run.T, run.Z, lw=1.5 if k == 0 else 1.1, color=color, label=label)
        err = 100 * (np.interp(T_mm, run.T, run.Z) / Z_mm - 1)
        ax2.plot(T_mm, err, marker="o", ms=3, lw=1.5 if k == 0 else 1.0, color=color, label=label)
    ax.plot(first.T + delay, first.Z, color=FRONT_COLORS[0], ls=":", lw=2,
            label=f"{first_label}, delayed by ΔT = {delay}")
    err = 100 * (np.interp(T_mm - delay, first.T, first.Z) / Z_mm - 1)
    ax2.plot(T_mm, err, marker="s", ms=3, color=FRONT_COLORS[0], ls=":", lw=2,
             label=f"{first_label}, delayed by ΔT = {delay}")
    ax.plot(T_mm, Z_mm, "ks", ms=5, mfc="white", zorder=5, label="Martin & Moyce (1952), n² = 2")
    ax.set(xlabel="T = t √(2g/a)", ylabel="Z = z / a", xlim=(0, T_max), ylim=(0.9, 5.0),
           title="dam-break surge front")
    ax.legend(fontsize=7, loc="upper left", frameon=True, framealpha=0.95).set_zorder(10)
    ax2.axhspan(-10, 10, color="C2", alpha=0.12, label="±10 % (the target)")
    ax2.axhline(0.0, color="k", lw=0.6)
    ax2.legend(fontsize=7, loc="lower center", ncol=2)
    ax2.set(xlabel="T = t √(2g/a)", ylabel="Z / Z_MM − 1 (%)", title="front against Martin & Moyce",
            ylim=(-32, 22))
    fig.tight_layout()
    return fig


def dam_animation(frames, sim, fps: float = 15.0, size=(6.0, 3.0), tank: float = 6.0,
                  dpi: float | None = None, vmax: float | None = None):
    """A ``FuncAnimation`` of saved frames, particles coloured by speed (m/s) with a
    colour bar (up to ``vmax``, default the fastest particle rounded up), walls in grey;
    ``tank`` its length in column widths."""
    from matplotlib.animation import FuncAnimation

    fig, ax = plt.subplots(figsize=size, dpi=dpi)
    a = 2.0 * (np.max(frames.x[0][:, 1]) + 0.5 * sim.params.spacing) / 4.0   # column width
    # the colour bar reaches the fastest particle of the clip, so that no colour saturates
    vmax = float(np.ceil(np.max(frames.speed))) if vmax is None else vmax
    walls = ax.scatter(*sim.wall.x.T, color="0.6", lw=0)
    dots = ax.scatter(*frames.x[0].T, c=frames.speed[0], cmap="viridis", vmin=0.0, vmax=vmax,
                      lw=0)
    fig.colorbar(dots, ax=ax, label="speed (m/s)", fraction=0.04, pad=0.02)
    ax.set(xlim=(-0.1 * a, (tank + 0.1) * a), ylim=(-0.1 * a, 2.3 * a), aspect="equal",
           xlabel="x (m)", ylabel="y (m)")
    ax.grid(False)
    title = ax.set_title("", fontsize=9)
    fig.tight_layout()
    # one dot per particle, about a lattice cell wide: points per metre from the axes' size
    per_metre = ax.get_window_extent().width * 72 / fig.dpi / ((tank + 0.2) * a)
    dots.set_sizes([(1.1 * sim.params.spacing * per_metre) ** 2])
    walls.set_sizes([(0.5 * sim.params.spacing * per_metre) ** 2])

    def update(f):
        dots.set_offsets(frames.x[f])
        dots.set_array(frames.speed[f])
        title.set_text(f"dam break (IISPH, {sim.n} particles), t = {frames.t[f]:.2f} s")
        return dots, title

    update(0)
    # laid out once: without a layout engine, saving a frame draws the figure once, not twice
    fig.set_layout_engine(None)
    return FuncAnimation(fig, update, frames=len(frames.t), interval=1000.0 / fps)

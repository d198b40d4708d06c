"""Notebook 11 (cloth): the drawings and the kernel-free animation of the drape.

Holds the three spring families of a grid (:func:`draw_families`), cloth wireframes in an
oblique view (:func:`draw_cloth_frames`, :func:`animate_drape`), energy against time
(:func:`draw_energy`) and the work per frame of the two methods (:func:`draw_work`).
Imports matplotlib and the core; the core never imports this module.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection

from ..plotting import METHOD_COLORS

FAMILY_COLORS = {"struct": "C0", "shear": "C1", "bend": "C2"}
FAMILY_NAMES = {"struct": "structural (grid neighbours)", "shear": "shear (cell diagonals)",
                "bend": "bend (two apart)"}


def draw_families(x0: np.ndarray, network):
    """One panel per spring family of a small flat grid (x-y); bend springs are drawn as
    arcs so that they do not hide the structural springs they run along."""
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.8), constrained_layout=True)
    for ax, kind in zip(axes, ("struct", "shear", "bend"), strict=True):
        sub = network.select(kind)
        p, q = x0[sub.i, :2], x0[sub.j, :2]
        if kind == "bend":
            s = np.linspace(0.0, 1.0, 12)[None, :, None]
            mid = p[:, None] + s * (q - p)[:, None]
            normal = np.stack((-(q - p)[:, 1], (q - p)[:, 0]), axis=1)[:, None]
            segments = mid + 0.15 * np.sin(np.pi * s) * normal
        else:
            segments = np.stack((p, q), axis=1)
        ax.add_collection(LineCollection(segments, colors=FAMILY_COLORS[kind], lw=1.2))
        ax.plot(x0[:, 0], x0[:, 1], "o", color="0.2", ms=4)
        ax.set(title=f"{FAMILY_NAMES[kind]}: {sub.n_springs}", xlabel="x (m)", aspect="equal")
        ax.margins(0.08)
    axes[0].set_ylabel("y (m)")
    return fig


def project(x, elevation: float = 20.0, azimuth: float = 30.0) -> np.ndarray:
    """Oblique view of 3D points (y up): turn by ``azimuth`` about the vertical, tilt by
    ``elevation``; returns screen coordinates (m), shape ``(..., 2)``."""
    a, e = np.radians(azimuth), np.radians(elevation)
    across = x[..., 0] * np.cos(a) + x[..., 2] * np.sin(a)
    depth = -x[..., 0] * np.sin(a) + x[..., 2] * np.cos(a)
    return np.stack((across, x[..., 1] * np.cos(e) + depth * np.sin(e)), axis=-1)


def _mesh(x, shape):
    p = project(x).reshape(*shape, 2)
    return [p[r] for r in range(shape[0])] + [p[:, c] for c in range(shape[1])]


def _sphere_and_ground(ax, radius, extent):
    e = np.radians(20.0)
    ax.add_patch(plt.Circle((0.0, 0.0), radius, color="0.82", zorder=0))
    corners = np.array([[-extent, -radius, -extent], [extent, -radius, -extent],
                        [extent, -radius, extent], [-extent, -radius, extent]])
    ax.add_patch(plt.Polygon(project(corners), color="0.93", zorder=-1))
    return e


def draw_cloth_frames(runs: dict, shape, frames, *, sphere: float | None = None, pinned=(),
                      xlim=(-0.55, 0.55), ylim=(-0.75, 0.3)):
    """Wireframes of cloth runs at some frames: one row per run (``label -> ClothRun``),
    one column per frame (the same frames in every row, so the rows compare at a glance),
    in an oblique view (20° above, turned 30°); ``pinned`` particles are marked. Each row
    is labelled at its left, each column by its time at the top."""
    fig, axes = plt.subplots(len(runs), len(frames), figsize=(3.0 * len(frames), 3.1 * len(runs)),
                             squeeze=False, constrained_layout=True)
    for r, (row, (label, run)) in enumerate(zip(axes, runs.items(), strict=True)):
        for ax, f in zip(row, frames, strict=True):
            if sphere is not None:
                _sphere_and_ground(ax, sphere, 0.6)
            if np.all(np.isfinite(run.x[f])):
                ax.add_collection(LineCollection(_mesh(run.x[f], shape), colors="C0", lw=0.7))
                if len(pinned):
                    ax.plot(*project(run.x[f][list(pinned)]).T, "o", color="black", ms=5)
            else:
                ax.text(0.5, 0.5, "blown up", ha="center", transform=ax.transAxes, color="C3")
            ax.set(xlim=xlim, ylim=ylim, aspect="equal")
            if r == 0:
                ax.set_title(f"t = {run.t[f]:.2f} s", fontsize=12)
            ax.tick_params(labelsize=8)
        row[0].set_ylabel(f"{label}\nscreen height (m)", fontsize=11)
    for ax in axes[-1]:
        ax.set_xlabel("screen x (m)")
    return fig


def draw_energy(t, totals: dict, released: float):
    """Total energy minus its initial value, in units of the energy the cloth releases
    when it comes to rest (from the energy minimum, found apart from any run), against
    time; ``totals`` maps a label to ``(energy, colour)``."""
    fig, ax = plt.subplots(figsize=(7.5, 3.6))
    for label, (total, color) in totals.items():
        ax.plot(t, (total - total[0]) / released, color=color, label=label)
    ax.axhline(-1.0, color="0.5", ls=":", lw=1, label="at rest (the energy minimum)")
    ax.set(xlabel="t (s)", ylabel=r"$(E - E_0)\,/\,E_\mathrm{released}$",
           title="total energy of the undamped cloth")
    ax.legend(loc="center right", fontsize=8)
    return fig


def draw_large_steps(rows, fps: float = 30.0):
    """Peak structural strain per frame of both methods, one panel per stiffness (one legend
    for all, above them), and the work per frame (substeps against CG iterations)."""
    fig, axes = plt.subplots(1, len(rows) + 1, figsize=(3.4 * (len(rows) + 1), 3.8),
                             constrained_layout=True)
    for ax, r in zip(axes, rows, strict=False):
        t = np.arange(r["explicit_strain"].size) / fps
        ax.plot(t, 100 * r["explicit_strain"], color=METHOD_COLORS["symplectic_euler"],
                label="symplectic Euler, substeps at 90 % of its limit")
        ax.plot(t, 100 * r["implicit_strain"], color=METHOD_COLORS["backward_euler"],
                label="Baraff–Witkin, one step per frame")
        ax.set(xlabel="t (s)", ylim=(0, None))
        ax.set_title(f"k = {r['k']:.0f} N/m: {r['substeps']} substeps", fontsize=10)
    axes[0].set_ylabel("largest structural strain (%)")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside upper left", ncols=2, fontsize=9,
               frameon=False)
    ax = axes[-1]
    k = np.array([r["k"] for r in rows])
    ax.loglog(k, [r["substeps"] for r in rows], "o-", color=METHOD_COLORS["symplectic_euler"],
              label="substeps per frame")
    ax.loglog(k, [r["iterations"] for r in rows], "s-", color=METHOD_COLORS["backward_euler"],
              label="CG iterations per frame")
    ax.loglog(k, 0.5 * rows[0]["substeps"] * np.sqrt(k / k[0]), ":", color="0.4",
              label=r"guide $\propto\sqrt{k}$ (slope ½)")                 # below the substeps
    ax.set(xlabel="structural stiffness k (N/m)", ylabel="per frame (1/30 s)")
    ax.set_title("work per frame", fontsize=10)
    ax.set_yticks([30, 100, 300], labels=["30", "100", "300"])
    ax.yaxis.set_minor_formatter(plt.NullFormatter())
    ax.legend(fontsize=7)
    return fig


def animate_drape(run, shape, radius: float, fps: float = 30.0, frames: int | None = None):
    """A ``FuncAnimation`` of the drape (oblique view), one picture per animation frame
    (the first ``frames`` frames, default all)."""
    from matplotlib.animation import FuncAnimation

    fig, ax = plt.subplots(figsize=(4.0, 3.4))
    _sphere_and_ground(ax, radius, 0.6)
    lines = LineCollection(_mesh(run.x[0], shape), colors="C0", lw=0.6)
    ax.add_collection(lines)
    ax.set(xlim=(-0.65, 0.65), ylim=(-0.55, 0.5), aspect="equal", xlabel="screen x (m)",
           ylabel="screen height (m)")
    ax.grid(False)
    title = ax.set_title("cloth on a sphere, t = 0.00 s", fontsize=9)
    fig.tight_layout()

    def update(f):
        lines.set_segments(_mesh(run.x[f], shape))
        title.set_text(f"cloth on a sphere, t = {run.t[f]:.2f} s")
        return lines, title

    return FuncAnimation(fig, update, frames=len(run.t) if frames is None else frames,
                         interval=1000.0 / fps)

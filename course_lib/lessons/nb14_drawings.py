"""Notebook 14 (rigid bodies): drawings and kernel-free animations.

Boxes are drawn as shaded polygons in an orthographic view from above and to the side
(:func:`view`, :func:`draw_boxes`; only the faces turned to the viewer, the nearer bodies
last), magnets as balls with their north half red (:func:`draw_magnets`). Plots: the
invariants per integrator (:func:`draw_invariants`), the flip against the exact solution
(:func:`draw_flip`), period errors (:func:`draw_period_errors`), sliding into rolling
(:func:`draw_rolling`), a dropped box's energy (:func:`draw_drop`), two magnets' distance
and alignment (:func:`draw_magnet_pair`). Animations: :func:`animate_spin`,
:func:`animate_boxes`, :func:`animate_magnets`. Imports matplotlib and the core.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation
from matplotlib.patches import Circle, Polygon, Wedge

from ..plotting import EXACT_STYLE, METHOD_COLORS
from ..rigid import quaternion as quat
from ..rigid.contact import CORNERS

COLORS = {**METHOD_COLORS, "baraff_euler": "#ff7f0e", "implicit_midpoint": "#1f77b4",
          "splitting": "#8c564b"}
LABELS = {"forward_euler": "forward Euler", "baraff_euler": "Baraff's explicit Euler", "rk4": "RK4",
          "backward_euler": "backward Euler", "implicit_midpoint": "implicit midpoint",
          "splitting": "Lie–Poisson splitting"}
#: Corner indices of the six faces (outward order), and a colour per face pair (x, y, z).
FACES = np.array([[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]])
FACE_NORMALS = np.array([[-1, 0, 0], [1, 0, 0], [0, -1, 0], [0, 1, 0], [0, 0, -1], [0, 0, 1]], float)
FACE_COLORS = np.array([[0.85, 0.45, 0.25], [0.85, 0.45, 0.25], [0.3, 0.55, 0.8], [0.3, 0.55, 0.8],
                        [0.95, 0.8, 0.35], [0.95, 0.8, 0.35]])
LIGHT = np.array([0.4, 0.8, 0.45]) / np.linalg.norm([0.4, 0.8, 0.45])


def view(elevation: float = 20.0, azimuth: float = 30.0) -> np.ndarray:
    """Camera rows ``(right, up, toward the viewer)`` of an orthographic view, y up."""
    a, e = np.radians(azimuth), np.radians(elevation)
    toward = np.array([np.cos(e) * np.sin(a), np.sin(e), np.cos(e) * np.cos(a)])
    right = np.array([toward[2], 0.0, -toward[0]]) / np.hypot(toward[0], toward[2])
    return np.stack((right, np.cross(toward, right), toward))


def box_polygons(x, q, sides, cam) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """``(depth, screen polygon, RGB)`` of the faces of boxes ``x`` (N, 3), ``q`` (N, 4) and
    ``sides`` (N, 3) that face the camera, shaded by a fixed light."""
    out = []
    for xi, qi, si in zip(x, q, sides, strict=True):
        corners = xi + quat.rotate(qi, CORNERS * si)
        normals = quat.rotate(qi, FACE_NORMALS)
        for face, normal, color in zip(FACES, normals, FACE_COLORS, strict=True):
            if normal @ cam[2] <= 0:
                continue
            shade = 0.45 + 0.55 * max(0.0, float(normal @ LIGHT))
            pts = corners[face] @ cam.T
            out.append((float(pts[:, 2].mean()), pts[:, :2], np.clip(color * shade, 0, 1)))
    return sorted(out, key=lambda item: item[0])


def draw_boxes(ax, x, q, sides, cam, ground: float | None = None, extent: float = 1.0):
    """Draw boxes (and, with ``ground``, the plane ``y = ground`` as a grey square)."""
    artists = []
    if ground is not None:
        square = np.array([[-extent, ground, -extent], [extent, ground, -extent],
                           [extent, ground, extent], [-extent, ground, extent]])
        artists.append(ax.add_patch(Polygon(square @ cam[:2].T, color="0.9", zorder=0)))
    for _, pts, color in box_polygons(x, q, sides, cam):
        artists.append(ax.add_patch(Polygon(pts, facecolor=color, edgecolor="0.2", lw=0.6)))
    return artists


def draw_magnets(ax, x, m, radius, cam):
    """Balls of ``radius`` at ``x`` (N, 3), their north half red towards the dipoles ``m``."""
    artists = []
    screen, depth = x @ cam[:2].T, x @ cam[2]
    arrows = m @ cam[:2].T
    for k in np.argsort(depth):
        angle = np.degrees(np.arctan2(arrows[k, 1], arrows[k, 0]))
        artists.append(ax.add_patch(Circle(screen[k], radius, facecolor="0.55", edgecolor="0.2", lw=0.6)))
        artists.append(ax.add_patch(Wedge(screen[k], radius, angle - 90, angle + 90,
                                          facecolor="#d62728", edgecolor="0.2", lw=0.6)))
    return artists


def _replace(drawn: list, new: list) -> None:
    """Remove last frame's patches (``drawn``) and keep this frame's: cheaper than clearing
    the axes, whose limits, title and hidden frame stay as they were set once."""
    for artist in drawn:
        artist.remove()
    drawn[:] = new


def animate_spin(t, q, sides, frames: int = 60, fps: float = 15.0, title: str = "torque-free box"):
    """The box of a torque-free run turning in place (its centre fixed), ``frames`` frames
    spread over the run."""
    cam = view(20.0, 35.0)
    fig, ax = plt.subplots(figsize=(3.6, 3.6))
    picks = np.linspace(0, len(t) - 1, frames).round().astype(int)
    ax.set(xlim=(-0.14, 0.14), ylim=(-0.14, 0.14), aspect="equal")
    ax.set_axis_off()
    label = ax.set_title("", fontsize=9)
    drawn: list = []

    def update(f):
        k = picks[f]
        _replace(drawn, draw_boxes(ax, np.zeros((1, 3)), q[k][None], np.asarray(sides)[None], cam))
        label.set_text(f"{title}, t = {t[k]:.2f} s")
        return ()

    update(0)
    fig.tight_layout()
    fig.set_layout_engine(None)        # laid out once: each saved frame is drawn once
    return FuncAnimation(fig, update, frames=frames, interval=1000.0 / fps)


def animate_boxes(run, sides, frames: int | None = None, extent: float = 0.6, figsize=(4.8, 3.6),
                  title: str = "box dropped on the ground", xlim=(-0.5, 0.7), ylim=(-0.35, 0.6)):
    """A box run over a ground square (y = 0) in real time: ``frames`` recorded frames
    evenly spread over the run (default all)."""
    cam = view(18.0, 30.0)
    fig, ax = plt.subplots(figsize=figsize)
    sides = np.broadcast_to(np.asarray(sides, float), (*run.x.shape[1:2], 3))
    picks = _picks(len(run.t), frames)
    ax.set(xlim=xlim, ylim=ylim, aspect="equal")
    ax.set_axis_off()
    label = ax.set_title("", fontsize=9)
    drawn: list = []

    def update(f):
        k = picks[f]
        _replace(drawn, draw_boxes(ax, run.x[k], run.q[k], sides, cam, ground=0.0, extent=extent))
        label.set_text(f"{title}, t = {run.t[k]:.2f} s")
        return ()

    update(0)
    fig.tight_layout()
    fig.set_layout_engine(None)        # laid out once: each saved frame is drawn once
    return FuncAnimation(fig, update, frames=len(picks), interval=_interval(run.t, picks))


def _picks(n: int, frames: int | None) -> np.ndarray:
    return np.arange(n) if frames is None else np.linspace(0, n - 1, frames).round().astype(int)


def _interval(t, picks, slow: float = 1.0) -> float:
    """Milliseconds between frames to play ``t[picks]`` at ``1/slow`` of real speed."""
    return 1000.0 * slow * float(t[picks[-1]] - t[picks[0]]) / max(len(picks) - 1, 1)


def animate_magnets(run, radius, frames: int | None = None, fps: float = 30.0, figsize=(4.0, 3.2),
                    title: str = "magnets", half_width: float | None = None):
    """A magnet run viewed from above (the x-y plane), times in ms, ``frames`` recorded
    frames evenly spread over the run (default all), played at ``fps``."""
    cam = np.eye(3)
    fig, ax = plt.subplots(figsize=figsize)
    b = run.bodies
    centre = run.x[0].mean(axis=0)
    half = half_width or 1.15 * (np.abs(run.x[0] - centre).max() + 2 * radius)
    aspect = figsize[0] / figsize[1]
    picks = _picks(len(run.t), frames)
    ax.set(xlim=(-half * aspect, half * aspect), ylim=(-half, half), aspect="equal")
    ax.set_axis_off()
    label = ax.set_title("", fontsize=10)
    drawn: list = []

    def update(f):
        k = picks[f]
        _replace(drawn, draw_magnets(ax, run.x[k] - centre, quat.rotate(run.q[k], b.dipole), radius, cam))
        label.set_text(f"{title}, t = {run.t[k] * 1e3:.1f} ms")
        return ()

    update(0)
    fig.tight_layout()
    fig.set_layout_engine(None)        # laid out once: each saved frame is drawn once
    return FuncAnimation(fig, update, frames=len(picks), interval=1000.0 / fps)


def draw_invariants(rows: dict):
    """Size of the relative drift of ``|L|`` and of the kinetic energy against time, one
    line per method: solid where the quantity grew, dashed where it shrank."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.9), constrained_layout=True)
    for ax, key, name in zip(axes, ("dL", "dE"), ("|L|", "E"), strict=True):
        for method, row in rows.items():
            drift = row[key]
            size = np.maximum(np.abs(drift), 1e-17)
            style = "-" if drift[-1] >= 0 else "--"
            ax.semilogy(row["t"], size, style, color=COLORS[method], label=LABELS[method], lw=1.4)
        ax.set(xlabel="t (s)", ylabel=f"|{name} / {name}₀ − 1|", ylim=(1e-17, 10),
               title=f"drift of {name} (dashed: it shrinks)")
    axes[1].legend(fontsize=8, loc="center left", bbox_to_anchor=(1.0, 0.5))
    return fig


def draw_flip(t, omega, exact_omega, label: str):
    """The body angular velocity of a run against the exact solution (dashed)."""
    fig, ax = plt.subplots(figsize=(10, 3.8), constrained_layout=True)
    for k, color in enumerate(("C3", "C0", "C2")):
        ax.plot(t, omega[:, k], color=color, lw=1.5, label=f"Ω{'xyz'[k]} ({label})")
        ax.plot(t, exact_omega[:, k], **{**EXACT_STYLE, "linewidth": 1.0},
                label="exact (Jacobi elliptic functions)" if k == 0 else None)
    ax.set(xlabel="t (s)", ylabel="body angular velocity (rad/s)",
           title="spin about the intermediate axis: Ωy flips sign every half period")
    ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.0, 0.5))
    return fig


def draw_period_errors(study: dict):
    """|measured period / exact − 1| against steps per period, with 1/N² and 1/N⁴ guides."""
    fig, ax = plt.subplots(figsize=(6.5, 3.8), constrained_layout=True)
    n = study["steps"]
    for method in ("implicit_midpoint", "splitting", "rk4"):
        ax.loglog(n, np.abs(study[method]), "o-", color=COLORS[method],
                  label=f"{LABELS[method]} (slope {study[method + '_order']:.2f})")
    # guides a little below the last (asymptotic) point of a method of each order
    for order, method in ((2, "implicit_midpoint"), (4, "rk4")):
        guide = 0.3 * abs(study[method][-1]) * (n / n[-1]) ** -order
        ax.loglog(n, guide, "--", color="0.45", lw=1.0)
        ax.annotate(f"∝ 1/N{'²' if order == 2 else '⁴'}", (n[-1], guide[-1]), fontsize=9, color="0.3",
                    xytext=(6, -3), textcoords="offset points")
    ax.set_xticks(n, labels=[str(k) for k in n])
    ax.set_xlim(n[0] * 0.85, n[-1] * 1.35)
    ax.minorticks_off()
    ax.set(xlabel="steps per period N", ylabel="|T_measured / T_exact − 1|",
           title="flip period against the elliptic-integral value")
    ax.legend(fontsize=8)
    return fig


def draw_rolling(r: dict):
    """Speed and rim speed ``ωR`` of the sliding sphere, with the exact answer."""
    fig, ax = plt.subplots(figsize=(7.5, 3.8), constrained_layout=True)
    ax.plot(r["t"], r["v"], color="C0", lw=2, label="centre speed v (simulated)")
    ax.plot(r["t"], r["rim"], color="C1", lw=2, label="rim speed ωR (simulated)")
    g = 9.81
    t = r["t"]
    sliding = t < r["t_roll"]
    v_exact = np.where(sliding, r["v0"] - r["mu"] * g * t, r["v_roll"])
    rim_exact = np.where(sliding, 2.5 * r["mu"] * g * t, r["v_roll"])
    ax.plot(t, v_exact, **EXACT_STYLE, label="exact")
    ax.plot(t, rim_exact, **EXACT_STYLE)
    ax.axvline(r["t_roll"], color="0.5", lw=0.8, ls=":")
    ax.annotate("rolls from t = 2v₀/(7μg), at v = 5v₀/7", (r["t_roll"], r["v_roll"]),
                xytext=(10, 18), textcoords="offset points", fontsize=9)
    ax.set(xlabel="t (s)", ylabel="speed (m/s)", title="a sphere sliding into rolling (μ = 0.3)")
    ax.legend(fontsize=8, loc="lower right")
    return fig


def draw_drop(run, e: dict, rest_height: float, rest_energy: float):
    """Height of the dropped box's centre and its energies against time, with the height
    (m) and the energy (J) of the box at rest on its largest face (dashed)."""
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 3.6), constrained_layout=True)
    a1.plot(run.t, run.x[:, 0, 1], color="C0", label="simulated")
    a1.axhline(rest_height, **{**EXACT_STYLE, "linewidth": 1.0}, label="at rest on its largest face")
    a1.set(xlabel="t (s)", ylabel="height of the centre (m)", title="the box bounces and settles")
    a1.legend(fontsize=8)
    for key, color in (("kinetic", "C1"), ("potential", "C2"), ("total", "k")):
        a2.plot(run.t, e[key], color=color, label=key)
    a2.axhline(rest_energy, **{**EXACT_STYLE, "linewidth": 1.0}, label="m g × rest height")
    a2.set(xlabel="t (s)", ylabel="energy (J)", title="energy: lost at impacts, nearly kept in flight")
    a2.legend(fontsize=8)
    return fig


def draw_magnet_pair(run, align: dict):
    """Two magnets: centre distance (in contact distances) and dipole angles to the line."""
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 3.6), constrained_layout=True)
    ms = run.t * 1e3
    a1.plot(ms, align["distance"], color="C0")
    a1.axhline(1.0, **{**EXACT_STYLE, "linewidth": 1.0}, label="touching")
    a1.set(xlabel="t (ms)", ylabel="distance / (2 R)", title="the magnets snap together")
    a1.legend(fontsize=8)
    for k in range(2):
        a2.plot(ms, align["angles"][:, k], color=f"C{k + 1}", label=f"magnet {k + 1}")
    a2.set(xlabel="t (ms)", ylabel="angle to the line of centres (°)",
           title="and turn head to tail")
    a2.legend(fontsize=8)
    return fig

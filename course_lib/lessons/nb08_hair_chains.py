"""Notebook 08 (hair chains): the held strand, its widget, substep studies, animations.

Built on the strand model of :mod:`course_lib.hair` and the springs of
:mod:`course_lib.springs`; imports view helpers (:mod:`course_lib.plotting`,
:mod:`course_lib.widgets`). The core never imports this module.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..hair import FPS, MASS, STRAND, max_strain, simulate, static_shape, strand_system
from ..integrators import integrate
from ..springs import SpringNetwork, hair_chain, max_frequency
from ..systems import split_state, stack_state


def stiffest_edge(substeps: int, fps: float = FPS, mass=MASS, safety: float = 0.5) -> float:
    """Edge stiffness (N/m) a budget of ``substeps`` per frame affords: the step
    ``dt = 1/(fps substeps)`` must stay below about ``√(m/k)``, so ``k = safety · m / dt²``."""
    return float(safety * mass * (fps * substeps) ** 2)


def max_strain_vs_substeps(substeps, frames: int = 12, **strand) -> list[float]:
    """Inextensibility error against the substep budget: for each number of substeps per
    frame, the strand (released horizontally, root pinned) gets the stiffest edges that
    budget affords (:func:`stiffest_edge`); returns the max edge strain over ``frames``."""
    out = []
    for s in substeps:
        x0, net = hair_chain(**{**STRAND, **strand, "k_edge": stiffest_edge(s)})
        out.append(max_strain(simulate(x0, net, frames=frames, substeps=s), net))
    return out


def held_strand(k_bend: float = 0.0, zigzag: float = 0.0, **strand):
    """A strand laid out horizontally along +x with a clamped root (particles 0 and 1
    pinned): ``(x0, network)``."""
    return hair_chain(**{**STRAND, "k_bend": k_bend, "zigzag": zigzag, **strand})


@functools.lru_cache(maxsize=64)
def _held_equilibrium(k_bend: float, zigzag: float) -> np.ndarray:
    x0, net = held_strand(k_bend, zigzag)
    x = static_shape(x0, net)
    x.setflags(write=False)
    return x


def tip_sag(k_bend: float = 0.0, zigzag: float = 0.0) -> float:
    """How far (m) the tip of the held-out :data:`STRAND` drops at equilibrium under
    gravity (root clamped: particles 0 and 1 pinned)."""
    x0, _ = held_strand(k_bend, zigzag)
    return float(x0[-1, 1] - _held_equilibrium(float(k_bend), float(zigzag))[-1, 1])


# --- the notebook 08 widget ---------------------------------------------------------------


@dataclass
class HeldStrandRun:
    """Result of :func:`run_held_strand`."""

    t: np.ndarray
    frames: np.ndarray
    tip_y: np.ndarray
    equilibrium: np.ndarray
    stable: bool
    message: str
    dt_limit: float
    params: dict


def run_held_strand(k_bend: float = 2000.0, damping: float = 2e-3, dt: float = 1e-4,
                    zigzag: float = 0.3, t_end: float = 0.5, n_frames: int = 6) -> HeldStrandRun:
    """Release a held-out strand (clamped root) under gravity with symplectic Euler.

    Returns the strand at ``n_frames`` times, the tip height at every step, the static
    equilibrium it should settle to, the verdict, and the step limit ``2 / ω_max``.
    """
    x0, net = held_strand(k_bend, zigzag)
    equilibrium = _held_equilibrium(float(k_bend), float(zigzag))
    system = strand_system(net, MASS, (0, 1), damping)
    traj = integrate(system, stack_state(x0, np.zeros_like(x0)), (0.0, t_end), dt,
                     method="symplectic_euler", blowup_bound=100.0)
    x, _ = split_state(traj.y)
    pick = np.linspace(0, len(traj.t) - 1, n_frames).round().astype(int)
    return HeldStrandRun(traj.t[pick], x[pick], x[:, -1, 1], equilibrium,
                         traj.stable, traj.message, 2.0 / max_frequency(net, x0, MASS, (0, 1)),
                         {"k_bend": k_bend, "damping": damping, "dt": dt, "t": traj.t,
                          "t_end": t_end})


def draw_held_strand(run: HeldStrandRun):
    """Strand snapshots (side view) and tip height against time, with the equilibrium."""
    import matplotlib.pyplot as plt

    from ..plotting import EXACT_STYLE

    p = run.params
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.4))
    colors = plt.cm.viridis(np.linspace(0.0, 0.9, len(run.t)))
    for tk, xk, col in zip(run.t, run.frames, colors, strict=True):
        ax1.plot(xk[:, 0], xk[:, 1], "o-", ms=2, color=col, label=f"t = {tk:.2f} s")
    ax1.plot(run.equilibrium[:, 0], run.equilibrium[:, 1], **EXACT_STYLE, label="equilibrium")
    ax1.set(xlim=(-0.05, 0.35), ylim=(-0.33, 0.07), xlabel="x (m)", ylabel="y (m)",
            aspect="equal")
    ax1.legend(fontsize=7, loc="lower left")
    ax2.plot(p["t"], run.tip_y, color="C0", label="tip, symplectic Euler")
    ax2.axhline(run.equilibrium[-1, 1], **EXACT_STYLE, label="equilibrium")
    ax2.set(xlim=(0.0, p["t_end"]), ylim=(-0.33, 0.07), xlabel="t (s)", ylabel="tip height y (m)")
    ax2.legend(fontsize=8, loc="upper right")
    verdict = "stable" if run.stable else "BLOWN UP: " + run.message
    fig.suptitle(f"k_bend = {p['k_bend']:.3g} N/m, damping = {p['damping']:.3g} kg/s, "
                 f"dt = {p['dt']:.3g} s (limit {run.dt_limit:.3g} s): {verdict}", fontsize=10)
    fig.tight_layout()
    return fig


def held_strand_explorer(k_bend: float = 2000.0, damping: float = 2e-3, dt: float = 1e-4):
    """An :class:`~course_lib.widgets.ExplorerView` over :func:`run_held_strand`."""
    import ipywidgets as w

    from ..widgets import ExplorerView, log_slider

    controls = {
        "k_bend": log_slider("k_bend (N/m)", k_bend, 1.0, 1e4),
        "damping": w.FloatSlider(value=damping, min=0.0, max=1e-2, step=5e-4,
                                 description="damping (kg/s)", readout_format=".1e",
                                 continuous_update=False, style={"description_width": "initial"}),
        "dt": log_slider("dt (s)", dt, 2e-5, 1e-3),
    }
    return ExplorerView(run_held_strand, draw_held_strand, controls)


def animate(frames, network: SpringNetwork, *, head=None, size: float = 4.0,
            xlim=(-0.35, 0.35), ylim=(-0.45, 0.42), fps: float = FPS, title: str = ""):
    """A ``FuncAnimation`` of strands seen from the front (x-y), one line per strand
    (springs of kind ``"edge"``), with an optional head ``(center, radius)``."""
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation

    edges = network.select("edge")
    fig, ax = plt.subplots(figsize=(size, size))
    if head is not None:
        ax.add_patch(plt.Circle(head[0][:2], head[1], color="0.85", zorder=0))
    # NaN between consecutive edges of different strands breaks the line per strand.
    seg = np.stack((edges.i, edges.j), axis=1)

    def coords(x):
        pts = np.concatenate((x[seg], np.full((seg.shape[0], 1, 3), np.nan)), axis=1)
        return pts.reshape(-1, 3)

    p0 = coords(frames[0])
    (line,) = ax.plot(p0[:, 0], p0[:, 1], "-", color="saddlebrown", lw=1.5)
    stamp = ax.text(0.97, 0.03, "", transform=ax.transAxes, fontsize=9, ha="right")
    ax.set(xlim=xlim, ylim=ylim, aspect="equal", xlabel="x (m)", ylabel="y (m)", title=title)
    fig.tight_layout()

    def update(k):
        p = coords(frames[k])
        line.set_data(p[:, 0], p[:, 1])
        stamp.set_text(f"t = {k / fps:.2f} s")
        return line, stamp

    return FuncAnimation(fig, update, frames=len(frames), interval=1000.0 / fps, blit=True)

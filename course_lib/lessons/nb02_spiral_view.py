"""Notebook 02 (forward Euler): the spiral explorer, dt against the spiral and the errors.

- :class:`SpiralPlot` draws a :class:`~course_lib.lessons.nb02_forward_euler.SpiralResult`
  in two panels: one revolution of forward Euler beside the exact circle, and the global
  (slope 1) and local (slope 2) error curves against dt with the chosen step marked. Its
  axes never change, so with ``blit=True`` everything but the run is drawn once.
- :func:`spiral_explorer` is the live widget (a logarithmic dt slider), :func:`spiral_player`
  its kernel-free player for readers without a kernel.

Imports the lesson's computation, the view helpers and matplotlib.
"""

from __future__ import annotations

import numpy as np

from ..fields import grid, sample, vortex
from ..players import Player, parameter_player
from ..plotting import EXACT_STYLE, METHOD_COLORS, detached_figure
from ..widgets import BlitPlot, PictureView, log_slider
from .nb02_forward_euler import SPIRAL_DT_RANGE, SpiralResult, convergence_curves, spiral_experiment

#: Size of the explorer's figure (in).
FIGSIZE = (10.5, 4.3)
#: Half-width of the spiral panel (m): a run whose radius passes it leaves the picture.
SPIRAL_VIEW = 4.5
#: Time steps (s) of the kernel-free player.
SPIRAL_DTS = (0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0)


class SpiralPlot(BlitPlot):
    """The spiral explorer's figure, updated in place: call it with a
    :class:`~course_lib.lessons.nb02_forward_euler.SpiralResult`."""

    def __init__(self, fig=None, *, blit: bool = False):
        fig = detached_figure(FIGSIZE) if fig is None else fig
        super().__init__(fig, blit)
        ax_s, ax_e = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.0, 1.25]})
        self.ax_s, self.ax_e = ax_s, ax_e
        color = METHOD_COLORS["forward_euler"]
        Xg, Yg = grid(extent=SPIRAL_VIEW, n=13)
        U, W = sample(vortex, Xg, Yg)
        ax_s.quiver(Xg, Yg, U, W, color="0.85", angles="xy", width=0.004)
        theta = np.linspace(0.0, 2 * np.pi, 200)
        ax_s.plot(np.cos(theta), np.sin(theta), **EXACT_STYLE, label="exact: the unit circle")
        (self.path,) = ax_s.plot([], [], "-", color=color, lw=1.6, ms=3,
                                 label="forward Euler, one revolution")
        (self.end,) = ax_s.plot([], [], "o", color=color, ms=7, mec="black")
        ax_s.plot([1.0], [0.0], "ks", ms=5)
        ax_s.set(xlim=(-SPIRAL_VIEW, SPIRAL_VIEW), ylim=(-SPIRAL_VIEW, SPIRAL_VIEW),
                 aspect="equal", xlabel="x (m)", ylabel="y (m)")
        ax_s.legend(loc="lower left", fontsize=8)
        self.title_s = ax_s.set_title("", fontsize=10, y=1.01)
        dt, error, local = convergence_curves()
        ax_e.loglog(dt, error, color=color, lw=1.5, label="global error at T = π (slope 1)")
        ax_e.loglog(dt, local, color=color, lw=1.5, ls="--",
                    label="local error of one step (slope 2)")
        shown = np.pi / 2.0 ** np.arange(4, 12)            # Section 4's 16 ... 2048 steps
        ax_e.loglog(shown, np.interp(shown, dt[::-1], error[::-1]), "o", color=color, ms=4,
                    mfc="white", label="Section 4's runs")
        ax_e.set(xlim=(0.008, 1.3), ylim=(3e-6, 20), xlabel="time step dt (s)",
                 ylabel="error (m)")
        (self.mark_g,) = ax_e.plot([], [], "o", color="black", ms=8)
        (self.mark_l,) = ax_e.plot([], [], "s", color="black", ms=7)
        self.vline = ax_e.axvline(0.1, color="0.3", lw=1.0, ls=":")
        ax_e.legend(loc="lower right", fontsize=8)
        self.title_e = ax_e.set_title("", fontsize=10, y=1.01)
        fig.subplots_adjust(left=0.06, right=0.98, top=0.88, bottom=0.13, wspace=0.22)
        self.dynamic = [self.path, self.end, self.title_s, self.mark_g, self.mark_l,
                        self.vline, self.title_e]

    def __call__(self, result: SpiralResult):
        r = result
        self.path.set_data(r.X[:, 0], r.X[:, 1])
        self.path.set_marker("o" if len(r.t) <= 80 else "")
        self.end.set_data([r.X[-1, 0]], [r.X[-1, 1]])
        out = " (leaves the picture)" if r.growth > SPIRAL_VIEW else ""
        self.title_s.set_text(f"dt = {r.dt:.3g} s, {len(r.t) - 1} steps: radius 1 → "
                              f"{r.growth:.3f} m{out}\n(theory Π √(1 + dt²) = "
                              f"{r.growth_theory:.3f})")
        self.mark_g.set_data([r.dt], [r.error])
        self.mark_l.set_data([r.dt], [r.local])
        self.vline.set_xdata([r.dt, r.dt])
        self.title_e.set_text(f"errors against the step: at dt = {r.dt:.3g} s\n"
                              f"global {r.error:.2g} m (●), one step {r.local:.2g} m (■)")
        return self.fig


def spiral_explorer(dt: float = 0.25) -> PictureView:
    """The live explorer: a logarithmic ``dt`` slider over :func:`spiral_experiment`."""
    controls = {"dt": log_slider("dt (s)", dt, *SPIRAL_DT_RANGE)}
    return PictureView(spiral_experiment, SpiralPlot(blit=True), controls,
                       name="Spiral explorer")


def spiral_player(dts=SPIRAL_DTS) -> Player:
    """The explorer's ``dt`` slider, precomputed: plays without a kernel."""
    return parameter_player(
        spiral_experiment, SpiralPlot(), "dt", dts, unit="s", colors=32,
        title="Without a kernel: forward Euler on the vortex; slide the time step dt",
        caption=lambda r: r.verdict)

"""Notebook 10 (flocking): the drawings.

Holds a flock and its order parameters (:func:`draw_flock`, also the widget's drawing),
the key states of the widget and the alignment relaxation against its exact decay; the
drawings of the studies over many seeds are in :mod:`course_lib.lessons.nb10_figures`.
Imports matplotlib and the core; the core never imports this module.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ..plotting import EXACT_STYLE
from ..widgets import BlitPlot

#: Arrows show headings (unit length, ``ARROW`` m long on the plot) coloured by direction.
ARROW = 0.7


def _unit(v):
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _boids(ax, x, v, box, title):
    u = _unit(v)
    ax.quiver(x[:, 0], x[:, 1], u[:, 0], u[:, 1], np.arctan2(u[:, 1], u[:, 0]), cmap="hsv",
              clim=(-np.pi, np.pi), angles="xy", scale_units="xy", scale=1 / ARROW,
              width=0.007, headwidth=3.5)
    ax.set(xlim=(0, box), ylim=(0, box), aspect="equal", title=title)
    ax.set_xlabel("x (m)", labelpad=1)


class FlockPlot(BlitPlot):
    """The widget's figure: the final flock (arrows: velocity, colour: heading) beside its
    polarization and nearest-neighbour distance over time. Calling it with a
    :class:`~course_lib.lessons.nb10_flocking.FlockRun` updates the same artists in
    place, which keeps a widget update fast; it returns the figure. With ``freeze`` (for
    a figure redrawn many times) the ticks and axis-label places are fixed once. With
    ``blit`` (the widget) :meth:`png` redraws only the arrows, the curves and their
    references over a kept picture of the rest: the limits never change, so that picture
    is drawn once; its title names no weight (the sliders show them), a picture drawn
    without ``blit`` names all three."""

    def __init__(self, n: int, box: float, t_end: float, freeze: bool = True,
                 blit: bool = True):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.ticker import MaxNLocator

        fig = plt.figure(figsize=(9.5, 4.0))
        plt.close(fig)                        # the widget shows it; pyplot must not
        FigureCanvasAgg(fig)
        grid = fig.add_gridspec(2, 2, width_ratios=(1.0, 1.2), hspace=0.15, wspace=0.25,
                                left=0.07, right=0.98, top=0.88, bottom=0.12)
        ax = fig.add_subplot(grid[:, 0])
        zeros = np.zeros(n)
        self.arrows = ax.quiver(zeros, zeros, zeros, zeros, zeros, cmap="hsv",
                                clim=(-np.pi, np.pi), angles="xy", scale_units="xy",
                                scale=1 / ARROW, width=0.007, headwidth=3.5)
        ax.set(xlim=(0, box), ylim=(0, box), aspect="equal", xlabel="x (m)", ylabel="y (m)")
        ax1 = fig.add_subplot(grid[0, 1])
        (self.pol,) = ax1.plot([], [], color="C0")
        self.pol_ref = ax1.axhline(0.0, **EXACT_STYLE)
        ax1.text(0.01, 0.9, "dashed: random headings", transform=ax1.transAxes, fontsize=8)
        ax1.set(ylabel="polarization", ylim=(0, 1.02), xlim=(0, t_end))
        ax1.tick_params(labelbottom=False)
        ax2 = fig.add_subplot(grid[1, 1])          # not shared: sharing costs a layout pass
        (self.nn,) = ax2.plot([], [], color="C2")
        self.nn_ref = ax2.axhline(0.0, **EXACT_STYLE)
        ax2.text(0.01, 0.08, "dashed: random positions", transform=ax2.transAxes, fontsize=8)
        ax2.set(xlabel="t (s)", ylabel="nearest neighbour (m)", ylim=(0, 1.5), xlim=(0, t_end))
        ax.set_xticks([0, box / 2, box])
        ax.set_yticks([0, box / 2, box])
        for a in (ax1, ax2):                      # few tick labels: text is most of a redraw
            a.xaxis.set_major_locator(MaxNLocator(3))
            a.yaxis.set_major_locator(MaxNLocator(3))
        # The widget's title is still (text is the slowest thing to draw: 10 of an update's
        # 22 ms were the weights in the title), the sliders above it show the weights.
        self.title = fig.suptitle(f"{n} boids after {t_end:.0f} s, with the weights set above"
                                  if blit else "", fontsize=10)
        super().__init__(fig, blit)
        self.dynamic = [self.arrows, self.pol, self.pol_ref, self.nn, self.nn_ref]
        if freeze:
            self._freeze_layout()

    def _freeze_layout(self):
        """Fix what no update changes (the limits are fixed, so the ticks and the places
        of the axis labels are too): left automatic, every redraw would format the tick
        labels again and measure their boxes to place the axis labels."""
        self.fig.draw_without_rendering()
        for ax in self.fig.axes:
            to_axes = ax.transAxes.inverted()
            for axis in (ax.xaxis, ax.yaxis):
                lo, hi = axis.get_view_interval()
                axis.set_ticks(axis.get_majorticklocs())    # (this widens the limits
                axis.set_view_interval(lo, hi, ignore=True)  # to every tick: undone)
                label = axis.label
                axis.set_label_coords(*to_axes.transform(
                    label.get_transform().transform(label.get_position())))

    def __call__(self, run):
        r = run.rules
        u = _unit(run.v)
        self.arrows.set_offsets(run.x)
        self.arrows.set_UVC(u[:, 0], u[:, 1], np.arctan2(u[:, 1], u[:, 0]))
        self.pol.set_data(run.t, run.polarization)
        self.pol_ref.set_ydata([run.random_polarization] * 2)
        self.nn.set_data(run.t_nn, run.nn)
        self.nn_ref.set_ydata([run.random_nn] * 2)
        if not self.blit:
            self.title.set_text(f"{len(run.x)} boids after {run.t[-1]:.0f} s: separation "
                                f"{r.separation:.2g} m²/s², alignment {r.alignment:.2g} 1/s, "
                                f"cohesion {r.cohesion:.2g} 1/s²")
        return self.fig


def draw_flock(run):
    """A new figure of ``run`` (see :class:`FlockPlot`)."""
    return FlockPlot(len(run.x), run.rules.box, float(run.t[-1]), freeze=False,
                     blit=False)(run)


def draw_key_states(runs: dict):
    """One panel per labelled run: the flock at the end, with its order parameters."""
    fig, axes = plt.subplots(1, len(runs), figsize=(3 * len(runs), 3.5), squeeze=False,
                             constrained_layout=True)
    axes = axes[0]
    for ax, (label, run) in zip(axes, runs.items(), strict=True):
        _boids(ax, run.x, run.v, run.rules.box,
               f"{label}\npolarization {run.polarization[-1]:.2f}, spacing {run.nn[-1]:.2f} m")
        ax.title.set_fontsize(9)
    axes[0].set_ylabel("y (m)")
    return fig


def draw_relaxation(results: dict, dt: float, n: int):
    """RMS deviation from the mean velocity against step, measured and exact, per weight."""
    fig, ax = plt.subplots(figsize=(7.5, 3.6))
    for k, (w, (rms, exact)) in enumerate(results.items()):
        factor = 1 - w * dt * n / (n - 1)
        ax.semilogy(rms, "o", ms=4, color=f"C{k}",
                    label=f"w = {w:g} 1/s: factor 1 − w dt n/(n−1) = {factor:+.3f}")
        ax.semilogy(exact, **{**EXACT_STYLE, "linewidth": 1.0})
    ax.plot([], [], **EXACT_STYLE, label="exact |factor|$^k$")
    ax.set(xlabel="step k", ylabel="RMS deviation from the mean velocity (m/s)",
           title=f"alignment alone, {n} boids all in view, dt = {dt} s")
    ax.legend(fontsize=8, loc="lower left")
    return fig

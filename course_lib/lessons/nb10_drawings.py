"""Notebook 10 (flocking): the drawings.

Holds one function per picture: a flock and its order parameters (:func:`draw_flock`, also
the widget's drawing), the key states of the widget, the alignment relaxation against its
exact decay, the cost of the two neighbour searches, and the predator chase. Imports
matplotlib and the core; the core never imports this module.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ..plotting import EXACT_STYLE

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


class FlockPlot:
    """The widget's figure: the final flock (arrows: velocity, colour: heading) beside its
    polarization and nearest-neighbour distance over time. Calling it with a
    :class:`~course_lib.lessons.nb10_flocking.FlockRun` updates the same artists in
    place, which keeps a widget update fast; it returns the figure. With ``freeze`` (for
    a figure redrawn many times) the ticks and axis-label places are fixed once."""

    def __init__(self, n: int, box: float, t_end: float, freeze: bool = True):
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
        self.title = fig.suptitle("", fontsize=10)
        self.fig = fig
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
        self.title.set_text(f"{len(run.x)} boids after {run.t[-1]:.0f} s: separation "
                            f"{r.separation:.2g} m²/s², alignment {r.alignment:.2g} 1/s, "
                            f"cohesion {r.cohesion:.2g} 1/s²")
        return self.fig


def draw_flock(run):
    """A new figure of ``run`` (see :class:`FlockPlot`)."""
    return FlockPlot(len(run.x), run.rules.box, float(run.t[-1]), freeze=False)(run)


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


def draw_crossover(sizes, timings: dict):
    """Cost of one step against the number of boids, both neighbour searches."""
    fig, ax = plt.subplots(figsize=(7, 4))
    sizes = np.asarray(sizes, dtype=float)
    labels = {"all_pairs": "all pairs (N × N arrays)", "tree": "k-d tree (cKDTree)"}
    for key, color in (("all_pairs", "C3"), ("tree", "C0")):
        ax.loglog(sizes, 1e3 * timings[key], "o-", color=color, label=labels[key])
    a, t = timings["all_pairs"], timings["tree"]
    ok = np.isfinite(a)
    ax.loglog(sizes[ok], 1e3 * a[ok][-1] * (sizes[ok] / sizes[ok][-1]) ** 2, ":", color="C3",
              lw=1, label="∝ N²")
    ax.loglog(sizes, 1e3 * t[-1] * sizes / sizes[-1], ":", color="C0", lw=1, label="∝ N")
    faster = np.nonzero(ok & (t < a))[0]
    if faster.size:
        ax.axvline(sizes[faster[0]], color="0.5", lw=1)
        ax.text(sizes[faster[0]] * 1.05, 1e3 * np.nanmin(t) * 0.8,
                f"tree faster from N = {sizes[faster[0]]:.0f}", fontsize=9, color="0.3")
    ax.axhline(20.0, color="0.6", ls="--", lw=1)
    ax.text(sizes[0], 23.0, "20 ms", fontsize=8, color="0.4")
    ax.set(xlabel="number of boids N", ylabel="one step (ms)",
           title="neighbour search: all pairs against a k-d tree")
    ax.legend(fontsize=8, loc="upper left")
    return fig


def draw_order(run):
    """The flock at the end, and its polarization and mean nearest-neighbour distance over
    time beside their values for random placement."""
    fig, (ax0, ax1, ax2) = plt.subplots(1, 3, figsize=(12, 3.6), constrained_layout=True,
                                        width_ratios=(0.9, 1, 1))
    _boids(ax0, run.x, run.v, run.rules.box, f"{len(run.x)} boids after {run.t[-1]:.0f} s")
    ax0.set_ylabel("y (m)")
    ax1.plot(run.t, run.polarization, color="C0", label="flock")
    ax1.axhline(run.random_polarization, **EXACT_STYLE, label=r"random: $\sqrt{\pi}/(2\sqrt{N})$")
    ax1.set(xlabel="t (s)", ylabel="polarization", ylim=(0, 1.02), title="common heading")
    ax1.legend(loc="center right")
    ax2.plot(run.t_nn, run.nn, color="C2", label="flock")
    ax2.axhline(run.random_nn, **EXACT_STYLE, label="random positions (exact)")
    ax2.set(xlabel="t (s)", ylabel="mean distance (m)", ylim=(0, 1.3),
            title="distance to the nearest neighbour")
    ax2.legend(loc="lower right")
    return fig


def draw_chase(runs: dict, box: float):
    """Distance from the predator to its nearest boid, and the flock at the end."""
    fig, axes = plt.subplots(1, 1 + len(runs), figsize=(12, 3.8), constrained_layout=True,
                             width_ratios=(1.4,) + (1.0,) * len(runs))
    for k, (label, run) in enumerate(runs.items()):
        axes[0].plot(run.t, run.closest, color=f"C{k}", label=label)
        ax = axes[k + 1]
        _boids(ax, run.x, run.v, box, label)
        ax.plot(run.path[:, 0], run.path[:, 1], ".", color="0.3", ms=2)
        ax.plot(*run.predator, "X", color="black", ms=10, label="predator")
    axes[0].set(xlabel="t (s) since the predator entered", ylabel="to the nearest boid (m)",
                title="how close the predator gets")
    axes[0].legend()
    axes[1].set_ylabel("y (m)")
    return fig

"""Notebook 08 (hair chains): drawings, the hair widget, and the animations.

- :class:`HeldStrandPlot` draws a :class:`~course_lib.lessons.nb08_hair_runs.HeldStrandRun`
  (snapshots beside the equilibrium; the tip height against time) and redraws in place;
  a blown-up run shows its last finite state and its growth on a log scale. In the widget
  (``blit=True``) it keeps a picture of its axes, ticks and legends
  (:class:`~course_lib.widgets.BlitPlot`) and redraws only the curves and titles.
- :func:`held_strand_explorer`: the widget (bending stiffness, damping, step), which says
  when it is working and caps a run at :data:`MAX_STEPS` steps (said in the title).
- :func:`animate` and :func:`draw_hairstyle`: strands seen from the front and from the
  side, strands behind the head drawn behind it.

Lesson layer: imports the compute module (:mod:`~course_lib.lessons.nb08_hair_runs`), the
plotting style and the widget views; nothing imports it back but the notebook's facade
(:mod:`~course_lib.lessons.nb08_hair_chains`) and the kernel-free players.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.ticker import MaxNLocator

from ..hair import FPS
from ..plotting import EXACT_STYLE, detached_figure
from ..springs import SpringNetwork
from ..widgets import BlitPlot
from .nb08_hair_runs import HeldStrandRun, SaddleEscape, run_held_strand

#: The widget's time span (s) and cap on the steps of one run (and so on its update time).
T_END, MAX_STEPS = 0.3, 3000
FIGSIZE = (10.0, 3.6)
N_SNAPSHOTS = 6


class HeldStrandPlot(BlitPlot):
    """The hair widget's figure; call it with a :class:`HeldStrandRun` to (re)draw. With
    ``blit=True`` :meth:`png` redraws only the curves and titles over a kept background
    and the time axis ends at a round value."""

    def __init__(self, fig=None, *, blit: bool = False):
        if fig is None:
            fig = detached_figure(FIGSIZE)
        super().__init__(fig, blit)
        self.ax_s, self.ax_t = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.0, 1.25]})
        fig.subplots_adjust(left=0.07, right=0.98, top=0.80, bottom=0.15, wspace=0.22)
        colors = plt.cm.viridis(np.linspace(0.0, 0.9, N_SNAPSHOTS))
        self.snaps = [self.ax_s.plot([], [], "o-", ms=2, color=c)[0] for c in colors]
        self.eq_s, = self.ax_s.plot([], [], **EXACT_STYLE, label="equilibrium")
        self.last_s, = self.ax_s.plot([], [], "x-", color="#d62728", ms=4, lw=1,
                                      label="last finite state")
        self.ax_s.set(xlim=(-0.05, 0.35), ylim=(-0.33, 0.07), xlabel="x (m)", ylabel="y (m)",
                      aspect="equal")
        self.tip, = self.ax_t.plot([], [], color="C0", lw=1.2, label="tip, symplectic Euler")
        self.speed, = self.ax_t.plot([], [], color="C3", lw=1.2,
                                     label="largest speed of any particle (m/s)")
        self.eq_t = self.ax_t.axhline(0.0, **EXACT_STYLE, label="equilibrium")
        self.ax_t.set(xlabel="t (s)", ylabel="tip height y (m)")
        for ax in (self.ax_s, self.ax_t):     # few ticks: drawing text dominates a redraw
            ax.xaxis.set_major_locator(MaxNLocator(4))
            ax.yaxis.set_major_locator(MaxNLocator(4))
        self.title = fig.text(0.5, 0.975, "", ha="center", va="top", fontsize=10.5)
        self.subtitle = fig.text(0.5, 0.905, "", ha="center", va="top", fontsize=9.5)
        self.dynamic = [*self.snaps, self.eq_s, self.last_s, self.tip, self.speed, self.eq_t,
                        self.title, self.subtitle]
        self._legends: dict = {}
        if blit:    # unhinted text renders faster (the titles change with every update)
            self.rc = {"text.hinting": "none"}

    def _legend(self, ax, handles, **kw) -> None:
        """(Re)build ``ax``'s legend when its entries change (its labels and place)."""
        key = (tuple(h.get_label() for h in handles), tuple(sorted(kw.items())))
        if self._legends.get(ax) != key:
            ax.legend(handles=handles, **kw)
            self._legends[ax] = key

    def __call__(self, run: HeldStrandRun):
        p = run.params
        shown = []
        for line, tk, xk in zip(self.snaps, run.t, run.frames, strict=False):
            line.set_data(xk[:, 0], xk[:, 1])
            line.set_label("_")
            if np.all(np.isfinite(xk)):
                shown.append((line, tk))
        shown[0][0].set_label(f"t = {shown[0][1]:.2f} s")
        if len(shown) > 1:
            shown[-1][0].set_label(f"t = {shown[-1][1]:.2f} s")
        self.eq_s.set_data(run.equilibrium[:, 0], run.equilibrium[:, 1])
        handles = [shown[0][0]] + ([shown[-1][0]] if len(shown) > 1 else []) + [self.eq_s]
        if run.stable:
            self.last_s.set_data([], [])
        else:
            self.last_s.set_data(run.last_finite[:, 0], run.last_finite[:, 1])
            self.last_s.set_label(f"last finite state (step {run.last_step})")
            handles.append(self.last_s)
        self._legend(self.ax_s, handles, fontsize=8, loc="lower right")

        t = p["t"]
        last = run.last_step
        stride = max(1, last // 1500)
        idx = np.r_[np.arange(0, last + 1, stride), last]
        if run.stable:
            self.tip.set_data(t[idx], run.tip_y[idx])
            self.tip.set_label("tip, symplectic Euler")
            eq_y = float(run.equilibrium[-1, 1])
            self.eq_t.set_ydata([eq_y, eq_y])
            self.eq_t.set_visible(True)
            if self.ax_t.get_yscale() != "linear":
                self.ax_t.set_yscale("linear")
                self.ax_t.yaxis.set_major_locator(MaxNLocator(4))
            self.ax_t.set_ylim(-0.33, 0.07)
            self.ax_t.set_ylabel("tip height y (m)")
            shown = p["t_shown"]
            if self.round_limits and shown >= p["t_end"] - 0.5 * p["dt"]:   # not capped:
                shown = p["t_end"] + 0.5 * p["dt"]      # round(t_end/dt) steps end before
            self.limits(self.ax_t, "x", 0.0, shown, nbins=40)
            self.speed.set_data([], [])
            legend = [self.tip, self.eq_t]
        else:      # blown up: the growth, on a log scale, up to the last finite step
            self.tip.set_data(t[idx], np.maximum(run.growth[idx], 1e-16))
            self.tip.set_label("largest |x - x0| of any particle (m)")
            self.speed.set_data(t[1: last + 1], np.maximum(run.speed, 1e-16))
            self.eq_t.set_ydata([1.0, 1.0])        # hidden; positive, for the log scale
            self.eq_t.set_visible(False)
            if self.ax_t.get_yscale() != "log":
                self.ax_t.relim(visible_only=True)     # forget y = 0 before a log scale
                self.ax_t.set_yscale("log")
            self.ax_t.set_ylim(1e-8, 1e3)
            self.ax_t.set_ylabel("displacement, speed (log scale)")
            self.limits(self.ax_t, "x", 0.0, 1.05 * t[last], nbins=40)
            legend = [self.tip, self.speed]
        self._legend(self.ax_t, legend, fontsize=8,
                     loc="upper right" if run.stable else "lower right")
        self.static_key = (tuple(self._legends.values()), self.ax_t.get_ylabel())

        verdict = "stable" if run.stable else "BLOWN UP: " + run.message
        self.title.set_text(f"k_bend {p['k_bend']:.3g} N/m, damping {p['damping']:.2g} kg/s, "
                            f"dt {1e3 * p['dt']:.3g} ms: {verdict}")
        span = (f"the first {p['t_shown']:.3g} s ({p['steps']} steps, the widget's cap)"
                if p["t_shown"] < p["t_end"] - 0.5 * p["dt"] else f"{p['steps']} steps")
        if not run.stable:
            span = f"stopped after step {last} of {p['steps']}"

        self.subtitle.set_text(f"stable for dt < {1e3 * run.dt_limit:.3g} ms (ω_max² dt² + 2 (c/m) dt"
                               f" < 4, notebook 07); {span}")
        return self.fig


def draw_held_strand(run: HeldStrandRun, fig=None):
    """Draw one run in a new pyplot figure (or ``fig``) and return the figure."""
    if fig is None:
        fig = plt.figure(figsize=FIGSIZE)
    return HeldStrandPlot(fig)(run)


def held_strand_explorer(k_bend: float = 2000.0, damping: float = 2e-3, dt: float = 1e-4):
    """The hair widget over :func:`~course_lib.lessons.nb08_hair_runs.run_held_strand`
    (runs capped at :data:`MAX_STEPS` steps). Returns a
    :class:`~course_lib.lessons.busy_view.BusyExplorerView`."""
    import ipywidgets as w

    from ..widgets import log_slider
    from .busy_view import BusyExplorerView

    controls = {
        "k_bend": log_slider("k_bend (N/m)", k_bend, 1.0, 1e4),
        "damping": w.FloatSlider(value=damping, min=0.0, max=1e-2, step=5e-4,
                                 description="damping (kg/s)", readout_format=".1e",
                                 continuous_update=False, style={"description_width": "initial"}),
        "dt": log_slider("dt (s)", dt, 2e-5, 1e-3),
    }
    return BusyExplorerView(run_held_strand, HeldStrandPlot(blit=True), controls,
                            fixed={"max_steps": MAX_STEPS, "t_end": T_END})


def draw_saddle(esc: SaddleEscape, rest=None):
    """The held zigzag seen from the front (x, y) and along the held-out direction (z, y,
    stretched across): its equilibrium in its plane, the stable 3D resting shape, and
    snapshots of the run nudged off the first; on the right the tip's height against time.
    ``rest`` (n, 3) draws the rest shape too."""
    fig, (front, side, tip) = plt.subplots(1, 3, figsize=(12.5, 3.9),
                                           gridspec_kw={"width_ratios": [1.2, 0.8, 1.1]})
    picks = np.searchsorted(esc.t, [0.03, 0.05, 0.07, 0.1, 0.2])
    shades = plt.cm.Greys(np.linspace(0.35, 0.75, len(picks)))
    for ax, (h, v) in zip((front, side), ((0, 1), (2, 1)), strict=True):
        if rest is not None:
            ax.plot(rest[:, h], rest[:, v], **{**EXACT_STYLE, "linewidth": 1.0},
                    label="rest shape")
        for k, c in zip(picks, shades, strict=True):
            ax.plot(esc.x[k, :, h], esc.x[k, :, v], color=c, lw=0.8,
                    label=f"nudged run, t = {esc.t[picks[0]]:.2f} ... {esc.t[k]:.1f} s"
                    if k == picks[-1] else None)
        ax.plot(esc.planar.x[:, h], esc.planar.x[:, v], "o-", color="C1", ms=2.5, lw=1.5,
                label="equilibrium in its plane (a saddle)")
        ax.plot(esc.minimum.x[:, h], esc.minimum.x[:, v], "o-", color="C3", ms=2.5, lw=2,
                label="stable resting shape")
        ax.set(ylim=(-0.29, 0.03), ylabel="y (m)")
    front.set(xlabel="x (m)", aspect="equal", xlim=(-0.02, 0.32), title="from the front")
    side.set(xlabel="z (m), across the plane", xlim=(-0.012, 0.012),
             title="seen along x (z stretched)")
    side.xaxis.set_major_locator(MaxNLocator(3))
    front.legend(fontsize=7, loc="lower left", bbox_to_anchor=(0.25, 0.0))
    tip.plot(esc.t, esc.x[:, -1, 1] * 100, color="0.3", label="tip of the nudged run")
    tip.axhline(esc.planar.x[-1, 1] * 100, color="C1", ls="--", label="in-plane equilibrium")
    tip.axhline(esc.minimum.x[-1, 1] * 100, color="C3", ls="--", label="stable resting shape")
    tip.set(xlabel="t (s)", ylabel="tip height y (cm)", title="nudged by 1 µm, damped")
    tip.legend(fontsize=8, loc="center right")
    fig.tight_layout()
    return fig


# --- strands seen from the front and the side ----------------------------------------------

#: Views: (horizontal axis, vertical axis, depth axis toward the viewer, label).
VIEWS = {"front": (0, 1, 2, "x (m)"), "side": (2, 1, 0, "z (m)")}


class StrandPainter:
    """Draws strands in the given views; segments behind the head go behind its disc."""

    def __init__(self, axes, network: SpringNetwork, head=None, views=("front",),
                 color="saddlebrown", lw=1.5):
        edges = network.select("edge")
        self.seg = np.stack((edges.i, edges.j), axis=1)
        self.head, self.views, self.axes = head, views, axes
        self.front, self.back = [], []
        for ax, view in zip(axes, views, strict=True):
            h, v, _, label = VIEWS[view]
            if head is not None:
                c, r = head
                ax.add_patch(plt.Circle((c[h], c[v]), r, color="0.85", zorder=2))
            self.back.append(ax.add_collection(LineCollection([], colors=color, lw=lw, zorder=1)))
            self.front.append(ax.add_collection(LineCollection([], colors=color, lw=lw, zorder=3)))
            ax.set(xlabel=label, ylabel="y (m)", aspect="equal")
            ax.set_title(f"{view} view", fontsize=10)

    def __call__(self, x):
        pts = x[self.seg]                                   # (segments, 2, 3)
        for view, back, front in zip(self.views, self.back, self.front, strict=True):
            h, v, depth, _ = VIEWS[view]
            behind = (np.zeros(len(pts), bool) if self.head is None
                      else pts[:, :, depth].mean(axis=1) < self.head[0][depth])
            back.set_segments(pts[behind][:, :, [h, v]])
            front.set_segments(pts[~behind][:, :, [h, v]])
        return self.back + self.front


def animate(frames, network: SpringNetwork, *, head=None, views=("front",),
            size=(4.6, 4.0), xlim=(-0.32, 0.32), ylim=(-0.3, 0.35), fps: float = FPS,
            title: str = "", frame_times=None):
    """A ``FuncAnimation`` of strands (springs of kind ``"edge"``) in one or more views
    side by side, with an optional head ``(center, radius)``; ``xlim`` is the horizontal
    range of every view. The first frame is drawn before the animation is returned."""
    from matplotlib.animation import FuncAnimation

    fig, axes = plt.subplots(1, len(views), figsize=size, squeeze=False, sharey=True)
    axes = list(axes[0])
    paint = StrandPainter(axes, network, head, views)
    for ax in axes:
        ax.set(xlim=xlim, ylim=ylim)
    for ax in axes[1:]:
        ax.set_ylabel("")
    times = np.arange(len(frames)) / fps if frame_times is None else np.asarray(frame_times)
    stamp = axes[-1].text(0.97, 0.03, "", transform=axes[-1].transAxes, fontsize=9,
                          ha="right", zorder=5)
    if title:
        axes[0].set_title(f"{title}: {axes[0].get_title()}" if len(views) > 1 else title,
                          fontsize=10)
    fig.subplots_adjust(left=0.8 / size[0], right=0.98, bottom=0.12,
                        top=0.92, wspace=0.06)

    def update(k):
        stamp.set_text(f"t = {times[k]:.2f} s")
        return [*paint(frames[k]), stamp]

    update(0)
    return FuncAnimation(fig, update, frames=len(frames), interval=1000.0 / fps, blit=False)


def draw_hairstyle(states, times, network: SpringNetwork, head, xlim=(-0.32, 0.32),
                   ylim=(-0.3, 0.35)):
    """Static pictures of a hairstyle: one column per state, front view above, side below."""
    n = len(states)
    fig, axes = plt.subplots(2, n, figsize=(2.9 * n, 5.8), sharey=True, squeeze=False)
    for k, (x, t) in enumerate(zip(states, times, strict=True)):
        pair = [axes[0, k], axes[1, k]]
        StrandPainter(pair, network, head, ("front", "side"))(x)
        for ax in pair:
            ax.set(xlim=xlim, ylim=ylim)
            ax.set_title(f"t = {t:.1f} s, {ax.get_title()}", fontsize=10)
            if k:
                ax.set_ylabel("")
    fig.tight_layout(pad=0.3)
    return fig

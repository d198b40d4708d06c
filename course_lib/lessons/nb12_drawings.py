"""Notebook 12 (constraints and large steps): drawings, animations and the frame widget.

Holds the stiffness of PBD and XPBD against the iteration count
(:func:`draw_stiffness`), the convergence of one implicit step (:func:`draw_convergence`),
the measured comparison (:func:`draw_comparison`), the drape (:func:`draw_drape`,
:func:`animate_drape`, :func:`showcase_animation` for the course's clips), and the widget:
:class:`FramePlot` redraws one frame of :func:`~course_lib.lessons.nb12_frames.
frame_experiment` in place, :func:`frame_explorer` wires it to controls and
:func:`frame_player` precomputes it for readers without a kernel.
Lesson layer: imports matplotlib, the view helpers and the lesson's compute modules.
"""

from __future__ import annotations

import html

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.colors import LogNorm
from matplotlib.ticker import FixedLocator, NullLocator

from ..plotting import EXACT_STYLE, METHOD_COLORS, detached_figure
from ..widgets import BlitPlot, PictureView
from . import nb12_constraints as lesson
from . import nb12_frames as frames

COLORS = {"symplectic_euler": METHOD_COLORS["symplectic_euler"],
          "baraff_witkin": METHOD_COLORS["backward_euler"], "fast_mass_spring": "#2ca02c",
          "xpbd": "#ff7f0e"}


def draw_stiffness(study: dict):
    """Effective stiffness of the hanging chain against iterations per step, PBD and XPBD,
    beside the springs' own ``k``."""
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    its = study["iterations"]
    ax.loglog(its, study["pbd"], "o-", color="C3", label="PBD (stiffness 0.5 per iteration)")
    ax.loglog(its, study["xpbd"], "s-", color=COLORS["xpbd"], label="XPBD (compliance 1/k)")
    ax.axhline(study["k"], **EXACT_STYLE, label=f"the springs' k = {study['k']:g} N/m")
    ax.set(xlabel="iterations per step", ylabel="effective stiffness (N/m)",
           title="a hanging chain of 4 springs at rest: weight / sag")
    ax.set_xticks(its, labels=[str(i) for i in its])
    ax.minorticks_off()
    ax.legend(fontsize=8)
    return fig


def draw_convergence(conv: dict):
    """``g - g_min`` after each iteration of one implicit step, local/global and L-BFGS."""
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    for name, color in (("local/global", "C0"), ("L-BFGS", COLORS["fast_mass_spring"])):
        g = conv[name] - conv["minimum"]
        ax.semilogy(np.arange(g.size), g, "o-", ms=3, color=color, label=name)
    ax.set(xlabel="iteration", ylabel=r"$g(x_k) - \min g$ (J)",
           title="one implicit Euler step of the swinging cloth (16², stiffness ×100)")
    ax.legend(fontsize=8)
    return fig


def draw_comparison(rows: list):
    """CPU time per simulated second and peak structural strain of each method at each
    stiffness (two bar panels, log scales)."""
    factors = sorted({r["factor"] for r in rows})
    methods = list(lesson.METHOD_NAMES)
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), constrained_layout=True)
    width = 0.8 / len(methods)
    for k, method in enumerate(methods):
        sel = [next(r for r in rows if r["factor"] == f and r["method"] == method) for f in factors]
        pos = np.arange(len(factors)) + (k - 1.5) * width
        for ax, key, scale in ((axes[0], "seconds", 1.0), (axes[1], "peak", 100.0)):
            ax.bar(pos, [scale * r[key] for r in sel], width, color=COLORS[method],
                   label=lesson.METHOD_NAMES[method])
    for ax in axes:
        ax.set_xticks(np.arange(len(factors)), labels=[f"×{f}" for f in factors])
        ax.set(yscale="log", xlabel="structural stiffness (× 300 N/m)")
    axes[0].set(ylabel="CPU time per simulated second (s)",
                title="cost (this machine; one call per 1/60 s frame)")
    axes[1].set(ylabel="peak structural strain (%)",
                title=f"stretch over the first {lesson.TABLE_FRAMES} frames "
                      f"({lesson.TABLE_FRAMES / 60:.2g} s)")
    axes[0].legend(fontsize=8)
    return fig


def project(x, elevation: float = 22.0, azimuth: float = 35.0) -> np.ndarray:
    """Oblique view of 3D points (y up), screen coordinates (m), shape ``(..., 2)``."""
    a, e = np.radians(azimuth), np.radians(elevation)
    across = x[..., 0] * np.cos(a) + x[..., 2] * np.sin(a)
    depth = -x[..., 0] * np.sin(a) + x[..., 2] * np.cos(a)
    return np.stack((across, x[..., 1] * np.cos(e) + depth * np.sin(e)), axis=-1)


def _quads(x, shape):
    """The grid's cells as screen quadrilaterals, back to front, and a shade per cell."""
    p = project(x).reshape(*shape, 2)
    X = x.reshape(*shape, 3)
    quads = np.stack((p[:-1, :-1], p[:-1, 1:], p[1:, 1:], p[1:, :-1]), axis=2).reshape(-1, 4, 2)
    normal = np.cross(X[1:, :-1] - X[:-1, :-1], X[:-1, 1:] - X[:-1, :-1]).reshape(-1, 3)
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    shade = 0.35 + 0.65 * np.abs(normal @ np.array([0.3, 0.9, 0.3]) / np.sqrt(0.99))
    a, e = np.radians(35.0), np.radians(22.0)
    depth = (-X[:-1, :-1, 0] * np.sin(a) + X[:-1, :-1, 2] * np.cos(a)) * np.cos(e) \
        - X[:-1, :-1, 1] * np.sin(e)
    order = np.argsort(-depth.ravel())
    return quads[order], shade[order]


def _stage(ax, radius, extent=0.75):
    ax.add_patch(plt.Circle((0.0, 0.0), radius, color="0.78", zorder=0))
    corners = np.array([[-extent, -radius, -extent], [extent, -radius, -extent],
                        [extent, -radius, extent], [-extent, -radius, extent]])
    ax.add_patch(plt.Polygon(project(corners), color="0.92", zorder=-1))
    ax.set(aspect="equal", xticks=[], yticks=[])
    ax.grid(False)
    for side in ax.spines.values():
        side.set_visible(False)


def _cloth_patches(ax, x, shape):
    quads, shade = _quads(x, shape)
    colors = np.outer(shade, [0.25, 0.45, 0.85])
    poly = PolyCollection(quads, facecolors=colors, edgecolors="none", zorder=2)
    ax.add_collection(poly)
    return poly


def draw_drape(run, shape, radius: float, frames):
    """The drape at some frames, side by side."""
    fig, axes = plt.subplots(1, len(frames), figsize=(2.8 * len(frames), 2.7), constrained_layout=True)
    for ax, f in zip(axes, frames, strict=True):
        _stage(ax, radius)
        _cloth_patches(ax, run.x[f], shape)
        ax.set(xlim=(-0.75, 0.75), ylim=(-0.55, 0.55), title=f"t = {run.t[f]:.2f} s")
    return fig


def animate_drape(run, shape, radius: float, fps: float = 30.0, figsize=(4.0, 3.2),
                  title: str = "cloth on a sphere, self-collision on", every: int = 1):
    """A ``FuncAnimation`` of the drape, one picture per ``every`` stored frames (played
    at ``fps / every`` pictures per second, so the motion keeps its speed)."""
    from matplotlib.animation import FuncAnimation

    fig, ax = plt.subplots(figsize=figsize)
    fig.subplots_adjust(0.01, 0.01, 0.99, 0.92)
    _stage(ax, radius)
    ax.set(xlim=(-0.8, 0.8), ylim=(-0.55, 0.55))
    poly = _cloth_patches(ax, run.x[0], shape)
    label = ax.set_title(title, fontsize=9)

    def update(f):
        quads, shade = _quads(run.x[f], shape)
        poly.set_verts(quads)
        poly.set_facecolor(np.outer(shade, [0.25, 0.45, 0.85]))
        label.set_text(f"{title}, t = {run.t[f]:.2f} s")
        return poly, label

    return FuncAnimation(fig, update, frames=range(0, len(run.t), every),
                         interval=1000.0 * every / fps)


def showcase_animation():
    """The notebook's best scene for the course's clips: the drape, 3 s at 30 frames per
    second, 1280 × 720 pixels at 100 dpi."""
    c, run, _ = lesson.drape(frames=90, fps=30.0)
    return animate_drape(run, c.shape, lesson.DRAPE["radius"], figsize=(12.8, 7.2),
                         title="fast mass-springs: a cloth falls on a sphere and folds onto itself")


def _mesh_line(x, shape) -> np.ndarray:
    """The grid's rows and columns, projected, as one polyline with NaN breaks ``(K, 2)``."""
    p = project(x).reshape(*shape, 2)
    gap = np.full((1, 2), np.nan)
    lines = [part for r in range(shape[0]) for part in (p[r], gap)]
    lines += [part for c in range(shape[1]) for part in (p[:, c], gap)]
    return np.concatenate(lines)


class FramePlot(BlitPlot):
    """The widget's figure: the cloth in an oblique view (start of the frame grey, end dark
    with every particle coloured by the largest strain of its structural springs) and the
    peak strain against the converged frame's. Its axes never change: with ``blit=True``
    (the live widget) everything else is drawn once and a redraw draws only the two
    meshes, the particles and the two bars. The title (:meth:`describe`; ``title``,
    default ``not blit``) would cost more than all of them to draw: the live widget shows
    it as text above the picture (:class:`FrameView`)."""

    def __init__(self, fig=None, *, blit: bool = False, title: bool | None = None):
        if fig is None:
            fig = detached_figure((9.5, 3.6))
            fig.set_dpi(80)
        super().__init__(fig, blit)
        title = not blit if title is None else title
        self.ax, self.bar_ax = self.fig.subplots(1, 2, gridspec_kw={"width_ratios": [2.2, 1]})
        self.fig.subplots_adjust(left=0.08, right=0.97, bottom=0.15, top=0.84 if title else 0.95,
                                 wspace=0.4)
        self.start, = self.ax.plot([], [], color="0.8", lw=0.5, label="start of the frame")
        self.end, = self.ax.plot([], [], color="0.25", lw=0.4, label="end")
        self.dots = self.ax.scatter([], [], c=[], s=5, cmap="viridis", norm=LogNorm(0.01, 10.0),
                                    linewidths=0, zorder=3)
        bar = self.fig.colorbar(self.dots, ax=self.ax, pad=0.01)
        bar.set_label("strain at the end (%)")
        bar.set_ticks([0.01, 0.1, 1, 10], labels=["0.01", "0.1", "1", "10"])
        bar.ax.yaxis.set_minor_locator(NullLocator())
        # An oblique view: screen coordinates mean little, so no ticks.
        self.ax.set(xlim=(-0.45, 0.4), ylim=(-0.6, 0.12), aspect="equal", xticks=[], yticks=[],
                    xlabel="the cloth, oblique view (32 × 32, pinned at two corners)")
        self.ax.legend(handles=[self.start, self.end], loc="lower left", fontsize=8)
        self.bars = self.bar_ax.bar([0, 1], [1.0, 1.0], color=["C2", "0.5"])
        self.bar_ax.set_xticks([0, 1], labels=["this frame", "converged"])
        self.bar_ax.grid(False)
        self.bar_ax.set(yscale="log", ylim=(0.005, 1000.0), ylabel="peak structural strain (%)")
        self.bar_ax.yaxis.set_major_locator(FixedLocator([0.01, 0.1, 1, 10, 100, 1000]))
        self.bar_ax.yaxis.set_minor_locator(NullLocator())
        self.bar_ax.set_yticklabels(["0.01", "0.1", "1", "10", "100", "1000"])
        self.title = self.fig.suptitle("", fontsize=10) if title else None
        self.dynamic = [self.start, self.end, self.dots, *self.bars]
        self._struct = None

    def __call__(self, result):
        c = result.cloth
        net = c.network
        if self._struct is None or self._struct[0] is not net:
            struct = net.kind == "struct"
            self._struct = (net, struct, net.i[struct], net.j[struct])
        _, struct, i, j = self._struct
        self.start.set_data(*_mesh_line(result.x_start, c.shape).T)
        if result.stable:
            self.end.set_data(*_mesh_line(result.x_end, c.shape).T)
            worst = np.zeros(c.n)
            s = np.abs(result.strain[struct])
            np.maximum.at(worst, i, s)
            np.maximum.at(worst, j, s)
            self.dots.set_offsets(project(result.x_end))
            self.dots.set_array(np.maximum(100 * worst, 0.01))
        else:
            self.end.set_data([], [])
            self.dots.set_offsets(np.empty((0, 2)))
            self.dots.set_array(np.empty(0))
        peak = 100 * result.peak if result.stable else 1000.0
        self.bars[0].set_height(max(peak, 0.005))
        self.bars[0].set_color(COLORS[result.params["method"]] if result.stable else "C3")
        self.bars[1].set_height(100 * result.reference_peak)
        if self.title is not None:
            self.title.set_text(self.describe(result))
        return self.fig

    @staticmethod
    def describe(result) -> str:
        """The title: method, stiffness, iterations and the verdict."""
        p = result.params
        return (f"{lesson.METHOD_NAMES[p['method']]}, stiffness ×{p['stiffness']:g}, "
                f"{p['iterations']} iterations: {result.verdict}")


class FrameView(PictureView):
    """:class:`~course_lib.widgets.PictureView` with the frame's title as a line of text
    above the picture (:meth:`FramePlot.describe`)."""

    def __init__(self, compute, draw, controls, fixed=None, name: str = "Explorer"):
        import ipywidgets as w

        self.caption = w.HTML(value="")
        super().__init__(compute, draw, controls, fixed, name=name)
        head, image = self.widget.children
        self.widget.children = (head, self.caption, image)

    def update(self) -> None:
        super().update()
        self.caption.value = f"<b>{html.escape(self.draw.describe(self.result))}</b>"


def frame_explorer(method: str = "fast_mass_spring", stiffness: float = 100.0, iterations: int = 10):
    """The widget: method, stiffness and iterations over
    :func:`~course_lib.lessons.nb12_frames.frame_experiment` (32²), one :class:`FramePlot`
    redrawn in place (blitted) and shown as a picture. Building it loads what every
    stiffness needs and factors fast mass-springs' matrices
    (:func:`~course_lib.lessons.nb12_frames.warm_up`), so no first visit waits."""
    import ipywidgets as w

    frames.warm_up()
    controls = {
        "method": w.Dropdown(options=[(v, k) for k, v in lesson.METHOD_NAMES.items()],
                             value=method, description="method"),
        "stiffness": w.SelectionSlider(options=list(frames.WIDGET_FACTORS), value=stiffness,
                                       description="stiffness ×", continuous_update=False),
        "iterations": w.IntSlider(value=iterations, min=1, max=50, description="iterations",
                                  continuous_update=False),
    }
    return FrameView(frames.frame_experiment, FramePlot(blit=True), controls,
                     name="Frame explorer")


def frame_player(method: str = "xpbd", stiffness: float = 100.0,
                 iterations=(1, 4, 10, 40)):
    """The widget's iterations slider, precomputed (no kernel needed)."""
    from ..players import parameter_player

    return parameter_player(
        frames.frame_experiment, FramePlot(), "iterations", iterations,
        fixed={"method": method, "stiffness": stiffness}, fmt="{:d}", colors=32,
        title=f"Without a kernel: {lesson.METHOD_NAMES[method]}, stiffness ×{stiffness:g}; "
              "slide the iterations", caption=lambda r: r.verdict)

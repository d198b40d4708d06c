"""Notebook 03 (stability): the stability explorer's figure, updated in place.

:class:`ExperimentPlot` draws an :class:`~course_lib.lessons.nb03_stability.ExperimentResult`
in three panels: the run beside the exact solution, its size per step on a log scale
(where ``|R|^n`` is a straight line and an unstable run stays in view), and ``z = λ dt``
on the method's stability region. It makes its artists once and afterwards only updates
their data; with ``blit=True`` (the widget) it keeps a picture of the axes, ticks, legend
and region and redraws only the runs, markers and titles over it, and its limits are
rounded outward (:func:`~course_lib.widgets.nice_limits`) so that a small change of the
step keeps that picture. :func:`draw_experiment` makes a static picture.

Imports the lesson's computation and regions, the view helpers and matplotlib.
"""

from __future__ import annotations

import textwrap

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import LogLocator, MaxNLocator, MultipleLocator, NullLocator

from ..integrators import NEWTONIAN_METHODS
from ..plotting import EXACT_STYLE, METHOD_COLORS, METHOD_LABELS, detached_figure
from ..widgets import BlitPlot
from .nb03_problems import default_t_end
from .nb03_regions import REGION_WINDOW, draw_region
from .nb03_stability import ExperimentResult, _fmt_factor

#: Size of the explorer's figure (in).
FIGSIZE = (11.0, 3.9)
#: At most this many points of a run are drawn (a long run is thinned evenly).
MAX_DRAWN = 400


def _thin(n_points: int, keep: int | None = None) -> np.ndarray:
    """Indices of at most :data:`MAX_DRAWN` evenly spread points of ``0..n_points-1``."""
    idx = np.unique(np.linspace(0, n_points - 1, min(n_points, MAX_DRAWN)).round().astype(int))
    return idx if keep is None else np.union1d(idx, [keep])


def _fmt_complex(z: complex) -> str:
    if z.imag == 0:
        return f"{z.real:.3g}"
    if z.real == 0:
        return f"{z.imag:.3g}i"
    return f"{z.real:.3g}{z.imag:+.3g}i"


class ExperimentPlot(BlitPlot):
    """The explorer's figure, redrawn in place; call it with a result to update it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure, optional
        Figure to draw into; by default a new one with an Agg canvas, outside pyplot
        (the notebook's inline backend never shows it by itself).
    blit : bool
        For :meth:`png`: keep a picture of what changes only with the limits, the method
        or the problem (axes, ticks, legend, the stability region) and redraw only the
        rest on each update (:class:`~course_lib.widgets.BlitPlot`).
    snap : bool, optional
        Round the limits of the run's panels outward (default: as ``blit``).
    """

    def __init__(self, fig=None, *, blit: bool = False, snap: bool | None = None):
        if fig is None:
            fig = detached_figure(FIGSIZE)
        super().__init__(fig, blit)
        self.round_limits = blit if snap is None else snap
        if self.round_limits:   # unhinted text renders faster (titles change every update)
            self.rc = {"text.hinting": "none"}
        self.ax_t, self.ax_n, self.ax_z = fig.subplots(
            1, 3, gridspec_kw={"width_ratios": [1.25, 1.0, 0.95]})
        ax_t, ax_n, ax_z = self.ax_t, self.ax_n, self.ax_z
        (self.exact_line,) = ax_t.plot([], [], **EXACT_STYLE)
        (self.num_line,) = ax_t.plot([], [], "-", lw=1.2)
        (self.blow_marker,) = ax_t.plot([], [], "X", color="black", ms=10)
        self.na_text = ax_t.text(0.5, 0.5, "", transform=ax_t.transAxes, ha="center",
                                 va="center")
        self.more_text = ax_t.text(0.98, 0.03, "", transform=ax_t.transAxes, ha="right",
                                   fontsize=9)
        ax_t.set_xlabel("time t (s)")
        ax_t.set_ylabel("position x (m)")
        (self.size_exact,) = ax_n.semilogy([], [], **EXACT_STYLE)
        (self.size_line,) = ax_n.semilogy([], [], "-", lw=1.2)
        (self.size_marker,) = ax_n.semilogy([], [], "X", color="black", ms=10)
        self.bound_line = ax_n.axhline(1.0, color="0.45", ls=":", lw=1.2)
        ax_n.set_xlabel("step n")
        ax_n.set_ylabel("size |y_n|, log scale")
        ax_n.yaxis.set_major_locator(LogLocator(numticks=5))
        ax_n.yaxis.set_minor_locator(NullLocator())
        x0, x1, y0, y1 = REGION_WINDOW
        ax_z.axhline(0, color="0.4", lw=0.8)
        ax_z.axvline(0, color="0.4", lw=0.8)
        ax_z.set(xlim=(x0, x1), ylim=(y0, y1), aspect="equal", xlabel="Re z   (z = λ dt)",
                 ylabel="Im z")
        (self.z_marker,) = ax_z.plot([], [], "*", color="black", ms=14)
        self.z_arrow = ax_z.annotate("", xy=(0, 0), xytext=(0, 0), visible=False,
                                     arrowprops={"arrowstyle": "->", "color": "black", "lw": 2})
        # Few ticks: drawing text dominates the redraw time.
        steps = [1, 2, 5, 10] if self.round_limits else None   # 0 ... 20 on 0 ... 20.5
        for axis in (ax_t.xaxis, ax_t.yaxis):
            axis.set_major_locator(MaxNLocator(4, steps=steps))
        ax_n.xaxis.set_major_locator(MaxNLocator(4, integer=True))
        ax_z.xaxis.set_major_locator(MultipleLocator(2))
        ax_z.yaxis.set_major_locator(MultipleLocator(2))
        # Explicit title positions spare matplotlib a layout pass on every redraw.
        self.title_t = ax_t.set_title("", fontsize=10, y=1.01)
        self.title_n = ax_n.set_title(r"size per step: $|R|^n$ is a line", fontsize=10, y=1.01)
        self.title_z = ax_z.set_title("", fontsize=10, y=1.01)
        self.verdict_text = fig.text(0.01, 0.02, "", fontsize=10, va="bottom")
        fig.subplots_adjust(left=0.06, right=0.99, top=0.8, bottom=0.22, wspace=0.3)
        self._regions: dict[str, list] = {}  # method -> its artists, made once
        self._region_method: str | None = None
        self._legend_key = None
        self._legend = None
        # drawn over the kept background, in the order of a full redraw (lines, then texts)
        self.dynamic = [self.exact_line, self.num_line, self.blow_marker, self.na_text,
                        self.more_text, self.size_exact, self.size_line, self.size_marker,
                        self.bound_line, self.z_marker, self.z_arrow, self.title_t,
                        self.title_z, self.verdict_text]

    def _set_region(self, method: str) -> None:
        if method == self._region_method:
            return
        for artist in self._regions.get(self._region_method, []):
            artist.set_visible(False)
        if method not in self._regions:
            self._regions[method] = draw_region(self.ax_z, method, label=False, decorate=False)
        for artist in self._regions[method]:
            artist.set_visible(True)
        self._region_method = method

    def _set_legend(self, r: ExperimentResult) -> None:
        """One legend for the figure, above the panels; it changes only with the choices."""
        key = (r.problem, r.method, r.applicable)
        if key == self._legend_key:
            return
        if self._legend is not None:
            self._legend.remove()
        self.exact_line.set_label("exact solution, " + (
            "e^(−kt)" if r.problem == "decay" else "cos ωt (size 1)"))
        self.num_line.set_label(f"{METHOD_LABELS[r.method]} run")
        self.blow_marker.set_label("first step past the bound")
        self.bound_line.set_label("blow-up bound (largest size of a stable run × 2)")
        handles = [self.exact_line] + ([self.num_line] if r.applicable else [])
        handles += [self.blow_marker, self.bound_line]
        self._legend = self.fig.legend(handles=handles, loc="upper left", ncol=len(handles),
                                       bbox_to_anchor=(0.005, 1.0), fontsize=9,
                                       handlelength=1.8, columnspacing=1.5)
        self._legend_key = key

    def __call__(self, result: ExperimentResult):
        r = result
        color = METHOD_COLORS[r.method]
        name = METHOD_LABELS[r.method]
        self.exact_line.set_data(r.t_exact, r.x_exact)
        self.num_line.set_color(color)
        self.size_line.set_color(color)
        top, blow = 1.0, r.blowup_step
        if r.applicable:
            # Left: the run up to its first step past the bound (its last point there is
            # the ✖); what follows is on the log plot, where growth stays visible.
            end = r.last_finite if blow is None else blow
            idx = _thin(end + 1)
            self.num_line.set_data(r.t[idx], r.x[idx])
            self.num_line.set_marker("o" if end <= 100 else "")
            self.num_line.set_markersize(3)
            top = max(top, float(np.nanmax(np.abs(r.x[: end + 1]))))
            size = r.size
            idx = _thin(size.size, blow)
            self.size_line.set_data(idx, size[idx])
            self.size_line.set_marker("o" if size.size <= 101 else "")
            self.size_line.set_markersize(3)
            steps = r.t_exact / r.dt
            exact_size = (np.exp(-r.rate * r.t_exact) if r.problem == "decay"
                          else np.ones_like(steps))
            self.size_exact.set_data(steps, exact_size)
            finite = size[np.isfinite(size) & (size > 0)]
            # Zoomed on the run: the exact decay may leave through the bottom.
            lo = max(1e-300, min(finite.min(), 1.0) / 10)
            hi = min(max(finite.max(), r.bound, 1.0) * 3, 1e300)
            self.bound_line.set_ydata([r.bound, r.bound])
            last = size.size - 1
            if self.round_limits:        # past the most steps at a step near this dt
                last = max(last, self._span(r) / r.dt)
            self.limits(self.ax_n, "y", lo, hi, log=True)
            self.limits(self.ax_n, "x", 0, last, nbins=10)
            self.na_text.set_text("")
            more = blow is not None and r.last_finite > blow
            self.more_text.set_text("the run goes on: see the log plot →" if more else "")
        else:
            for line in (self.num_line, self.size_line, self.size_exact):
                line.set_data([], [])
            self.na_text.set_text(f"{name} does not apply\nto a first-order problem")
            self.na_text.set_color(color)
            self.more_text.set_text("")
        if blow is not None:
            self.blow_marker.set_data([r.t[blow]], [r.x[blow]])
            self.size_marker.set_data([blow], [r.size[blow]])
        else:
            self.blow_marker.set_data([], [])
            self.size_marker.set_data([], [])
        t_end = max(r.t_end, self._span(r)) if self.round_limits else r.t_end
        self.limits(self.ax_t, "x", 0.0, t_end, nbins=40)
        self.limits(self.ax_t, "y", -1.15 * top, 1.15 * top, nbins=10)
        self._set_legend(r)
        status = "stable" if r.stable else ("not applicable" if not r.applicable else "UNSTABLE")
        symbol = "k" if r.problem == "decay" else "ω"
        self.title_t.set_text(f"{name}, dt = {r.dt:.3g} s, {symbol} = {r.rate:.3g} /s: {status}")
        self._draw_z(r, name)
        self.verdict_text.set_text(textwrap.fill(r.verdict, 135))
        self.static_key = (self._region_method, self._legend_key)
        return self.fig

    @staticmethod
    def _span(r: ExperimentResult) -> float:
        """The longest run (s) at steps near ``r.dt``: ``n = round(T / dt)`` steps of the
        explorer's span ``T`` end before ``T + dt/2``, so limits past it hold."""
        return default_t_end(r.problem, r.rate) + 0.5 * r.dt

    def _draw_z(self, r: ExperimentResult, name: str) -> None:
        self._set_region(r.method)
        x0, x1, y0, y1 = REGION_WINDOW
        zlabel = f"★ z = {_fmt_complex(r.z)}"
        if r.applicable:
            zlabel += f",  |R| = {_fmt_factor(r.abs_R)}"
        inside = x0 <= r.z.real <= x1 and y0 <= r.z.imag <= y1
        self.z_arrow.set_visible(False)
        self.z_marker.set_data([], [])
        if not r.applicable:
            zlabel = "(for x'' = λ² x: the oscillator)"
        elif inside:
            self.z_marker.set_data([r.z.real], [r.z.imag])
        else:  # show where it is: an arrow towards it at the window's edge
            zlabel += " (off view)"
            tip = (float(np.clip(r.z.real, x0 + 0.3, x1 - 0.3)),
                   float(np.clip(r.z.imag, y0 + 0.3, y1 - 0.3)))
            self.z_arrow.xy = tip
            self.z_arrow.set_position((0.6 * tip[0], 0.6 * tip[1]))
            self.z_arrow.set_visible(True)
        shape = "(segment)" if r.method in NEWTONIAN_METHODS else "(shaded)"
        self.title_z.set_text(f"{name}: stable set {shape}\n{zlabel}")


def draw_experiment(result: ExperimentResult, fig=None):
    """Plot one result (see :class:`ExperimentPlot`) in a new pyplot figure, or in ``fig``.

    For static pictures in a notebook: ``draw_experiment(run_experiment(...)); plt.show()``.
    """
    if fig is None:
        fig = plt.figure(figsize=FIGSIZE)
    return ExperimentPlot(fig)(result)

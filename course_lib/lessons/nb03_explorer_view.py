"""Notebook 03 (stability): drawings and the ipywidgets view of the stability explorer.

The computation lives in :mod:`course_lib.lessons.nb03_stability` (pure functions, no
plotting); this module draws an :class:`~course_lib.lessons.nb03_stability.ExperimentResult`
and wires the controls. Imports the lesson's compute module and the view helpers.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import MaxNLocator, MultipleLocator

from ..plotting import EXACT_STYLE, METHOD_COLORS, METHOD_LABELS
from .nb03_stability import (
    METHODS,
    NEWTONIAN_METHODS,
    PROBLEMS,
    REGION_WINDOW,
    ExperimentResult,
    _fmt_factor,
    _unit_dt_max,
    region_grid,
    run_experiment,
)


def draw_region(
    ax, method: str, window: tuple = REGION_WINDOW, *, label: bool = True, decorate: bool = True
) -> None:
    """Shade ``|R(z)| <= 1`` of ``method`` on ``ax`` (equal aspect, labelled axes).

    The symplectic methods' stable set (for ``x'' = λ² x``) is the segment
    ``z ∈ [-2i, 2i]`` of the imaginary axis, which has no area: it is drawn as a thick line.
    ``decorate=False`` draws the region only (no axes lines, limits or labels).
    """
    color = METHOD_COLORS[method]
    if method in NEWTONIAN_METHODS:
        half = _unit_dt_max(method, "oscillator")
        ax.plot([0, 0], [-half, half], color=color, lw=5, solid_capstyle="butt",
                label="|R| ≤ 1 (a segment)" if label else None)
    else:
        re, im, absR = region_grid(method, window)
        ax.contourf(re, im, absR, levels=[0.0, 1.0], colors=[color], alpha=0.3)
        ax.contour(re, im, absR, levels=[1.0], colors=[color], linewidths=1.5)
        if label:
            ax.fill([], [], color=color, alpha=0.3, label="|R| ≤ 1")
    if not decorate:
        return
    ax.axhline(0, color="0.4", lw=0.8)
    ax.axvline(0, color="0.4", lw=0.8)
    ax.set_xlim(window[0], window[1])
    ax.set_ylim(window[2], window[3])
    ax.set_aspect("equal")
    ax.set_xlabel("Re z  (z = λ dt, dimensionless)")
    ax.set_ylabel("Im z")


def _wrap(text: str, width: int) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, width))


#: Size of the explorer's figure (in).
FIGSIZE = (10.0, 4.2)


class ExperimentPlot:
    """The explorer's figure, redrawn in place: the run beside the exact solution (left),
    and ``z`` on the method's stability region (right), the verdict underneath.

    Calling the object with an :class:`ExperimentResult` updates the data of its artists
    and returns the figure. Reusing one figure (rather than building axes anew) keeps a
    redraw within the explorer's time budget.

    Parameters
    ----------
    fig : matplotlib.figure.Figure, optional
        Figure to draw into; by default a new one, released from pyplot (so the notebook's
        inline backend does not show it a second time).
    """

    def __init__(self, fig=None):
        if fig is None:
            from matplotlib.backends.backend_agg import FigureCanvasAgg

            # Made through pyplot so that the backend (in a notebook: the inline one, which
            # lets IPython display figures as PNG) is loaded; closed at once so that pyplot
            # does not show it by itself (the view displays it), then given an Agg canvas
            # of its own again, since closing leaves it a canvas that cannot draw.
            fig = plt.figure(figsize=FIGSIZE)
            plt.close(fig)
            FigureCanvasAgg(fig)
        self.fig = fig
        self.ax_t, self.ax_z = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.5, 1.0]})
        ax_t, ax_z = self.ax_t, self.ax_z
        self.exact_line, = ax_t.plot([], [], **EXACT_STYLE)
        self.num_line, = ax_t.plot([], [], "o-", ms=3, lw=1.2)
        self.blow_marker, = ax_t.plot([], [], "X", color="black", ms=10)
        self.na_text = ax_t.text(0.5, 0.5, "", transform=ax_t.transAxes, ha="center",
                                 va="center")
        ax_t.set_xlabel("time t (s)")
        ax_t.set_ylabel("position x (m)")
        x0, x1, y0, y1 = REGION_WINDOW
        ax_z.axhline(0, color="0.4", lw=0.8)
        ax_z.axvline(0, color="0.4", lw=0.8)
        ax_z.set_xlim(x0, x1)
        ax_z.set_ylim(y0, y1)
        ax_z.set_aspect("equal")
        ax_z.set_xlabel("Re z   (z = λ dt)")
        ax_z.set_ylabel("Im z")
        self.z_marker, = ax_z.plot([], [], "*", color="black", ms=14)
        self.z_arrow = ax_z.annotate("", xy=(0, 0), xytext=(0, 0), visible=False,
                                     arrowprops={"arrowstyle": "->", "color": "black", "lw": 2})
        # Few ticks: drawing text dominates the redraw time.
        ax_t.xaxis.set_major_locator(MaxNLocator(4))
        ax_t.yaxis.set_major_locator(MaxNLocator(4))
        ax_z.xaxis.set_major_locator(MultipleLocator(2))
        ax_z.yaxis.set_major_locator(MultipleLocator(2))
        # An explicit title position spares matplotlib a layout pass on every redraw.
        self.title_t = ax_t.set_title("", fontsize=11, y=1.01)
        self.title_z = ax_z.set_title("", fontsize=10, y=1.01)
        self.verdict_text = fig.text(0.01, 0.02, "", fontsize=10, va="bottom")
        fig.subplots_adjust(left=0.07, right=0.98, top=0.87, bottom=0.2, wspace=0.25)
        self._region: list = []
        self._region_method: str | None = None

    def _set_region(self, method: str) -> None:
        if method == self._region_method:
            return
        for artist in self._region:
            artist.remove()
        before = set(self.ax_z.get_children())
        draw_region(self.ax_z, method, label=False, decorate=False)
        self._region = [a for a in self.ax_z.get_children() if a not in before]
        self._region_method = method

    def __call__(self, result: ExperimentResult):
        r = result
        color = METHOD_COLORS[r.method]
        name = METHOD_LABELS[r.method]
        ax_t = self.ax_t

        self.exact_line.set_data(r.t_exact, r.x_exact)
        self.exact_line.set_label("exact  exp(−k t)" if r.problem == "decay" else "exact  cos ωt")
        handles = [self.exact_line]
        top = 1.0
        if r.applicable:
            self.num_line.set_data(r.t, r.x)
            self.num_line.set_color(color)
            self.num_line.set_label(f"{name}, dt = {r.dt:.3g} s")
            handles.append(self.num_line)
            # Scale to the run up to the blow-up marker: what grows beyond it leaves the axes.
            shown = r.x if r.blowup_step is None else r.x[: r.blowup_step + 1]
            finite = shown[np.isfinite(shown)]
            top = max(top, float(np.max(np.abs(finite))))
            self.na_text.set_text("")
        else:
            self.num_line.set_data([], [])
            self.na_text.set_text(f"{name} does not apply\nto a first-order problem")
            self.na_text.set_color(color)
        if r.blowup_step is not None:
            self.blow_marker.set_data([r.t[r.blowup_step]], [r.x[r.blowup_step]])
            self.blow_marker.set_label(f"blew up at step {r.blowup_step}")
            handles.append(self.blow_marker)
        else:
            self.blow_marker.set_data([], [])
        ax_t.set_xlim(0.0, r.t_end)
        ax_t.set_ylim(-1.15 * top, 1.75 * top)  # headroom for the legend
        ax_t.legend(handles=handles, loc="upper right", fontsize=9)
        status = "stable" if r.stable else ("not applicable" if not r.applicable else "UNSTABLE")
        symbol = "k" if r.problem == "decay" else "ω"
        self.title_t.set_text(f"{r.problem}, {symbol} = {r.rate:.3g} /s: {status}")

        self._set_region(r.method)
        x0, x1, y0, y1 = REGION_WINDOW
        zlabel = f"★ z = λ dt = {_fmt_complex(r.z)}"
        if r.applicable:
            zlabel += f",  |R| = {_fmt_factor(r.abs_R)}"
        inside = x0 <= r.z.real <= x1 and y0 <= r.z.imag <= y1
        if not r.applicable:
            zlabel = "(for x'' = λ² x: the oscillator)"
            self.z_marker.set_data([], [])
            self.z_arrow.set_visible(False)
        elif inside:
            self.z_marker.set_data([r.z.real], [r.z.imag])
            self.z_arrow.set_visible(False)
        else:  # show where it is: an arrow towards it at the window's edge
            zlabel += " (off view)"
            self.z_marker.set_data([], [])
            tip = (float(np.clip(r.z.real, x0 + 0.3, x1 - 0.3)),
                   float(np.clip(r.z.imag, y0 + 0.3, y1 - 0.3)))
            self.z_arrow.xy = tip
            self.z_arrow.set_position((0.6 * tip[0], 0.6 * tip[1]))
            self.z_arrow.set_visible(True)
        shape = "on a segment" if r.method in NEWTONIAN_METHODS else "shaded"
        self.title_z.set_text(f"{name}: |R(z)| ≤ 1 {shape}\n{zlabel}")
        self.verdict_text.set_text(_wrap(r.verdict, 125))
        return self.fig


def _fmt_complex(z: complex) -> str:
    if z.imag == 0:
        return f"{z.real:.3g}"
    if z.real == 0:
        return f"{z.imag:.3g}i"
    return f"{z.real:.3g}{z.imag:+.3g}i"


def draw_experiment(result: ExperimentResult, fig=None):
    """Plot one result (see :class:`ExperimentPlot`) in a new pyplot figure, or in ``fig``.

    For static pictures in a notebook: ``draw_experiment(run_experiment(...)); plt.show()``.
    """
    if fig is None:
        fig = plt.figure(figsize=FIGSIZE)
    return ExperimentPlot(fig)(result)


def stability_explorer(
    problem: str = "decay", method: str = "forward_euler", dt: float = 0.5, rate: float = 1.0
):
    """The interactive explorer: problem, method, rate and a logarithmic ``dt`` slider.

    Returns a :class:`course_lib.widgets.ExplorerView`; display it in a notebook. Its
    ``result`` is the latest :class:`ExperimentResult`.
    """
    import ipywidgets as w

    from ..widgets import ExplorerView, log_slider

    controls = {
        "problem": w.Dropdown(options=[(label, key) for key, label in PROBLEMS.items()],
                              value=problem, description="problem"),
        "method": w.Dropdown(options=[(METHOD_LABELS[m], m) for m in METHODS],
                             value=method, description="method"),
        "dt": log_slider("dt (s)", dt, 0.01, 10.0),
        "rate": w.FloatSlider(value=rate, min=0.25, max=4.0, step=0.05,
                              description="k or ω (1/s)", continuous_update=False,
                              style={"description_width": "initial"}),
    }
    return ExplorerView(run_experiment, ExperimentPlot(), controls)

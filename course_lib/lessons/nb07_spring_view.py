"""Notebook 07 (springs): the drawing of a spring run and the spring widget.

:class:`SpringPlot` draws a :class:`~course_lib.lessons.nb07_spring_runs.SpringRun` in three
panels (stretch beside the exact curve, the error on a log scale, the energy on a log
scale) and redraws in place: a new result updates the data of the same artists. In the
widget (``blit=True``) it keeps a picture of its axes, ticks and legend
(:class:`~course_lib.widgets.BlitPlot`), redraws only the curves and titles over it, and
rounds its limits outward so that a small change of a slider keeps that picture. Long
runs are thinned for drawing only (every ``s``-th step, said in the legend); every step
is computed. A run that blows up is drawn
up to its last finite state, and its growth shows on the log panels.

Lesson layer: imports the compute module (:mod:`~course_lib.lessons.nb07_spring_runs`), the
plotting style and the widget views; nothing imports it back but the notebook's facade
(:mod:`~course_lib.lessons.nb07_springs`) and the kernel-free players.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import LogLocator, MaxNLocator, NullLocator

from ..integrators import METHODS
from ..plotting import EXACT_STYLE, METHOD_COLORS, METHOD_LABELS, detached_figure
from ..widgets import BlitPlot, nice_limits
from .nb07_spring_limits import velocity_verlet_gap_end, velocity_verlet_windows
from .nb07_spring_runs import SpringRun, run_spring

#: Size of the figure (in) and the most points drawn per curve.
FIGSIZE = (10.0, 3.5)
MAX_POINTS = 1500


class SpringPlot(BlitPlot):
    """The spring widget's figure; call it with a :class:`SpringRun` to (re)draw.

    Parameters
    ----------
    fig : matplotlib.figure.Figure, optional
        Figure to draw into; by default a new one, released from pyplot (the widget
        displays it itself).
    blit : bool
        The widget: :meth:`png` redraws only the curves and titles over a kept
        background, and the limits are rounded outward.
    """

    def __init__(self, fig=None, *, blit: bool = False):
        if fig is None:
            fig = detached_figure(FIGSIZE)
        super().__init__(fig, blit)
        # ticks at 1, 2, 5 times a power of ten: round limits such as 20.5 s then show 0 ... 20
        self._steps = [1, 2, 5, 10] if self.round_limits else None
        if blit:    # unhinted text renders faster (the titles change with every update)
            self.rc = {"text.hinting": "none"}
        self.ax_x, self.ax_e, self.ax_E = fig.subplots(1, 3)
        fig.subplots_adjust(left=0.085, right=0.985, top=0.74, bottom=0.15, wspace=0.34)
        ax_x, ax_e, ax_E = self.ax_x, self.ax_e, self.ax_E
        self.exact_x, = ax_x.plot([], [], **EXACT_STYLE, label="exact")
        self.num_x, = ax_x.plot([], [], ".-", ms=3, lw=1)
        self.blow_x, = ax_x.plot([], [], "X", color="black", ms=9, label="last finite state")
        self.num_e, = ax_e.plot([], [], lw=1.2)
        self.exact_E, = ax_E.plot([], [], **EXACT_STYLE, label="exact")
        self.num_E, = ax_E.plot([], [], lw=1.2)
        ax_x.set(xlabel="t (s)", ylabel="stretch x (m)")
        ax_e.set(xlabel="t (s)", ylabel="error |x − exact| (m)", yscale="log")
        ax_E.set(xlabel="t (s)", ylabel="energy (J)")
        # Few ticks and no minor tick labels: drawing text dominates a redraw.
        for ax in (ax_x, ax_e, ax_E):
            ax.xaxis.set_major_locator(MaxNLocator(4, steps=self._steps))
        ax_e.yaxis.set_major_locator(LogLocator(numticks=4))
        ax_e.yaxis.set_minor_locator(NullLocator())
        self.title = fig.text(0.5, 0.975, "", ha="center", va="top", fontsize=10.5)
        self.subtitle = fig.text(0.5, 0.905, "", ha="center", va="top", fontsize=9.5)
        self.dynamic = [self.exact_x, self.num_x, self.blow_x, self.num_e, self.exact_E,
                        self.num_E, self.title, self.subtitle]
        self._scales: dict = {}
        self._legend_key = None

    def _set_yscale(self, ax, scale: str, **kw) -> None:
        """Switch ``ax`` to ``scale`` (and its few ticks) when it changes."""
        if self._scales.get(ax) == (scale, kw):
            return
        ax.set_yscale(scale, **kw)
        if scale == "log":
            ax.yaxis.set_major_locator(LogLocator(numticks=4))
            ax.yaxis.set_minor_locator(NullLocator())
        elif scale == "linear":
            ax.yaxis.set_major_locator(MaxNLocator(5 if ax is self.ax_x else 4, steps=self._steps))
        self._scales[ax] = (scale, kw)

    def __call__(self, run: SpringRun):
        p = run.params
        method, label = p["method"], METHOD_LABELS[p["method"]]
        n = run.t.size
        stride = max(1, int(np.ceil(n / MAX_POINTS)))
        shown = slice(0, None, stride)
        last = run.blowup_step - 1 if run.blowup_step is not None else n - 1
        if stride > 1:   # always include the last finite state
            idx = np.r_[np.arange(0, last + 1, stride), last]
        else:
            idx = np.arange(n)
        color = METHOD_COLORS[method]
        thinned = f" (every {ordinal(stride)} step drawn)" if stride > 1 else ""
        a = abs(float(run.exact[0])) or 1.0

        self.exact_x.set_data(run.t_fine, run.exact_fine)
        self.num_x.set_data(run.t[idx], run.x[idx])
        self.num_x.set(color=color, label=label + thinned,
                       marker="." if n <= 400 else "None")
        top = float(np.nanmax(np.abs(run.x[: last + 1])))
        if run.blowup_step is None:
            self.blow_x.set_data([], [])
        else:
            self.blow_x.set_data([run.t[last]], [run.x[last]])
        if top > 10 * a:   # growth: a symmetric log scale keeps both the start and the end
            self._set_yscale(self.ax_x, "symlog", linthresh=a)
            top = nice_limits(a, 1.5 * top, log=True)[1] if self.round_limits else 1.5 * top
            self.ax_x.set_ylim(-top, top)
        else:
            top = max(top, float(np.max(np.abs(run.exact_fine))))
            self._set_yscale(self.ax_x, "linear")
            self.limits(self.ax_x, "y", -1.15 * top, 1.3 * top, nbins=10)
        # the widget: past the last step (round(t_end / dt) steps end before t_end + dt/2)
        t_last = max(run.t[-1], p["t_end"] + 0.5 * p["dt"]) if self.round_limits else run.t[-1]
        t_last = self.limits(self.ax_x, "x", 0.0, t_last, nbins=40)[1]
        handles = [self.exact_x, self.num_x] + ([self.blow_x] if run.blowup_step else [])
        legend_key = (tuple(h.get_label() for h in handles), color)
        if legend_key != self._legend_key:   # rebuilt only when its entries change
            self.ax_x.legend(handles=handles, loc="lower left", bbox_to_anchor=(0.0, 1.0),
                             ncol=3, fontsize=8.5, borderaxespad=0.2)
            self._legend_key = legend_key

        err = run.error[idx]
        self.num_e.set_data(run.t[idx], np.where(err > 0, err, np.nan))   # 0 at t = 0
        self.num_e.set_color(color)
        positive = err[np.isfinite(err) & (err > 0)]
        if positive.size:
            self.limits(self.ax_e, "y", max(1e-16, 0.3 * float(positive.min())),
                        3.0 * float(positive.max()), log=True)
        self.ax_e.set_xlim(0.0, t_last)

        self.exact_E.set_data(run.t[shown], np.maximum(run.exact_energy[shown], 1e-300))
        self.num_E.set_data(run.t[idx], run.energy[idx])
        self.num_E.set(color=color, label=label)
        E0 = float(run.exact_energy[0])
        E_all = np.r_[run.energy[idx], run.exact_energy[shown]]
        E_all = E_all[np.isfinite(E_all) & (E_all > 0)]
        lo, hi = float(E_all.min()), float(E_all.max())
        if hi > 10 * lo:     # growth or decay: log scale
            self._set_yscale(self.ax_E, "log")
            self.limits(self.ax_E, "y", max(0.3 * lo, 1e-8 * E0), 3.0 * hi, log=True)
        else:                # a band around the exact energy: linear scale shows it
            self._set_yscale(self.ax_E, "linear")
            pad = max(0.15 * (hi - lo), 0.02 * hi)
            self.limits(self.ax_E, "y", lo - pad, hi + 2 * pad, nbins=4)
        self.ax_E.set_xlim(0.0, t_last)
        self.static_key = (self._legend_key, tuple(self._scales.values()))

        self.title.set_text(f"{label}, k = {p['k']:.3g} N/m, c = {p['c']:.3g} N s/m, "
                            f"m = {p['m']:.3g} kg, dt = {p['dt']:.3g} s: {run.message}")
        self.subtitle.set_text(f"{label} with this damping: {run.limit_text}"
                               f"   ({n - 1} steps)")
        return self.fig


def ordinal(n: int) -> str:
    """``1st``, ``2nd``, ``3rd``, ``4th``, ..., ``11th``, ``12th``, ``13th``, ``21st``, ..."""
    if 10 <= n % 100 <= 20:
        return f"{n}th"
    return f"{n}{ {1: 'st', 2: 'nd', 3: 'rd'}.get(n % 10, 'th')}"


def draw_spring_run(run: SpringRun, fig=None):
    """Draw one run in a new pyplot figure (or ``fig``) and return the figure.

    For static pictures in a notebook: ``draw_spring_run(run_spring(...)); plt.show()``.
    """
    if fig is None:
        fig = plt.figure(figsize=FIGSIZE)
    return SpringPlot(fig)(run)


def spring_explorer(k: float = 10.0, c: float = 0.0, dt: float = 0.05,
                    method: str = "symplectic_euler"):
    """The spring widget: sliders for ``k``, ``c`` and ``dt`` and a method menu over
    :func:`~course_lib.lessons.nb07_spring_runs.run_spring`, drawn by one :class:`SpringPlot`.

    Returns a :class:`~course_lib.lessons.busy_view.BusyExplorerView`; ``view.result`` is
    the latest :class:`SpringRun`.
    """
    import ipywidgets as w

    from ..widgets import log_slider
    from .busy_view import BusyExplorerView

    controls = {
        "k": log_slider("k (N/m)", k, 1.0, 1e3),
        "c": w.FloatSlider(value=c, min=0.0, max=20.0, step=0.1, description="c (N s/m)",
                           continuous_update=False, style={"description_width": "initial"}),
        "dt": log_slider("dt (s)", dt, 1e-3, 1.0),
        "method": w.Dropdown(options=[(METHOD_LABELS[m], m) for m in METHODS], value=method,
                             description="method"),
    }
    return BusyExplorerView(run_spring, SpringPlot(blit=True), controls)


def draw_damped_limits(ax, measured: dict | None = None, zeta_max: float = 2.0,
                       top: float = 2.4):
    """Symplectic Euler's and velocity Verlet's stable steps against the damping ratio
    ``ζ = c / c_crit``, in units of the undamped limit ``2/ω``: shaded where the step is
    stable (:func:`~course_lib.lessons.nb07_spring_limits.stable_windows`), and the edges
    ``measured`` (``{method: {ζ: windows in units of 2/ω}}``) as dots."""
    zetas = np.linspace(0.0, zeta_max, 801)[1:]
    se = np.sqrt(1.0 + zetas**2) - zetas
    vv = np.full((zetas.size, 4), np.nan)
    for row, zeta in zip(vv, zetas, strict=True):
        for w, (lo, hi) in enumerate(velocity_verlet_windows(1.0, 1.0, 2.0 * zeta)[:2]):
            row[2 * w:2 * w + 2] = 0.5 * lo, 0.5 * hi
    col_vv, col_se = METHOD_COLORS["velocity_verlet"], METHOD_COLORS["symplectic_euler"]
    ax.fill_between(zetas, 0.0, np.minimum(vv[:, 1], top), color=col_vv, alpha=0.25, lw=0,
                    label="velocity Verlet stable")
    second = np.isfinite(vv[:, 2])
    ax.fill_between(zetas, vv[:, 2], np.minimum(vv[:, 3], top), where=second, color=col_vv,
                    alpha=0.25, lw=0)
    ax.plot(zetas, np.minimum(vv[:, 1], top), color=col_vv, lw=1.2)
    ax.plot(zetas[second], vv[second, 2], color=col_vv, lw=1.2)
    ax.plot(zetas[second], np.minimum(vv[second, 3], top), color=col_vv, lw=1.2)
    ax.fill_between(zetas, 0.0, se, color=col_se, alpha=0.45, lw=0,
                    label=r"symplectic Euler stable: $\sqrt{1+\zeta^2} - \zeta$")
    ax.plot(zetas, se, color=col_se, lw=1.5)
    jump = velocity_verlet_gap_end()[0]
    ax.axvline(jump, color="0.4", ls=":", lw=1)
    ax.text(jump + 0.03, top - 0.06, f"ζ* = {jump:.3f}: Verlet's gap closes", fontsize=8,
            va="top", color="0.3")
    ax.text(0.33, 1.45, "Verlet's gap:\nunstable", fontsize=8, color="0.3", ha="center")
    markers = {"symplectic_euler": "o", "velocity_verlet": "s"}
    for method, by_zeta in (measured or {}).items():
        pts = [(z, edge) for z, windows in by_zeta.items() for lo, hi in windows
               for edge in (lo, hi) if 0.0 < edge <= top]
        z, e = np.array(pts).T
        ax.plot(z, e, markers[method], color="black", mfc=METHOD_COLORS[method], ms=6,
                label=f"{METHOD_LABELS[method]}: measured edges")
    ax.set(xlim=(0.0, zeta_max), ylim=(0.0, top), xlabel=r"damping ratio $\zeta = c/c_{crit}$",
           ylabel=r"stable step $\Delta t$ (units of $2/\omega$)")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return ax

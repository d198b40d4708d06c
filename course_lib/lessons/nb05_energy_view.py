"""Notebook 05 (Newton's second law): the energy-band explorer, live and without a kernel.

- :class:`EnergyBandPlot` draws an :class:`~course_lib.lessons.nb05_newton.EnergyBands`:
  on the left each method's ``E/E0`` over the run beside its theory band (a log scale once
  the run grows without bound, or the bands are wide); on the right the width of the
  symplectic methods' bands against the step, theory as lines and this step's measured
  widths as dots (forward Euler has no band: its growth is in the title). It redraws in
  place; in the widget (``blit=True``) it keeps a picture of its axes, ticks and legends
  (:class:`~course_lib.widgets.BlitPlot`), redraws only the curves and the title over it,
  and rounds its limits outward so that a small change of the step keeps that picture.
- :func:`energy_explorer`: the widget (a log slider for ``dt``) over
  :func:`~course_lib.lessons.nb05_newton.energy_bands`.
- :func:`energy_player`: the same pictures for a list of steps, as a kernel-free player.

Lesson layer: imports the lesson's compute module, the plotting style, the widget view and
the players; nothing in the library imports this module.
"""

from __future__ import annotations

import numpy as np
from matplotlib.ticker import LogLocator, MaxNLocator, NullLocator

from ..players import Player, parameter_player
from ..plotting import EXACT_STYLE, METHOD_COLORS, METHOD_LABELS, detached_figure
from ..widgets import BlitPlot
from .nb05_newton import BAND_METHODS, EnergyBands, energy_bands

FIGSIZE = (10.5, 3.9)
#: Points drawn per curve at most (every step is computed; long runs are thinned to draw).
MAX_POINTS = 1500
#: The steps (s) of the kernel-free player, with ω = 1 rad/s: the limit ω dt = 2 between
#: the last two.
PLAYER_DTS = (0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 1.5, 1.9, 2.1)
DT_RANGE = (0.01, 4.0)


#: The methods whose band widths the right panel draws (forward Euler has no band: its
#: growth is in the title).
WIDTH_METHODS = ("symplectic_euler", "velocity_verlet")


def _band_widths(omega: float, dts: np.ndarray) -> dict:
    """Theory: width of the symplectic methods' bands of ``E/E0`` against the step."""
    h = omega * dts
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return {"symplectic_euler": np.where(h < 2, h / (1.0 - 0.25 * h * h), np.nan),
                "velocity_verlet": np.where(h < 2, 0.25 * h * h, np.nan)}


class EnergyBandPlot(BlitPlot):
    """The explorer's figure; call it with an :class:`EnergyBands` to (re)draw.

    With ``blit=True`` (the widget) :meth:`png` redraws only what changes with the step
    over a kept background, and the energy panel's limits are rounded outward.
    """

    def __init__(self, fig=None, *, blit: bool = False):
        super().__init__(fig if fig is not None else detached_figure(FIGSIZE), blit)
        if blit:    # unhinted text renders faster (the title changes with every update)
            self.rc = {"text.hinting": "none"}
        self.ax_e, self.ax_w = self.fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.35, 1.0]})
        self.fig.subplots_adjust(left=0.07, right=0.98, top=0.80, bottom=0.13, wspace=0.25)
        self.lines, self.lo, self.hi, self.dots = {}, {}, {}, {}
        for m in BAND_METHODS:
            color = METHOD_COLORS[m]
            self.lines[m], = self.ax_e.plot([], [], color=color, lw=0.8, label=METHOD_LABELS[m])
            self.lo[m], = self.ax_e.plot([], [], color=color, ls=":", lw=1.2)
            self.hi[m], = self.ax_e.plot([], [], color=color, ls=":", lw=1.2)
        self.lo["symplectic_euler"].set_label("theory bands")
        self.exact = self.ax_e.axhline(1.0, label="exact $E = E_0$", **EXACT_STYLE)
        self.ax_e.set(xlabel="time (periods)", ylabel="energy $E/E_0$")
        dts = np.geomspace(*DT_RANGE, 200)
        self.ax_w.axvspan(2.0, DT_RANGE[1], color="0.9", zorder=0)
        self.ax_w.text(2.1, 2e-4, "ω dt\n≥ 2:\nun-\nstable", fontsize=8, color="0.35")
        for m in WIDTH_METHODS:
            self.dots[m], = self.ax_w.plot([], [], "o", color=METHOD_COLORS[m], ms=7)
        self.ax_w.plot([], [], "o", color="0.3", label="measured at this dt")
        self.ax_w.plot([], [], color="0.3", label="theory")
        self.widths = {m: self.ax_w.plot(dts, np.full(dts.size, np.nan), color=METHOD_COLORS[m],
                                         lw=1.5)[0] for m in WIDTH_METHODS}
        self.now = self.ax_w.axvline(0.1, color="0.4", lw=0.8)
        self.ax_w.set(xscale="log", yscale="log", xlim=DT_RANGE, ylim=(1e-5, 1e2),
                      xlabel="dt (s)", ylabel="band width of $E/E_0$",
                      title="symplectic Euler ∝ dt, Verlet ∝ dt² (for small ω dt)")
        self.ax_w.title.set_fontsize(9)
        # few ticks: drawing tick labels dominates a redraw
        self.ax_w.xaxis.set_major_locator(LogLocator(numticks=4))
        self.ax_w.yaxis.set_major_locator(LogLocator(numticks=5))
        for axis in (self.ax_w.xaxis, self.ax_w.yaxis):
            axis.set_minor_locator(NullLocator())
        self.ax_e.xaxis.set_major_locator(MaxNLocator(5))
        self.ax_e.yaxis.set_major_locator(MaxNLocator(5))
        self.ax_w.legend(fontsize=8, loc="upper left")
        self._omega = None
        self._fe_label = None
        self.title = self.fig.text(0.5, 0.975, "", ha="center", va="top", fontsize=10)
        self.dynamic = [*(line for m in BAND_METHODS for line in (self.lines[m], self.lo[m],
                                                                  self.hi[m])),
                        *self.dots.values(), self.now, self.title]

    def _set_yscale(self, scale: str) -> None:
        """Switch the energy panel's scale (and its few ticks) when it changes."""
        if self.ax_e.get_yscale() == scale:
            return
        self.ax_e.set_yscale(scale)
        if scale == "log":
            self.ax_e.yaxis.set_major_locator(LogLocator(numticks=5))
            self.ax_e.yaxis.set_minor_locator(NullLocator())
        else:
            self.ax_e.yaxis.set_major_locator(MaxNLocator(5))

    def __call__(self, res: EnergyBands):
        if res.omega != self._omega:
            dts = self.widths["symplectic_euler"].get_xdata()
            for m, w in _band_widths(res.omega, dts).items():
                self.widths[m].set_ydata(w)
            self._omega = res.omega
        stride = max(1, res.t.size // MAX_POINTS)
        periods = res.t[::stride] * res.omega / (2 * np.pi)
        for m in BAND_METHODS:
            self.lines[m].set_data(periods, res.ratio[m][::stride])
            lo, hi = res.band[m]
            show = res.stable and m != "forward_euler"
            self.lo[m].set_data([0, periods[-1]], [lo, lo] if show else [np.nan, np.nan])
            self.hi[m].set_data([0, periods[-1]], [hi, hi] if show else [np.nan, np.nan])
            if m in self.dots:
                low, high = res.spread[m]
                width = high - low if res.stable and np.isfinite(high - low) else np.nan
                self.dots[m].set_data([res.dt], [width])
        self.now.set_xdata([res.dt, res.dt])
        # the widget: past the last step (within half a step of a whole number of periods)
        self.ax_e.set_xlim(0.0, round(periods[-1]) + 0.5 if self.blit else periods[-1])
        lo = min(res.band[m][0] for m in WIDTH_METHODS)
        hi = max(res.band[m][1] for m in WIDTH_METHODS)
        fe_label = "forward Euler (leaves the panel)"
        if res.stable and hi < 4 * lo:     # narrow bands: a linear scale shows them
            pad = 0.25 * (hi - lo)
            self._set_yscale("linear")
            limits = (lo - pad, hi + pad)
            self.limits(self.ax_e, "y", *limits)
        elif res.stable:                   # wide bands (ω dt near 2): a log scale shows both
            self._set_yscale("log")
            limits = (0.6 * lo, 1.6 * hi)
            self.limits(self.ax_e, "y", *limits, log=True)
        else:
            self._set_yscale("log")
            self.ax_e.set_ylim(0.05, 1e12)
            fe_label = METHOD_LABELS["forward_euler"]
        if fe_label != self._fe_label:     # the legend changes with this label only
            self.lines["forward_euler"].set_label(fe_label)
            self.ax_e.legend(fontsize=8, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=3,
                             borderaxespad=0.2, frameon=False)
            self._fe_label = fe_label
        self.static_key = (self._omega, fe_label)
        self.title.set_text(f"ω dt = {res.omega * res.dt:.3g}: {res.verdict}")
        return self.fig


def draw_energy_bands(res: EnergyBands, fig=None):
    """Draw one result in a new pyplot figure (or ``fig``) and return the figure."""
    if fig is None:
        import matplotlib.pyplot as plt

        fig = plt.figure(figsize=FIGSIZE)
    return EnergyBandPlot(fig)(res)


def energy_explorer(dt: float = 0.1):
    """The energy-band widget: a log slider for ``dt`` over
    :func:`~course_lib.lessons.nb05_newton.energy_bands` (ω = 1 rad/s, 20 periods)."""
    from ..widgets import ExplorerView, load_backend, log_slider

    load_backend()
    return ExplorerView(energy_bands, EnergyBandPlot(blit=True),
                        {"dt": log_slider("dt (s)", dt, *DT_RANGE)})


def energy_player(dts=PLAYER_DTS) -> Player:
    """The widget's ``dt`` slider, precomputed (no kernel needed)."""
    return parameter_player(energy_bands, EnergyBandPlot(), "dt", dts, unit="s", fmt="{:g}",
                            colors=16, caption=lambda r: r.verdict,
                            title="Without a kernel: the oscillator x'' = -x (ω = 1 rad/s) "
                                  "over 20 periods; slide the step dt")

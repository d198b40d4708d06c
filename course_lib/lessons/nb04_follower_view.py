"""Notebook 04 (beyond Euler): the follower explorer, κ dt against the methods' first steps.

:class:`FollowerPlot` draws a :class:`~course_lib.lessons.nb04_beyond_euler.FollowerResult`
in two panels: the first 40 steps of every method on the stiff follower beside the exact
solution (time in steps, so the axes never change), and each method's ``|R(-κ dt)|`` along
the negative real axis with the chosen ``κ dt`` marked, where ``|R| > 1`` means the catch-up
mode grows. :func:`follower_explorer` is the live widget (a logarithmic ``κ dt`` slider) and
:func:`follower_player` its kernel-free player. Imports the lesson's computation, the view
helpers of notebook 02's explorer and matplotlib.
"""

from __future__ import annotations

import io

import numpy as np

from ..players import MAX_BYTES, Player, frames_html, parameter_player
from ..plotting import EXACT_STYLE, METHOD_COLORS, METHOD_LABELS, detached_figure
from ..stability import amplification_factor
from ..widgets import BlitPlot, PictureView, log_slider
from .nb04_beyond_euler import FOLLOWER_METHODS, KAPPA_DT_RANGE, FollowerResult, follower_experiment

#: Size of the explorer's figure (in).
FIGSIZE = (11.0, 4.4)
#: κ dt of the kernel-free player: the explicit limits are 2 (forward Euler, midpoint) and
#: 2.785 (RK4).
FOLLOWER_KAPPA_DTS = (0.2, 0.5, 1.0, 1.9, 2.1, 2.9, 5.0, 20.0, 100.0)
_MARKERS = {"forward_euler": "o", "midpoint": "^", "rk4": "D", "backward_euler": "s",
            "trapezoidal": "v"}


class FollowerPlot(BlitPlot):
    """The follower explorer's figure, updated in place: call it with a result."""

    def __init__(self, fig=None, *, blit: bool = False):
        fig = detached_figure(FIGSIZE) if fig is None else fig
        super().__init__(fig, blit)
        ax_x, ax_r = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.25, 1.0]})
        self.ax_x, self.ax_r = ax_x, ax_r
        # drawn on top: backward Euler follows it so closely that it would hide it
        (self.exact,) = ax_x.plot([], [], **{**EXACT_STYLE, "zorder": 5},
                                  label="exact x(t) (left panel)")
        self.lines = {}
        for m in FOLLOWER_METHODS:
            (self.lines[m],) = ax_x.plot([], [], "-", marker=_MARKERS[m], ms=3.5, lw=1.1,
                                         color=METHOD_COLORS[m], label=METHOD_LABELS[m])
        ax_x.axhline(0.0, color="0.6", lw=0.8)
        ax_x.set(xlim=(0, 40), ylim=(-1.6, 2.2), xlabel="step n", ylabel="x (m)")
        self.title_x = ax_x.set_title("", fontsize=10, y=1.01)
        s = np.geomspace(*KAPPA_DT_RANGE, 600)
        for m in FOLLOWER_METHODS:
            ax_r.loglog(s, np.abs(amplification_factor(m, -s)), color=METHOD_COLORS[m], lw=1.4,
                        label=METHOD_LABELS[m])
        ax_r.axhline(1.0, color="black", lw=1.0)
        ax_r.axhspan(1.0, 1e9, color="#f6dede", zorder=0)
        ax_r.text(0.07, 2e3, "|R| > 1: the catch-up mode grows", fontsize=8, color="#a03030")
        ax_r.set(xlim=KAPPA_DT_RANGE, ylim=(1e-3, 1e4), xlabel="κ dt  (z = -κ dt)",
                 ylabel="|R(-κ dt)|")
        self.vline = ax_r.axvline(1.0, color="0.3", lw=1.0, ls=":")
        self.dots = {m: ax_r.plot([], [], _MARKERS[m], color=METHOD_COLORS[m], ms=7,
                                  mec="black")[0] for m in FOLLOWER_METHODS}
        # one legend for both panels, below them: an unstable run sweeps the left panel, and
        # the exact curve is only there
        fig.legend(handles=[self.exact, *self.lines.values()], loc="lower center", ncol=6,
                   fontsize=8, frameon=False, bbox_to_anchor=(0.5, 0.0))
        self.title_r = ax_r.set_title("amplification per step on the negative real axis",
                                      fontsize=10, y=1.01)
        fig.subplots_adjust(left=0.06, right=0.98, top=0.86, bottom=0.2, wspace=0.2)
        # drawn in this order when blitting: the exact curve on top, as in a full redraw
        self.dynamic = [*self.lines.values(), self.exact, self.title_x, self.vline,
                        *self.dots.values()]

    def __call__(self, result: FollowerResult):
        r = result
        self.exact.set_data(r.n_exact, r.x_exact)
        for m, line in self.lines.items():
            line.set_data(r.n, r.x[m])
            self.dots[m].set_data([r.kappa_dt], [max(abs(r.R[m]), 1.1e-3)])
        self.vline.set_xdata([r.kappa_dt, r.kappa_dt])
        blown = [METHOD_LABELS[m] for m in FOLLOWER_METHODS if not r.stable[m]]
        self.title_x.set_text(f"κ dt = {r.kappa_dt:.3g} (dt = {1e3 * r.dt:.3g} ms, 40 steps = "
                              f"{40 * r.dt:.3g} s)\n" + ("unstable: " + ", ".join(blown)
                                                         if blown else "every method is stable"))
        return self.fig


def follower_explorer(kappa_dt: float = 1.5) -> PictureView:
    """The live explorer: a logarithmic ``κ dt`` slider over :func:`follower_experiment`."""
    controls = {"kappa_dt": log_slider("κ dt", kappa_dt, *KAPPA_DT_RANGE)}
    return PictureView(follower_experiment, FollowerPlot(blit=True), controls,
                       name="Follower explorer")


def follower_player(kappa_dts=FOLLOWER_KAPPA_DTS) -> Player:
    """The explorer's ``κ dt`` slider, precomputed: plays without a kernel.

    The frames come from one blitted :class:`FollowerPlot`, as in the live explorer: the
    axes, the ``|R|`` curves and the legend are drawn once, and each frame redraws only the
    runs, the marker and the title over them (about a fifth of a full redraw's CPU time).
    A player over :data:`~course_lib.players.MAX_BYTES` is made again by
    :func:`~course_lib.players.parameter_player`, which lowers the resolution until it fits.
    """
    values = list(kappa_dts)
    results = [follower_experiment(kappa_dt=v) for v in values]
    plot = FollowerPlot(blit=True)
    pngs = []
    for result in results:
        plot(result)
        plot.render()
        pngs.append(_palette_png(plot.fig, _COLORS))
    labels = [f"κ dt = {v:g}" for v in values]
    captions = [r.verdict for r in results]
    html_text = frames_html(pngs, labels, captions, kind="parameter", title=_TITLE, alt=_TITLE)
    if len(html_text.encode("utf-8")) <= MAX_BYTES:
        return Player(html_text, labels, captions, "parameter")
    return parameter_player(follower_experiment, FollowerPlot(), "kappa_dt", values,
                            label="κ dt", fmt="{:g}", colors=_COLORS,
                            caption=lambda r: r.verdict, title=_TITLE,
                            max_bytes=MAX_BYTES)


_TITLE = "Without a kernel: the stiff follower (κ = 1000 /s), first 40 steps; slide κ dt"
_COLORS = 32   # palette size of the player's frames: line plots look the same


def _palette_png(fig, colors: int) -> bytes:
    """The figure's Agg canvas as a ``colors``-entry palette PNG (what
    :func:`~course_lib.players.encode_png` makes of a full redraw)."""
    from PIL import Image

    out = io.BytesIO()
    rgb = Image.fromarray(np.asarray(fig.canvas.buffer_rgba())).convert("RGB")
    rgb.quantize(colors=colors, method=Image.Quantize.FASTOCTREE,
                 dither=Image.Dither.NONE).save(out, format="PNG", optimize=True)
    return out.getvalue()

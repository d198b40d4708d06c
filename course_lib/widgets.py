"""A thin ipywidgets view over a pure computation.

Every interactive demo in the course has two halves:

- a **pure function** ``compute(**params) -> result`` in ``course_lib`` (tested directly);
- a **view**: controls whose values are the function's keyword arguments, and a
  ``draw(result) -> Figure`` that plots the result. The view recomputes and redraws when a
  control changes; it never prints (printing from a widget callback lands in widget state
  and upsets nbval).

:class:`ExplorerView` shows the figure as a PNG in an image widget (no flicker, no page
jump); :class:`PictureView` lets the drawing render its own PNG and says "computing…" while
it works; :class:`BlitPlot` is a kept figure that redraws only its moving artists over a kept
picture of the rest, drawn again when its limits, scales or legends change (notebooks 02,
03, 04, 05, 07, 08 and 12; :func:`nice_limits` rounds a widget's limits).

:func:`load_backend`, called by every view, makes a widget's first picture show in a fresh
kernel (a detached figure never makes pyplot load the inline backend).

No view displays into an ``ipywidgets.Output``: every picture is PNG bytes in an image
widget. A headless runner (nbclient, hence ``nbconvert --execute``) mimics an Output widget
by sending each captured output back to the kernel on the shell socket while it waits on
that socket for the cell's reply, and that reply's wake-up is sometimes lost: the cell then
returns only at the runner's timeout (45 of 200 such cells under load here, none with an
image widget; ``tests/test_widgets_headless.py``).

Tests drive a view the way a student does, by setting a control's ``.value``, then assert
on ``view.result``. Outside a kernel (tests, benchmarks) the figure is drawn off-screen and
closed, so drawing code is exercised too.
"""

from __future__ import annotations

import io
from collections.abc import Callable, Mapping

import matplotlib.pyplot as plt
import numpy as np


def _in_kernel() -> bool:
    try:
        from IPython import get_ipython
    except ImportError:  # pragma: no cover
        return False
    shell = get_ipython()
    return shell is not None and getattr(shell, "kernel", None) is not None


def log_slider(description: str, value: float, lo: float, hi: float, steps: int = 200, **kw):
    """A ``FloatLogSlider`` between ``lo`` and ``hi`` (for time steps and stiffnesses)."""
    import ipywidgets as w

    return w.FloatLogSlider(
        value=value, base=10, min=np.log10(lo), max=np.log10(hi),
        step=(np.log10(hi) - np.log10(lo)) / steps, description=description,
        continuous_update=False, readout_format=".3g",
        style={"description_width": "initial"}, **kw,
    )


def load_backend() -> None:
    """Load matplotlib's backend now. A widget draws on a detached figure, which never
    makes pyplot load its backend; in a fresh kernel the inline backend, which registers
    the PNG display of figures, is then missing and the widget shows ``<Figure ...>`` text
    instead of its picture (until some other cell draws with pyplot)."""
    try:
        from IPython import get_ipython
    except ImportError:  # pragma: no cover
        return
    shell = get_ipython()
    if shell is None or getattr(shell, "kernel", None) is None:
        return                                  # outside a kernel: nothing to display
    from matplotlib.figure import Figure

    try:
        shell.display_formatter.formatters["image/png"].lookup_by_type(Figure)
        return                                  # loaded already (switching would close figures)
    except KeyError:
        pass
    import matplotlib
    import matplotlib.pyplot as plt

    plt.switch_backend(matplotlib.get_backend())


class ExplorerView:
    """Controls + output area wired to ``compute`` and ``draw``.

    Parameters
    ----------
    compute : callable
        ``compute(**params) -> result``: pure, no plotting.
    draw : callable
        ``draw(result) -> matplotlib.figure.Figure``.
    controls : mapping of str to ipywidgets.ValueWidget
        One control per keyword argument of ``compute``.
    fixed : mapping, optional
        Extra keyword arguments passed to ``compute`` unchanged.

    Attributes
    ----------
    result
        The latest result of ``compute``.
    image : ipywidgets.Image
        The figure, as PNG bytes (set on every update in a kernel).
    widget : ipywidgets.VBox
        What to display: the controls above the figure.
    """

    def __init__(self, compute: Callable, draw: Callable, controls: Mapping, fixed: Mapping | None = None):
        import ipywidgets as w

        load_backend()
        self.compute = compute
        self.draw = draw
        self.controls = dict(controls)
        self.fixed = dict(fixed or {})
        self.image = w.Image(format="png")
        self.result = None
        self.figure = None
        for control in self.controls.values():
            control.observe(self._on_change, names="value")
        self.widget = w.VBox([w.HBox(list(self.controls.values()),
                                     layout=w.Layout(flex_flow="row wrap")), self.image])
        self.update()

    @property
    def params(self) -> dict:
        return {**self.fixed, **{name: c.value for name, c in self.controls.items()}}

    def _on_change(self, change) -> None:
        self.update()

    def update(self) -> None:
        """Recompute from the controls' values and redraw."""
        self.result = self.compute(**self.params)
        with plt.ioff():
            self.figure = self.draw(self.result)
        if hasattr(self.draw, "png"):          # a kept figure (BlitPlot): redraws what changed
            self.image.value = self.draw.png()
            return
        if _in_kernel():
            self.image.value = figure_png(self.figure)
        else:
            self.figure.canvas.draw()
        plt.close(self.figure)

    def _ipython_display_(self) -> None:
        from IPython.display import display

        display(self.widget)


class PictureView(ExplorerView):
    """An :class:`ExplorerView` whose figure is a PNG in an image widget.

    ``draw(result)`` updates the figure; ``draw.png()`` renders it. ``name`` is what the
    stored output says in place of the widget when no kernel runs.
    """

    def __init__(self, compute, draw, controls, fixed=None, name: str = "Explorer"):
        import ipywidgets as w

        self.name = name
        self.status = w.HTML(value="", layout=w.Layout(min_width="9em"))
        self.image = w.Image(format="png")
        super().__init__(compute, draw, controls, fixed)
        self.widget = w.VBox([
            w.HBox([*self.controls.values(), self.status], layout=w.Layout(flex_flow="row wrap")),
            self.image,
        ])

    def update(self) -> None:
        """Recompute from the controls' values and redraw, saying so while it runs."""
        self.status.value = "<i>computing…</i>"
        try:
            self.result = self.compute(**self.params)
            self.figure = self.draw(self.result)
            self.image.value = self.draw.png()
        finally:
            self.status.value = ""

    def _repr_mimebundle_(self, **kwargs):
        bundle = self.widget._repr_mimebundle_(**kwargs)
        bundle["text/plain"] = (f"{self.name} (interactive): run this cell in a Jupyter kernel "
                                "to use it; the player above shows its key states.")
        return bundle

    def _ipython_display_(self) -> None:
        from IPython.display import display

        display(self._repr_mimebundle_(), raw=True)


def figure_png(fig) -> bytes:
    """Draw ``fig`` and return it as PNG bytes (its Agg buffer when it has one)."""
    fig.canvas.draw()
    if hasattr(fig.canvas, "buffer_rgba"):
        return png_of(fig)
    buffer = io.BytesIO()                       # pragma: no cover (non-Agg canvases)
    fig.savefig(buffer, format="png")
    return buffer.getvalue()


def png_of(fig) -> bytes:
    """The figure's Agg canvas as PNG bytes, written directly: 8-bit RGBA rows without a
    filter, zlib level 1 (twice as fast as Pillow's adaptive filters, about as small: a
    widget sends it at once)."""
    import struct
    import zlib

    rgba = np.asarray(fig.canvas.buffer_rgba())
    height, width = rgba.shape[:2]
    rows = np.zeros((height, 4 * width + 1), dtype=np.uint8)   # byte 0 of a row: filter 0
    rows[:, 1:] = rgba.reshape(height, -1)

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows.tobytes(), 1)) + chunk(b"IEND", b""))


class BlitPlot:
    """A kept figure redrawn in part: :meth:`render` draws everything once, keeps that
    picture (the background), and afterwards redraws only the artists in :attr:`dynamic`
    over it.

    The background is drawn again when :meth:`background_key` changes: the canvas size,
    every axes' limits and scales, and :attr:`static_key`, which a subclass sets to what
    else its background shows that may change (legend labels, a colour). A widget whose
    axes rescale keeps its limits from :func:`nice_limits`, so a small change of the data
    keeps the background (:meth:`limits`).
    """

    def __init__(self, fig, blit: bool):
        self.fig, self.blit = fig, blit
        self.round_limits = blit
        self.rc: dict = {}       # matplotlib settings while rendering, e.g. faster text
        self.dynamic: list = []
        self.static_key = None
        self._background = None
        self._key = None
        self._limits: dict = {}

    def limits(self, ax, which: str, lo: float, hi: float, log: bool = False,
               nbins: int = 5) -> tuple[float, float]:
        """Limits of ``ax``'s ``which`` axis (``"x"`` or ``"y"``) to show ``[lo, hi]``: as
        given, or with :attr:`round_limits` (the widget) rounded outward
        (:func:`nice_limits`), the previous ones kept while they still fit on the same
        scale. Sets them and returns them."""
        if self.round_limits:
            scale = ax.get_xscale() if which == "x" else ax.get_yscale()
            before = self._limits.get((id(ax), which))
            keep = before[1] if before is not None and before[0] == scale else None
            lo, hi = nice_limits(lo, hi, log, nbins, keep)
            self._limits[(id(ax), which)] = (scale, (lo, hi))
        (ax.set_xlim if which == "x" else ax.set_ylim)(lo, hi)
        return lo, hi

    def background_key(self) -> tuple:
        """What the kept background depends on (hashable, compared between updates)."""
        axes = tuple((ax.get_xlim(), ax.get_ylim(), ax.get_xscale(), ax.get_yscale())
                     for ax in self.fig.axes)
        return self.fig.canvas.get_width_height(), axes, self.static_key

    def render(self) -> None:
        """Draw the figure on its Agg canvas (with :attr:`blit`, only what changed)."""
        if self.rc:
            import matplotlib as mpl

            with mpl.rc_context(self.rc):
                self._render()
        else:
            self._render()

    def _render(self) -> None:
        canvas = self.fig.canvas
        if not self.blit:
            canvas.draw()
            return
        key = self.background_key()
        if self._background is None or key != self._key:
            for artist in self.dynamic:
                artist.set_animated(True)
            canvas.draw()
            self._background = canvas.copy_from_bbox(self.fig.bbox)
            self._key = key
        else:
            canvas.restore_region(self._background)
        for artist in self.dynamic:
            self.fig.draw_artist(artist)

    def png(self) -> bytes:
        """Render (see :meth:`render`) and return the figure as PNG bytes."""
        self.render()
        return png_of(self.fig)


def nice_limits(lo: float, hi: float, log: bool = False, nbins: int = 5,
                keep: tuple[float, float] | None = None) -> tuple[float, float]:
    """Axis limits around ``[lo, hi]`` at round values: outer ticks of a
    ``MaxNLocator(nbins)`` (linear), or whole decades (``log``; ``lo`` > 0). A small
    change of the data keeps them, so a blitted background stays valid; ``keep`` (the
    current limits) is returned while it holds ``[lo, hi]`` and is at most twice as wide
    as the new limits (one decade wider on a log scale), so data near a round value does
    not make the limits flip."""
    if log:
        new = float(10.0 ** np.floor(np.log10(lo))), float(10.0 ** np.ceil(np.log10(hi)))
    else:
        from matplotlib.ticker import MaxNLocator

        ticks = MaxNLocator(nbins).tick_values(lo, hi)
        below, above = ticks[ticks <= lo], ticks[ticks >= hi]
        new = (float(below.max()) if below.size else float(lo),
               float(above.min()) if above.size else float(hi))
    if keep is not None and keep[0] <= lo and hi <= keep[1]:
        a, b = keep
        if (np.log10(b / a) <= np.log10(new[1] / new[0]) + 1.0 if log
                else b - a <= 2.0 * (new[1] - new[0])):
            return float(a), float(b)
    return new

"""Kernel-free players: precomputed PNG frames behind a slider, as self-contained HTML.

Two uses share one player:

- :func:`animation_player` turns a ``matplotlib.animation.Animation`` into a player with
  play/pause and step buttons (what :func:`course_lib.plotting.animation_html` returns);
- :func:`parameter_player` runs a widget's pure ``compute`` function for a list of values of
  one parameter, draws each result with the widget's ``draw`` function, and returns a
  player whose slider scrubs through the values: a reader without a kernel can still feel
  where a method turns unstable.

The HTML needs no network and no kernel: icons are inline SVG, frames are PNG data URIs,
the script is inline. The first frame is a plain ``<img>`` with its size set, so a frame
shows (and the page does not jump) before any script runs, for instance in an untrusted
notebook, where a note says how to enable the controls. Imports only NumPy, matplotlib,
Pillow (a matplotlib dependency) and :mod:`course_lib._player_assets`.
"""

from __future__ import annotations

import base64
import hashlib
import html
import io
import json
from collections.abc import Callable, Mapping, Sequence

import matplotlib.pyplot as plt
import numpy as np

from ._player_assets import PLAYER_CSS, PLAYER_JS, controls_html
from .clips.frames import write_frames

#: Default size budget of a parameter player's HTML (bytes).
MAX_BYTES = 300_000
MODES = ("loop", "once", "reflect")


class Player:
    """HTML of a player; displays itself in a notebook (``_repr_html_``).

    Attributes
    ----------
    html : str
        The self-contained HTML fragment.
    labels : list of str
        One label per frame (e.g. ``"dt = 0.5 s"``).
    captions : list of str
        One caption per frame (e.g. the verdict), possibly empty strings.
    nbytes : int
        Size of :attr:`html` in bytes (UTF-8).
    """

    def __init__(self, html_text: str, labels: list[str], captions: list[str], kind: str):
        self.html = html_text
        self.labels = labels
        self.captions = captions
        self.kind = kind

    @property
    def nbytes(self) -> int:
        return len(self.html.encode("utf-8"))

    def _repr_html_(self) -> str:
        return self.html

    def __repr__(self) -> str:  # deterministic: nbval compares text/plain
        span = f"{self.labels[0]} … {self.labels[-1]}" if len(self.labels) > 1 else self.labels[0]
        return f"<{self.kind} player: {len(self.labels)} frames, {span}>"

    def save(self, path) -> None:
        """Write a standalone HTML page holding the player (UTF-8)."""
        from pathlib import Path

        Path(path).write_text(f"<!DOCTYPE html>\n<meta charset='utf-8'>\n{self.html}\n",
                              encoding="utf-8")


def encode_png(fig, dpi: float | None = None, colors: int = 256) -> bytes:
    """PNG bytes of ``fig`` at ``dpi`` (default: the figure's), reduced to a ``colors``-entry
    palette (plots have few colours: frames shrink 2-4x and look the same)."""
    _check_colors(colors)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi or fig.dpi, metadata={"Software": None},
                pil_kwargs={"compress_level": 1 if colors else 6})  # if decoded at once: fast
    if not colors:
        return buf.getvalue()
    from PIL import Image

    return _palette_png(Image.open(io.BytesIO(buf.getvalue())).convert("RGB"), colors)


def rgba_png(rgba, colors: int = 256) -> bytes:
    """PNG bytes of a drawn canvas's pixels ``rgba`` (``height × width × 4``, ``uint8``),
    reduced to a ``colors``-entry palette as :func:`encode_png` does (0: RGBA as is)."""
    from PIL import Image

    _check_colors(colors)
    img = Image.fromarray(np.array(rgba, dtype=np.uint8, copy=True), "RGBA")
    if not colors:
        out = io.BytesIO()
        img.save(out, format="PNG", compress_level=6)
        return out.getvalue()
    return _palette_png(img.convert("RGB"), colors)


def _check_colors(colors: int) -> None:
    if colors and not 2 <= colors <= 256:
        raise ValueError(f"colors must be 0 (no palette) or 2..256, got {colors!r}")


def _palette_png(img, colors: int) -> bytes:
    from PIL import Image

    out = io.BytesIO()
    img.quantize(colors=colors, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE).save(
        out, format="PNG", optimize=True)
    return out.getvalue()


def _png_size(png: bytes) -> tuple[int, int]:
    # width and height are the first fields of the IHDR chunk (big-endian uint32)
    return int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")


def frames_html(pngs: Sequence[bytes], labels: Sequence[str], captions: Sequence[str] | None = None,
                *, kind: str = "animation", interval: float = 100.0, mode: str = "loop",
                title: str = "", alt: str = "") -> str:
    """The player's HTML for PNG ``pngs`` (one per frame, all the same size).

    Parameters
    ----------
    pngs : sequence of bytes
        PNG images, at least one.
    labels : sequence of str
        Text shown beside the slider for each frame (same length as ``pngs``).
    captions : sequence of str, optional
        Text shown under the image for each frame (e.g. a verdict).
    kind : {"animation", "parameter"}
        ``"animation"`` adds play/pause and step buttons; ``"parameter"`` has step buttons
        and the slider only.
    interval : float
        Time between frames when playing (ms), > 0.
    mode : {"loop", "once", "reflect"}
        What playing does at the last frame.
    title, alt : str
        A heading above the image, and the image's alternative text.
    """
    n = len(pngs)
    if n == 0:
        raise ValueError("pngs must hold at least one frame")
    captions = list(captions) if captions is not None else [""] * n
    if len(labels) != n or len(captions) != n:
        raise ValueError(f"labels and captions must have one entry per frame ({n}), "
                         f"got {len(labels)} and {len(captions)}")
    if kind not in ("animation", "parameter"):
        raise ValueError(f"kind must be 'animation' or 'parameter', got {kind!r}")
    if mode not in MODES:
        raise ValueError(f"mode must be one of {MODES}, got {mode!r}")
    if not interval > 0:
        raise ValueError(f"interval must be > 0 (ms), got {interval!r}")
    width, height = _png_size(pngs[0])
    b64 = [base64.b64encode(p).decode("ascii") for p in pngs]
    # The id is a hash of the content: equal inputs give byte-equal HTML.
    uid = "clp-" + hashlib.sha1("".join(b64 + list(labels) + captions).encode()).hexdigest()[:12]
    # The controls are written by the script: where scripts do not run (an untrusted
    # notebook) the reader sees the first frame and the hint, not dead buttons.
    data = json.dumps({"frames": [None, *b64[1:]], "labels": list(labels), "captions": captions,
                       "interval": float(interval), "mode": mode, "kind": kind,
                       "controls": controls_html(kind, n, html.escape(labels[0]), mode)})
    data = data.replace("</", "<\\/")  # no "</script>" inside the script element
    esc = html.escape
    return (
        f'<div class="clp" id="{uid}" data-kind="{kind}" '
        f'style="width:max({width}px,44em);max-width:100%">\n<style>{PLAYER_CSS}</style>\n'
        + (f'<div class="clp-title">{esc(title)}</div>\n' if title else "")
        + f'<img class="clp-img" width="{width}" height="{height}" alt="{esc(alt or title)}" '
        f'src="data:image/png;base64,{b64[0]}">\n'
        f'<div class="clp-caption">{esc(captions[0])}</div>\n'
        '<div class="clp-hint">Run this cell (or trust the notebook) to use the controls.'
        '</div>\n'
        f'<script type="application/json" class="clp-data">{data}</script>\n'
        f'<script>{PLAYER_JS.replace("__UID__", uid)}</script>\n</div>'
    )


def _grabber(colors: int):
    """A matplotlib movie writer that keeps each frame as palette PNG bytes: fed pixels by
    :func:`course_lib.clips.frames.write_frames` (``grab_rgba``), or a figure (``grab_frame``)."""
    from matplotlib.animation import AbstractMovieWriter

    class FrameGrabber(AbstractMovieWriter):
        def setup(self, fig, outfile, dpi=None):
            super().setup(fig, outfile, dpi)
            self.frames: list[bytes] = []

        def grab_frame(self, **savefig_kwargs):
            self.frames.append(encode_png(self.fig, self.dpi, colors))

        def grab_rgba(self, rgba) -> None:
            self.frames.append(rgba_png(rgba, colors))

        def finish(self):
            pass

    return FrameGrabber()


def animation_player(anim, *, mode: str = "loop", dpi: float | None = None, colors: int = 256,
                     close: bool = True) -> Player:
    """A :class:`Player` of every frame of a ``matplotlib.animation.Animation``.

    The frames are drawn as a clip's are (:func:`course_lib.clips.frames.write_frames`):
    when the frame function returns the artists it changes, the still figure is drawn once
    and each frame draws only those on it. The frame interval is the animation's. ``close``
    closes the figure afterwards, so the notebook does not show its last frame a second
    time below the player.
    """
    fig = anim._fig
    grabber = _grabber(colors)
    _draw_frames(anim, grabber, dpi or fig.dpi)
    if close:
        plt.close(fig)
    n = len(grabber.frames)
    labels = [f"frame {k + 1} / {n}" for k in range(n)]
    html_text = frames_html(grabber.frames, labels, kind="animation",
                            interval=getattr(anim, "_interval", 100.0), mode=mode)
    return Player(html_text, labels, [""] * n, "animation")


def _draw_frames(anim, grabber, dpi: float) -> None:
    # A test pass that skips rasterizing (tests/skip_raster_startup.py) swaps in
    # _save_in_full, whose savefig per frame it turns into blank PNGs.
    write_frames(anim, grabber, "unused", dpi=dpi)


def _save_in_full(anim, grabber, dpi: float) -> None:
    # ``save`` asks the canvas to redraw after each frame (``draw_idle``), then the grabber
    # renders the frame again: one render is enough, so the redraw is skipped while saving.
    canvas = anim._fig.canvas
    own = vars(canvas).get("draw_idle")
    canvas.draw_idle = lambda *args, **kwargs: None
    try:
        anim.save("unused", writer=grabber, dpi=dpi)
    finally:
        if own is None:
            del canvas.draw_idle
        else:
            canvas.draw_idle = own


def _default_caption(result) -> str:
    verdict = getattr(result, "verdict", None)
    if isinstance(verdict, str):
        return verdict
    stable = getattr(result, "stable", None)
    if stable is None:
        return ""
    return "stable" if stable else f"UNSTABLE: {getattr(result, 'message', '')}".rstrip(": ")


def parameter_player(compute: Callable, draw: Callable, param: str, values: Sequence,
                     *, fixed: Mapping | None = None, label: str | None = None, fmt: str = "{:.3g}",
                     unit: str = "", caption: Callable | None = None, title: str = "",
                     dpi: float | None = None, colors: int = 64, max_bytes: int = MAX_BYTES) -> Player:
    """Precompute ``draw(compute(**fixed, param=v))`` for each ``v`` in ``values``.

    Parameters
    ----------
    compute : callable
        The live widget's pure function (keyword arguments only).
    draw : callable
        The live widget's drawing function: ``draw(result) -> Figure`` (closed here), or
        a view that redraws one figure in place (faster: its axes are made once).
    param : str
        Name of the keyword argument the slider scrubs.
    values : sequence
        Its values, in slider order (at least one).
    fixed : mapping, optional
        Other keyword arguments for ``compute``.
    label, fmt, unit : str
        The slider reads ``f"{label} = {fmt.format(v)} {unit}"`` (``label`` defaults to
        ``param``).
    caption : callable, optional
        ``caption(result) -> str`` under the picture; default: the result's ``verdict``, or
        "stable" / "UNSTABLE: message" from its ``stable`` and ``message``.
    title : str
        Heading above the picture.
    dpi, colors : float, int
        Resolution of the frames (dots per inch; default the figure's) and palette size
        (fewer colours, smaller frames: line plots look the same with 16).
    max_bytes : int
        Size budget of the HTML: frames are redrawn at lower resolution until it fits.

    Returns
    -------
    Player
    """
    values = list(values)
    if not values:
        raise ValueError("values must hold at least one parameter value")
    if not isinstance(param, str) or not param:
        raise TypeError(f"param must be the name of a keyword argument of compute, got {param!r}")
    fixed = dict(fixed or {})
    if param in fixed:
        raise ValueError(f"param {param!r} is also in fixed; give it in values only")
    results = [compute(**{**fixed, param: v}) for v in values]
    caption = caption or _default_caption
    labels = [f"{label or param} = {fmt.format(v)}{(' ' + unit) if unit else ''}" for v in values]
    captions = [str(caption(r)) for r in results]
    while True:                   # one pass when the frames fit at ``dpi``
        pngs = []
        for r in results:
            fig = draw(r)
            dpi = dpi or fig.dpi
            pngs.append(encode_png(fig, dpi, colors))
            plt.close(fig)
        html_text = frames_html(pngs, labels, captions, kind="parameter", title=title,
                                alt=title or f"{label or param} explorer")
        size = len(html_text.encode("utf-8"))
        if size <= max_bytes:
            return Player(html_text, labels, captions, "parameter")
        if dpi < 30:
            raise ValueError(f"the player needs {size} bytes even at {dpi:.0f} dpi, more than "
                             f"max_bytes = {max_bytes}: use fewer values")
        # A palette PNG of a line plot grows about as dpi^1.3: aim 8 % under the budget
        dpi *= max(0.5, min(0.95, (0.92 * max_bytes / size) ** (1 / 1.3)))

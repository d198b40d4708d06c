"""Drawing an animation's frames for a clip, only what moves when it can.

``Animation.save`` draws the whole figure for every frame (axes, ticks, labels, layout),
most of the time of a clip. :func:`write_frames` draws the same frames with the same
pixels: when the frame function returns the artists it changed (a ``FuncAnimation``
made for blitting, ``blit=True`` or not), the rest of the figure is drawn once at the
clip's resolution and kept as a picture (``copy_from_bbox``); each frame restores it
and draws on it the moving artists and whatever the full drawing puts above them (a
legend over a curve, the artists of another axes that meet the region an artist is
clipped to), in the full drawing's order. The picture is drawn again whenever the frame
function changes something it did not return (matplotlib marks the figure stale: the
moving artists are set ``animated`` while saving, so only other changes do), and every
frame is drawn in full for an animation whose function returns no artists (e.g. one
that clears its axes). It returns how often the whole figure was drawn.

The frames go to a writer with a ``grab_rgba(buffer)`` method
(:class:`course_lib.clips.RGBAFFMpegWriter`, :class:`course_lib.clips.RGBAPillowWriter`).
"""

from __future__ import annotations

import itertools
from contextlib import ExitStack

import matplotlib
import matplotlib.colors
import numpy as np
from matplotlib import animation
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.image import AxesImage


def write_frames(anim: animation.Animation, writer, outfile, *, dpi: float | None = None,
                 frames: int | None = None, progress_callback=None) -> dict:
    """Draw the frames of ``anim`` and hand each to ``writer``; return ``{"frames": n,
    "full_draws": k}``, ``k`` how often the whole figure was drawn (1 for an animation
    whose frame function returns every artist it changes; ``n`` for one that returns none).

    Parameters
    ----------
    anim : matplotlib.animation.Animation
        Its frames are made as ``Animation.save`` makes them (the first frame, or the
        ``init_func``, once before; then each frame of ``new_saved_frame_seq``).
    writer : matplotlib.animation.AbstractMovieWriter
        With a method ``grab_rgba(buffer)`` taking one frame's pixels (``height × width × 4``,
        ``uint8``), e.g. :class:`course_lib.clips.RGBAFFMpegWriter` or ``RGBAPillowWriter``.
    outfile : str or Path
        Passed to ``writer.saving``.
    dpi : float, optional
        Pixels per inch of the frames; default the figure's.
    frames : int, optional
        Only the first ``frames`` frames.
    progress_callback : callable, optional
        Called with no argument after each frame's function ran.
    """
    fig = anim._fig
    dpi = fig.dpi if dpi is None else float(dpi)
    done = {"frames": 0, "full_draws": 0}
    layers = None
    with ExitStack() as stack:
        canvas = fig.canvas
        if type(canvas) is not FigureCanvasAgg:  # a widget's, a GUI's or a bare canvas: draw off screen
            stack.callback(_put_back, fig, canvas, getattr(fig, "_original_dpi", None))
            canvas = FigureCanvasAgg(fig)
        stack.enter_context(writer.saving(fig, str(outfile), dpi))
        # As Animation.save and savefig: no GUI resizing, no starting the animation's timer.
        for name, value in (("_is_saving", True), ("manager", None)):
            stack.callback(setattr, canvas, name, getattr(canvas, name))
            setattr(canvas, name, value)
        _swap(stack, fig, "dpi", writer.dpi)
        _savefig_colours(stack, fig, writer)
        anim._draw_was_started = True
        anim._init_draw()
        seq = anim.new_saved_frame_seq()
        seq = seq if frames is None else itertools.islice(seq, frames)
        size = writer.frame_size[::-1]
        try:
            for data in seq:
                anim._draw_frame(data)
                if progress_callback is not None:
                    progress_callback()
                moving = _returned_artists(getattr(anim, "_drawn_artists", None), fig)
                if layers is None or not layers.blit or fig.stale or layers.ids != frozenset(map(id, moving)):
                    if layers is not None:
                        layers.release()
                    layers = _Layers(canvas, moving)  # draws the figure in full
                    done["full_draws"] += 1
                else:
                    canvas.restore_region(layers.background)
                layers.draw_moving()
                rgba = canvas.buffer_rgba()
                if tuple(rgba.shape[:2]) != tuple(size):
                    raise RuntimeError(f"a frame of {rgba.shape[1]} × {rgba.shape[0]} pixels does not fit "
                                       f"the clip's {size[1]} × {size[0]}")
                writer.grab_rgba(rgba)
                done["frames"] += 1
        finally:
            if layers is not None:
                layers.release()
    return done


def _put_back(fig, canvas, original_dpi) -> None:
    fig.set_canvas(canvas)
    if original_dpi is not None:
        fig._original_dpi = original_dpi


def _swap(stack: ExitStack, obj, name: str, value) -> None:
    """``obj.set_<name>(value)`` until ``stack`` closes (then the old value is set back)."""
    stack.callback(getattr(obj, f"set_{name}"), getattr(obj, f"get_{name}")())
    getattr(obj, f"set_{name}")(value)


def _savefig_colours(stack: ExitStack, fig, writer) -> None:
    """The colours ``Animation.save`` saves with: ``savefig.facecolor`` (``"auto"``: the
    figure's) laid on white for a writer without transparency, and ``savefig.transparent``
    for one with it (then the figure and every axes see-through, as in savefig)."""
    rc = matplotlib.rcParams
    face, edge = rc["savefig.facecolor"], rc["savefig.edgecolor"]
    if not writer._supports_transparency():
        rgba = matplotlib.colors.to_rgba(fig.get_facecolor() if face == "auto" else face)
        face = tuple(rgba[3] * np.asarray(rgba[:3]) + 1 - rgba[3])
    elif rc["savefig.transparent"]:
        face, edge = "none", "none"
        for ax in fig.axes:
            _swap(stack, ax.patch, "facecolor", "none")
            _swap(stack, ax.patch, "edgecolor", "none")
    for name, colour in (("facecolor", face), ("edgecolor", edge)):
        if not (isinstance(colour, str) and colour == "auto"):
            _swap(stack, fig, name, colour)


def _returned_artists(value, fig) -> list:
    """The artists a frame function returned, by zorder; [] if it returned anything else."""
    try:
        items = list(value) if value is not None else []
    except TypeError:
        return []
    if not all(isinstance(a, Artist) and a.figure is fig for a in items):
        return []
    return sorted({id(a): a for a in items}.values(), key=lambda a: a.get_zorder())


class _Layers:
    """A figure drawn once without its moving artists (and what the full drawing puts over
    them), kept as a picture, and those artists, drawn on it at each frame. With no moving
    artists, or one nested where its place in the drawing is not known, the figure is
    drawn in full (``blit`` False)."""

    def __init__(self, canvas: FigureCanvasAgg, moving: list):
        fig = canvas.figure
        self.canvas, self.ids = canvas, frozenset(map(id, moving))
        self.redrawn = _redrawn(fig, moving, canvas.get_renderer()) if moving else None
        self.blit = self.redrawn is not None
        # animated: their changes do not mark the figure stale (only other changes do)
        # animated: left out of the full drawing (when not saving), and their changes do not
        # mark the figure stale (only other changes do). Images are hidden as well: matplotlib
        # before 3.10 draws animated images anyway.
        self.flags = [(a, a.get_animated(), a.get_visible()) for a in self.redrawn or ()]
        for a, _, _ in self.flags:
            a.set_animated(True)
            if isinstance(a, AxesImage):
                a.set_visible(False)
        canvas._is_saving = False  # a drawing that leaves the animated artists out
        try:
            with canvas.callbacks.blocked(signal="draw_event"):  # e.g. the animation's own start
                canvas.draw()
        finally:
            canvas._is_saving = True
        for a, _, shown in self.flags:
            a.set_visible(shown)
        self.background = canvas.copy_from_bbox(fig.bbox) if self.blit else None

    def draw_moving(self) -> None:
        renderer = self.canvas.get_renderer()
        for a in self.redrawn or ():
            a.draw(renderer)
        # Drawing may mark the figure stale (a tick's change reaches its axes directly); the
        # picture is current now, so only the next frame function's changes count.
        self.canvas.figure.stale = False

    def release(self) -> None:
        for a, animated, _ in self.flags:
            a.set_animated(animated)


def _children(container, fig) -> list:
    """What ``container`` (the figure or an Axes) draws, in the order it draws them."""
    kids = [a for a in container.get_children() if a is not container.patch]
    if container is fig:
        return sorted(kids, key=lambda a: a.get_zorder())
    framed = container.axison and container.get_frame_on()
    dropped = set() if framed else set(map(id, container.spines.values()))
    if not container.axison:
        dropped |= {id(container.xaxis), id(container.yaxis)}
    kids = sorted((a for a in kids if id(a) not in dropped), key=lambda a: a.get_zorder())
    return [container.patch, *kids] if framed else kids


def _redrawn(fig, moving: list, renderer) -> list | None:
    """The artists drawn at every frame, in the full drawing's order: the moving ones and
    every later one that may paint over one of them or over another one drawn at every
    frame (all later ones of the same container, the figure or a plain Axes; elsewhere,
    those whose extent meets theirs; a moving artist reaches its clip box, else the whole
    figure). None if a moving artist is not a child of the figure or of a plain Axes."""
    order = []
    for item in _children(fig, fig):
        if isinstance(item, Axes) and type(item).draw is Axes.draw:
            order += [(a, item) for a in _children(item, fig)]
        else:
            order.append((item, fig))
    place = {id(a): k for k, (a, _) in enumerate(order)}
    if not all(id(a) in place for a in moving):
        return None
    ids = {id(a) for a in moving}
    redrawn, reach = [], []  # reach: (container, display box) of each artist redrawn so far
    for artist, box in order[min(place[i] for i in ids):]:
        if id(artist) in ids:
            clip = artist.get_clip_box() if artist.get_clip_on() else None
            area = fig.bbox if clip is None else clip
        elif any(box is b for b, _ in reach):
            area = _extent(artist, renderer, fig)
        else:
            area = _extent(artist, renderer, fig)
            if area is None or not any(area.overlaps(r) for _, r in reach):
                continue
        if area is not None:
            reach.append((box, area))
        redrawn.append(artist)
    return redrawn


def _extent(artist, renderer, fig):
    """Where ``artist`` may paint (display box, 2 pixels wider), the figure's box when that is
    not known, None when it paints nothing (hidden, or an empty text)."""
    try:
        extent = artist.get_tightbbox(renderer)
    except Exception:  # an artist that cannot say where it draws may draw anywhere
        return fig.bbox
    if extent is None or not np.isfinite(extent.extents).all():
        return None
    return extent.padded(2)

"""Clips: any of the course's animations saved as an MP4 (H.264) or GIF file.

:func:`save_clip` takes a ``matplotlib.animation.Animation`` (every animation of the
notebooks, and a project's own ``FuncAnimation``) and writes it by the file's extension:

- ``.mp4``: H.264 (``libx264``, pixel format ``yuv420p``, which every browser and
  player reads; matplotlib rounds the frame to even pixel sizes for it), encoded by the
  ffmpeg binary that the ``imageio-ffmpeg`` wheel ships, so no system ffmpeg is needed;
- ``.gif``: written by Pillow (every frame, its duration 1/fps).

Frames are drawn by :func:`.frames.write_frames`, which draws only what moves when the
frame function returns the artists it changed (see :mod:`course_lib.clips.frames`); the
frames have the same pixels as ``Animation.save``'s, which draws the whole figure for
each frame (and then a layout pass and, on a pyplot canvas, a draw for the screen).
The figure's layout engine (e.g. constrained layout) runs once, before the first frame.

A tqdm bar counts the frames as they are drawn. :func:`clip_info` reads a written file
back: frames, pixel size, duration.

Imports: matplotlib (its animation writers, the Agg canvas), tqdm, imageio-ffmpeg and
Pillow when used.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
from matplotlib import animation

from ..plotting import freeze_layout
from .frames import write_frames

__all__ = ["FORMATS", "clip_info", "ffmpeg_exe", "frame_count", "save_clip", "write_frames"]

#: What each extension is written as.
FORMATS = {".mp4": "H.264 video (libx264, yuv420p)", ".gif": "GIF (Pillow)"}


def ffmpeg_exe() -> str:
    """The ffmpeg binary of the ``imageio-ffmpeg`` wheel, set as matplotlib's ffmpeg."""
    import imageio_ffmpeg

    exe = imageio_ffmpeg.get_ffmpeg_exe()
    matplotlib.rcParams["animation.ffmpeg_path"] = exe
    return exe


def frame_count(anim: animation.Animation) -> int | None:
    """How many frames ``anim`` saves (None if it does not say, e.g. a generator)."""
    count = getattr(anim, "_save_count", None)
    if count is None and getattr(anim, "_framedata", None) is not None:
        try:
            count = len(anim._framedata)
        except TypeError:
            count = None
    return int(count) if count is not None else None


class RGBAFFMpegWriter(animation.FFMpegWriter):
    """matplotlib's ffmpeg pipe, also fed a drawn canvas's RGBA pixels directly."""

    def grab_rgba(self, rgba) -> None:
        """Write one frame: ``rgba`` (bytes-like, ``height × width × 4``, ``uint8``)."""
        self._proc.stdin.write(rgba)


class RGBAPillowWriter(animation.PillowWriter):
    """matplotlib's GIF writer, also fed a drawn canvas's RGBA pixels directly."""

    def grab_rgba(self, rgba) -> None:
        """Keep one frame, as :meth:`grab_frame` keeps a saved one (RGB if opaque)."""
        from PIL import Image

        im = Image.frombuffer("RGBA", self.frame_size, bytes(rgba), "raw", "RGBA", 0, 1)
        self._frames.append(im if im.getextrema()[3][0] < 255 else im.convert("RGB"))


def save_clip(anim: animation.Animation, path, *, fps: float | None = None, dpi: float | None = None,
              height: int | None = None, frames: int | None = None, crf: int = 20,
              preset: str = "veryfast", progress: bool = True) -> Path:
    """Save ``anim`` as ``path`` (``.mp4`` or ``.gif``) and return the path.

    Parameters
    ----------
    anim : matplotlib.animation.Animation
        The animation (drawn by :func:`write_frames`: only what moves, if it can).
    path : str or Path
        The file to write; its extension chooses the format (:data:`FORMATS`).
    fps : float, optional
        Frames per second of the clip; default: the animation's own interval
        (``1000 / interval``). A clip of ``n`` frames lasts ``n / fps`` seconds.
    dpi : float, optional
        Pixels per inch of the frames (default: the figure's, not ``savefig.dpi`` as
        ``Animation.save`` takes). Not with ``height``.
    height : int, optional
        Frame height in pixels, e.g. 720 (the dpi is chosen for it; the width follows
        the figure's aspect).
    frames : int, optional
        Write only the first ``frames`` frames (a quick preview); default all.
    crf, preset : int, str
        H.264 quality (0-51, lower is better; 20 is visually clean) and x264's speed preset
        (``veryfast``: plots compress well, and encoding stays a small part of the time).
    progress : bool
        Show a tqdm bar over the frames.
    """
    if not isinstance(anim, animation.Animation):
        raise TypeError(f"anim must be a matplotlib.animation.Animation, got {type(anim).__name__}")
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FORMATS:
        raise ValueError(f"path: unknown clip format {path.suffix!r}; valid choices: {sorted(FORMATS)}")
    if fps is None:
        fps = 1000.0 / float(getattr(anim, "_interval", 200) or 200)
    if not (isinstance(fps, (int, float)) and fps > 0):
        raise ValueError(f"fps must be a positive number of frames per second, got {fps!r}")
    if dpi is not None and height is not None:
        raise ValueError("give dpi or height, not both")
    if height is not None:
        if not (isinstance(height, int) and height >= 16):
            raise ValueError(f"height must be a whole number of pixels >= 16, got {height!r}")
        dpi = height / anim._fig.get_figheight()
    if dpi is not None and not dpi > 0:
        raise ValueError(f"dpi must be > 0, got {dpi!r}")
    if frames is not None and not (isinstance(frames, int) and not isinstance(frames, bool) and frames >= 1):
        raise ValueError(f"frames must be a whole number of frames >= 1, got {frames!r}")
    if suffix == ".mp4":
        ffmpeg_exe()
        x264 = ["-vcodec", "libx264", "-preset", preset, "-crf", str(crf)]  # after matplotlib's "h264"
        writer = RGBAFFMpegWriter(fps=fps, codec="h264", extra_args=x264)
    else:
        writer = RGBAPillowWriter(fps=fps)
    path.parent.mkdir(parents=True, exist_ok=True)
    from tqdm import tqdm

    fig = anim._fig
    engine = fig.get_layout_engine()
    # Lay the figure out before the first frame instead of at every frame drawn in full;
    # the frames then also keep still axes. (Not canvas.draw(): the bare canvas of a
    # figure closed by pyplot draws nothing, and so did not lay it out.)
    freeze_layout(fig)
    total = frame_count(anim)
    if frames is not None:
        total = frames if total is None else min(total, frames)
    try:
        with tqdm(total=total, unit="frame", desc=path.name, disable=not progress) as bar:
            write_frames(anim, writer, path, dpi=dpi, frames=frames, progress_callback=lambda: bar.update(1))
    finally:
        if engine is not None and fig.get_layout_engine() is not engine:
            fig.set_layout_engine(engine)
    return path


def clip_info(path) -> dict:
    """What a written clip holds: ``frames``, ``width`` and ``height`` (pixels), ``seconds``
    (duration), ``fps`` and, for MP4, ``codec`` and ``pix_fmt`` as ffmpeg reads them."""
    path = Path(path)
    if path.suffix.lower() == ".gif":
        from PIL import Image

        with Image.open(path) as im:
            durations = []
            for k in range(im.n_frames):
                im.seek(k)
                durations.append(im.info.get("duration", 0))
            seconds = sum(durations) / 1000.0
            return {"frames": im.n_frames, "width": im.width, "height": im.height, "seconds": seconds,
                    "fps": im.n_frames / seconds if seconds else None, "codec": "gif", "pix_fmt": "pal8"}
    import imageio_ffmpeg

    frames, seconds = imageio_ffmpeg.count_frames_and_secs(str(path))
    reader = imageio_ffmpeg.read_frames(str(path))
    try:
        meta = next(reader)
    finally:
        reader.close()
    width, height = meta["size"]
    return {"frames": frames, "width": width, "height": height, "seconds": seconds, "fps": meta.get("fps"),
            "codec": meta.get("codec", ""), "pix_fmt": meta.get("pix_fmt", "")}

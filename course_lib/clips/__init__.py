"""Clips: any of the course's animations saved as an MP4 (H.264) or GIF file.

:func:`save_clip` takes a ``matplotlib.animation.Animation`` (every animation of the
notebooks, and a project's own ``FuncAnimation``) and writes it by the file's extension:

- ``.mp4``: H.264 (``libx264``, pixel format ``yuv420p``, which every browser and
  player reads; matplotlib rounds the frame to even pixel sizes for it), encoded by the
  ffmpeg binary that the ``imageio-ffmpeg`` wheel ships, so no system ffmpeg is needed;
- ``.gif``: written by Pillow (every frame, its duration 1/fps).

A tqdm bar counts the frames as they are drawn (``Animation.save``'s progress callback).
:func:`clip_info` reads a written file back: frames, pixel size, duration.

Imports: matplotlib (its animation writers), tqdm, imageio-ffmpeg and Pillow when used.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import matplotlib
from matplotlib import animation

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


def save_clip(anim: animation.Animation, path, *, fps: float | None = None, dpi: float | None = None,
              height: int | None = None, frames: int | None = None, crf: int = 20,
              preset: str = "veryfast", progress: bool = True) -> Path:
    """Save ``anim`` as ``path`` (``.mp4`` or ``.gif``) and return the path.

    Parameters
    ----------
    anim : matplotlib.animation.Animation
        The animation (its figure is drawn once per frame).
    path : str or Path
        The file to write; its extension chooses the format (:data:`FORMATS`).
    fps : float, optional
        Frames per second of the clip; default: the animation's own interval
        (``1000 / interval``). A clip of ``n`` frames lasts ``n / fps`` seconds.
    dpi : float, optional
        Pixels per inch of the frames (default: the figure's). Not with ``height``.
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
        writer = animation.FFMpegWriter(fps=fps, codec="h264", extra_args=x264)
    else:
        writer = animation.PillowWriter(fps=fps)
    path.parent.mkdir(parents=True, exist_ok=True)
    from tqdm import tqdm

    fig = anim._fig
    engine = fig.get_layout_engine()
    if engine is not None and type(engine).__name__ != "PlaceHolderLayoutEngine":
        # Lay the figure out once, at the first frame, instead of at every frame (a third of
        # the time of a two-panel clip); the frames then also keep still axes.
        fig.canvas.draw()
        fig.set_layout_engine("none")
    total = frame_count(anim)
    if frames is not None:
        # Animation.save draws whatever new_saved_frame_seq yields: the first `frames` of it
        every = anim.new_saved_frame_seq
        anim.new_saved_frame_seq = lambda: itertools.islice(every(), frames)
        total = frames if total is None else min(total, frames)
    try:
        with tqdm(total=total, unit="frame", desc=path.name, disable=not progress) as bar:
            anim.save(str(path), writer=writer, dpi=dpi, progress_callback=lambda i, n: bar.update(1))
    finally:
        if frames is not None:
            del anim.new_saved_frame_seq
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

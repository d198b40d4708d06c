"""Writing a clip: a 10-second 720p MP4 of a course animation (target: at most 30 s).

The animation is notebook 07's showcase (a mass on a spring beside its stretch against
time, 16:9), built with 300 frames and saved at 30 frames per second and 1280 × 720
pixels by :func:`course_lib.clips.save_clip` (H.264 by the ffmpeg of imageio-ffmpeg).
Like the other rows, the time is CPU time: this process's (building, drawing) plus
ffmpeg's (encoding), which on two idle cores runs beside the drawing, so their sum bounds
what a student waits; the wall clock of this run is in the note (on a shared machine it
counts other processes too).
"""

from __future__ import annotations

import resource
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

from benchmarks.timing import Row


def _cpu() -> float:
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def run(quick: bool = False) -> list[Row]:
    from course_lib.clips import clip_info, save_clip
    from course_lib.lessons.showcase_scenes import nb07

    frames, height = (6, 144) if quick else (300, 720)
    with tempfile.TemporaryDirectory() as tmp:
        cpu, start = _cpu(), time.perf_counter()
        path = save_clip(nb07(frames=frames), Path(tmp) / "clip.mp4", fps=30, height=height, progress=False)
        wall, cpu = time.perf_counter() - start, _cpu() - cpu
        info = clip_info(path)
    shape = f"{info['width']}×{info['height']}, {info['frames']} frames, {info['seconds']:.1f} s"
    case = f"clip: {frames / 30:g}-second {height}p MP4 of a course animation (notebook 07), written"
    return [Row(case, cpu, "≤ 30 s", cpu <= 30.0, ratio=shape,
                note=f"CPU of this process and ffmpeg, {cpu / frames * 1e3:.0f} ms/frame; wall {wall:.1f} s")]

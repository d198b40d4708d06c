"""Clips (MP4 and GIF) of the course's animations, read back from the written files.

Every file is read back: its frame count, its pixel size and its duration must be those
asked for. MP4 files are read with the ffmpeg binary of ``imageio-ffmpeg`` (no system
ffmpeg: the tests run with a PATH that has none), GIF files with Pillow.
"""

import shutil

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt
from matplotlib.animation import FuncAnimation

from course_lib.clips import clip_info, frame_count, save_clip
from course_lib.lessons import showcase


@pytest.fixture
def no_system_ffmpeg(monkeypatch, tmp_path):
    monkeypatch.setenv("PATH", str(tmp_path / "empty-bin"))
    assert shutil.which("ffmpeg") is None


def wave(frames=12, size=(3.2, 2.4), dpi=50, interval=100):
    fig = plt.figure(figsize=size, dpi=dpi)
    plt.close(fig)
    ax = fig.add_subplot()
    x = np.linspace(0, 2 * np.pi, 100)
    (line,) = ax.plot(x, np.sin(x))
    return FuncAnimation(fig, lambda k: line.set_ydata(np.sin(x + 0.3 * k)), frames=frames, interval=interval)


def test_mp4_is_h264_yuv420p_with_the_frames_size_and_duration_asked(tmp_path, no_system_ffmpeg):
    path = save_clip(wave(12), tmp_path / "wave.mp4", fps=8, progress=False)
    info = clip_info(path)
    assert (info["frames"], info["width"], info["height"]) == (12, 160, 120)
    assert info["seconds"] == pytest.approx(12 / 8, abs=1 / 8)  # to within one frame
    assert info["codec"] == "h264" and info["pix_fmt"].startswith("yuv420p")
    assert b"x264 - core" in path.read_bytes()  # encoded by libx264 (its settings are in the stream)


def test_height_sets_the_pixel_size_and_odd_sizes_become_even(tmp_path, no_system_ffmpeg):
    info = clip_info(save_clip(wave(4, size=(6.4, 3.6)), tmp_path / "hd.mp4", height=720, progress=False))
    assert (info["width"], info["height"], info["frames"]) == (1280, 720, 4)
    info = clip_info(save_clip(wave(3, size=(3.01, 2.01), dpi=100), tmp_path / "odd.mp4", progress=False))
    assert info["width"] % 2 == 0 and info["height"] % 2 == 0  # yuv420p needs even sizes


def test_gif_by_pillow_with_the_frames_size_and_duration_asked(tmp_path, no_system_ffmpeg):
    anim = wave(10, interval=125)
    info = clip_info(save_clip(anim, tmp_path / "wave.gif", progress=False))  # fps from the interval
    assert (info["frames"], info["width"], info["height"]) == (10, 160, 120)
    assert info["seconds"] == pytest.approx(10 * 0.125, abs=0.01 * 10)  # GIF durations are in 10 ms


def test_the_progress_bar_counts_frames(tmp_path, capsys):
    save_clip(wave(7), tmp_path / "bar.gif", fps=10)
    assert "7/7" in capsys.readouterr().err
    assert frame_count(wave(7)) == 7


@pytest.mark.parametrize("call,message", [
    (lambda a, p: save_clip(a, p / "x.avi"), "valid choices"),
    (lambda a, p: save_clip(a, p / "x.mp4", fps=0), "fps must be a positive"),
    (lambda a, p: save_clip(a, p / "x.mp4", dpi=50, height=100), "not both"),
    (lambda a, p: save_clip(a, p / "x.mp4", height=10.5), "whole number of pixels"),
    (lambda a, p: save_clip("not an animation", p / "x.mp4"), "matplotlib.animation.Animation"),
    (lambda a, p: save_clip(a, p / "x.mp4", frames=0), "frames must be a whole number"),
    (lambda a, p: save_clip(a, p / "x.mp4", frames=2.0), "frames must be a whole number"),
])
def test_bad_requests_name_the_argument(tmp_path, call, message):
    with pytest.raises((ValueError, TypeError), match=message):
        call(wave(2), tmp_path)


def test_frames_writes_the_first_frames_only_and_leaves_the_animation_whole(tmp_path, no_system_ffmpeg):
    anim = wave(12)
    drawn = []
    anim._func = (lambda f, draw=anim._func: (drawn.append(f), draw(f))[1])
    info = clip_info(save_clip(anim, tmp_path / "first.mp4", fps=8, frames=5, progress=False))
    assert info["frames"] == 5 and info["seconds"] == pytest.approx(5 / 8, abs=1 / 8)
    assert drawn[-5:] == [0, 1, 2, 3, 4]
    assert clip_info(save_clip(anim, tmp_path / "all.gif", fps=8, progress=False))["frames"] == 12
    assert clip_info(save_clip(wave(3), tmp_path / "few.gif", frames=10, progress=False))["frames"] == 3


def test_registry_has_every_notebook_and_finds_a_new_lessons_showcase(tmp_path, monkeypatch):
    table = showcase.showcases()
    assert {f"{n:02d}" for n in range(1, 15)} <= set(table)
    assert [table[n].name for n in ("12", "13", "14")] == [
        "12_constraints_and_large_steps", "13_sph_liquids", "14_rigid_bodies"]
    assert table["08"].name == "08_hair_chains"
    (tmp_path / "nb99_demo_topic.py").write_text("def showcase_animation():\n    return None\n")
    (tmp_path / "nb98_no_showcase.py").write_text("def other():\n    pass\n")
    (tmp_path / "nb97_broken.py").write_text("def showcase_animation(:\n")
    monkeypatch.setattr(showcase, "HERE", tmp_path)
    found = showcase.showcases()
    assert found["99"].function == "showcase_animation" and found["99"].name == "99_demo_topic"
    assert found["99"].module.endswith(".nb99_demo_topic") and "98" not in found and "97" not in found


def test_select_by_number_or_name():
    assert [s.number for s in showcase.select(["8", "03_stability", "11"])] == ["08", "03", "11"]
    with pytest.raises(ValueError, match="valid choices"):
        showcase.select(["77"])


@pytest.mark.parametrize("number", [f"{n:02d}" for n in range(1, 12)])
def test_each_notebooks_showcase_becomes_a_clip(number, tmp_path, no_system_ffmpeg):
    """Built with 3 frames and written small: the builder runs and the clip reads back."""
    entry = showcase.showcases()[number]
    if entry.module != "course_lib.lessons.showcase_scenes":
        pytest.skip(f"notebook {number}'s own lesson module provides its showcase (tested there)")
    anim = entry.build(frames=3)
    fig = anim._fig
    info = clip_info(save_clip(anim, tmp_path / f"{entry.name}.mp4", dpi=40, progress=False))
    assert info["frames"] == 3
    width, height = fig.get_size_inches() * 40
    assert abs(info["width"] - width) <= 2 and abs(info["height"] - height) <= 2
    assert info["seconds"] == pytest.approx(3 * anim._interval / 1000, abs=anim._interval / 1000)


#: Small builds of the showcases that live in their own lessons (notebooks 12-14): the
#: options of each builder that keep the run short (12's drape has none: the test hands it
#: a 4-frame drape, as tests/test_nb12_constraints.py does, instead of the full 3.4 s run;
#: only 3 frames are written).
SMALL = {"12": {}, "13": {"n_particles": 200, "seconds": 0.1, "fps": 30.0, "simulated": 0.05},
         "14": {"t_end": 0.0015}}


@pytest.mark.parametrize("number", sorted(SMALL))
def test_the_project_starters_showcases_become_clips(number, tmp_path, no_system_ffmpeg, monkeypatch):
    """Notebooks 12-14's own showcases, built small and written 3 frames at 40 dpi: the
    clip reads back with the frames, size and duration asked for."""
    entry = showcase.showcases()[number]
    assert entry.module.startswith(f"course_lib.lessons.nb{number}_")
    if number == "12":
        from course_lib.lessons import nb12_constraints

        small = nb12_constraints.drape(frames=4)
        monkeypatch.setattr(nb12_constraints, "drape", lambda frames, fps: small)
    anim = entry.build(**SMALL[number])
    width, height = anim._fig.get_size_inches() * 40
    info = clip_info(save_clip(anim, tmp_path / f"{entry.name}.mp4", dpi=40, frames=3, progress=False))
    assert info["frames"] == 3 and info["codec"] == "h264"
    assert abs(info["width"] - width) <= 2 and abs(info["height"] - height) <= 2
    assert info["seconds"] == pytest.approx(3 * anim._interval / 1000, abs=anim._interval / 1000)
    assert width / height == pytest.approx(16 / 9, rel=0.01)     # every project clip is 16:9


def test_clips_command_line(tmp_path, capsys, monkeypatch):
    from course_lib.instructor.__main__ import main

    assert main(["clips", "--list"]) == 0
    assert "08_hair_chains" in capsys.readouterr().out
    # The command builds each showcase with its builder's defaults (03: 40 frames at 10 per
    # second, 4 s; the full build is 5 s of drawing, and each builder is tested above): the
    # builder is handed 4 frames here, and the options the command passed are recorded.
    asked, build = [], showcase.Showcase.build
    monkeypatch.setattr(showcase.Showcase, "build",
                        lambda self, **options: asked.append(options) or build(self, frames=4, **options))
    assert main(["clips", str(tmp_path), "--only", "03", "--format", "gif", "--dpi", "30",
                 "--no-progress"]) == 0
    assert asked == [{}]                             # the builder's own defaults
    info = clip_info(tmp_path / "03_stability.gif")  # Pillow merges frames that repeat the last one
    assert info["frames"] <= 4 and info["seconds"] == pytest.approx(4 / 10)
    assert (info["width"], info["height"]) == (192, 108)  # --dpi 30 reached the writer
    assert main(["clips", str(tmp_path), "--only", "nothing"]) == 2
    assert "no showcase for 'nothing'" in capsys.readouterr().err

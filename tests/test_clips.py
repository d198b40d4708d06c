"""Clips (MP4 and GIF) of the course's animations, read back from the written files.

Every file is read back: its frame count, its pixel size and its duration must be those
asked for. MP4 files are read with the ffmpeg binary of ``imageio-ffmpeg`` (no system
ffmpeg: the tests run with a PATH that has none), GIF files with Pillow.

The frames drawn only where they move (:func:`course_lib.clips.write_frames`) are
compared, pixel by pixel, with the frames ``Animation.save`` draws in full, on figures
built to catch each way blitting goes wrong (a legend or another axes over a moving
artist, a change the frame function does not return, an image, a cleared axes), and the
number of full drawings says the fast path was taken (not a wall-clock time).
"""

import io
import shutil

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt
from matplotlib.animation import AbstractMovieWriter, FuncAnimation
from matplotlib.backends.backend_agg import FigureCanvasAgg

from course_lib.clips import clip_info, frame_count, save_clip, write_frames
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


@pytest.fixture
def full_draws(monkeypatch):
    """How often a figure is drawn in full on an Agg canvas (a list, one entry a drawing).
    Only drawings that finish count: a layout pass breaks off its drawing once it has a
    renderer."""
    drawn, draw = [], FigureCanvasAgg.draw
    monkeypatch.setattr(FigureCanvasAgg, "draw", lambda self: (draw(self), drawn.append(1))[0])
    return drawn


@pytest.mark.parametrize("number", [f"{n:02d}" for n in range(1, 12)])
def test_each_notebooks_showcase_becomes_a_clip(number, tmp_path, no_system_ffmpeg, full_draws):
    """Built with 3 frames and written small: the builder runs and the clip reads back;
    every showcase but notebook 01's (which clears its axes) draws its figure once."""
    entry = showcase.showcases()[number]
    if entry.module != "course_lib.lessons.showcase_scenes":
        pytest.skip(f"notebook {number}'s own lesson module provides its showcase (tested there)")
    anim = entry.build(frames=3)
    fig = anim._fig
    full_draws.clear()  # only the clip's drawings count
    info = clip_info(save_clip(anim, tmp_path / f"{entry.name}.mp4", dpi=40, progress=False))
    assert info["frames"] == 3
    assert len(full_draws) == (3 if number == "01" else 1)
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
def test_the_project_starters_showcases_become_clips(number, tmp_path, no_system_ffmpeg, monkeypatch,
                                                    full_draws):
    """Notebooks 12-14's own showcases, built small and written 3 frames at 40 dpi: the
    clip reads back with the frames, size and duration asked for; 12's and 13's draw
    their figure once, 14's (whose frame function replaces its magnets) at every frame."""
    entry = showcase.showcases()[number]
    assert entry.module.startswith(f"course_lib.lessons.nb{number}_")
    if number == "12":
        from course_lib.lessons import nb12_constraints

        small = nb12_constraints.drape(frames=4)
        monkeypatch.setattr(nb12_constraints, "drape", lambda frames, fps: small)
    anim = entry.build(**SMALL[number])
    full_draws.clear()  # only the clip's drawings count
    width, height = anim._fig.get_size_inches() * 40
    info = clip_info(save_clip(anim, tmp_path / f"{entry.name}.mp4", dpi=40, frames=3, progress=False))
    assert info["frames"] == 3 and info["codec"] == "h264"
    assert abs(info["width"] - width) <= 2 and abs(info["height"] - height) <= 2
    assert info["seconds"] == pytest.approx(3 * anim._interval / 1000, abs=anim._interval / 1000)
    assert width / height == pytest.approx(16 / 9, rel=0.01)     # every project clip is 16:9
    assert len(full_draws) == (3 if number == "14" else 1)


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


class Frames(AbstractMovieWriter):
    """Keeps the frames in memory: as ``Animation.save`` draws them (``grab_frame``: the
    whole figure by savefig) or as :func:`write_frames` hands them over (``grab_rgba``)."""

    transparency = False

    def _supports_transparency(self):
        return self.transparency

    def setup(self, fig, outfile, dpi=None):
        super().setup(fig, outfile, dpi)
        self.frames = []

    def grab_frame(self, **savefig_kwargs):
        buf = io.BytesIO()
        self.fig.savefig(buf, format="rgba", dpi=self.dpi, **savefig_kwargs)
        width, height = self.frame_size
        self.frames.append(np.frombuffer(buf.getvalue(), np.uint8).reshape(height, width, 4))

    def grab_rgba(self, rgba):
        self.frames.append(np.array(rgba))

    def finish(self):
        pass


def both_ways(anim, dpi=40, transparency=False):
    """The frames of ``anim`` drawn in full by ``Animation.save`` and by :func:`write_frames`
    (laid out once first, as :func:`save_clip` does), and what ``write_frames`` counted.
    The frame functions below depend on the frame number only, so one animation serves."""
    fig = anim._fig
    if fig.get_layout_engine() is not None:
        fig.draw_without_rendering()
        fig.set_layout_engine("none")
    full, fast = Frames(fps=10), Frames(fps=10)
    full.transparency = fast.transparency = transparency
    anim.save("unused.mp4", writer=full, dpi=dpi)
    counted = write_frames(anim, fast, "unused.mp4", dpi=dpi)
    assert len(full.frames) == len(fast.frames) == counted["frames"] > 0
    for k, (a, b) in enumerate(zip(full.frames, fast.frames, strict=True)):
        assert a.shape == b.shape
        # Agg draws the same artists in the same order onto the same pixels: equal up to
        # rounding of the blending; a missing artist or a wrong order differs by far more
        differ = np.abs(a.astype(int) - b.astype(int)).max(axis=-1) > 2
        assert not differ.any(), f"frame {k}: {differ.sum()} pixels differ from the full drawing"
    return counted


def _figure(size=(3.2, 2.4)):
    fig = plt.figure(figsize=size, dpi=50)
    plt.close(fig)  # a bare canvas, as the notebooks' clips have
    return fig


def moving_line_under(kind, frames=5):
    """A sine wave that moves, returned by the frame function, under ``kind``: a framed
    legend, a twin axes' thick line, a figure text (returned), an image (returned); or
    (``"unreturned"``) over the axes' background, which the function changes without
    returning it."""
    fig = _figure()
    ax = fig.add_subplot()
    x = np.linspace(0, 2 * np.pi, 60)
    (line,) = ax.plot(x, np.sin(x), lw=3, label="wave")
    ax.plot(x, np.cos(x), "k--", label="still")
    ax.set(xlim=(0, 2 * np.pi), ylim=(-1.2, 1.2))
    moving, also = [line], []
    if kind == "legend":
        ax.legend(loc="center", frameon=True, framealpha=0.9, fontsize=14)
    elif kind == "twin":
        twin = ax.twinx()
        twin.plot(x, 0.3 * x, color="C2", lw=8)  # drawn after the first axes, over its line
    elif kind == "text":
        moving.append(fig.text(0.5, 0.5, "", fontsize=20, ha="center"))
    elif kind == "image":
        image = ax.imshow(np.zeros((4, 4)), extent=(1, 3, -0.5, 0.5), vmin=0, vmax=1, zorder=2.2)
        moving.append(image)

    def draw(k):
        line.set_ydata(np.sin(x + 0.5 * k))
        if kind == "unreturned":  # the background, not returned: the still picture is redrawn
            ax.set_facecolor(str(0.7 + 0.05 * k))
        if kind == "text":
            moving[1].set_text(f"t = {k}")
        if kind == "image":
            image.set_data(np.eye(4) * (k + 1) / frames)
        return [*moving, *also]

    return FuncAnimation(fig, draw, frames=frames)


@pytest.mark.parametrize("kind", ["legend", "twin", "text", "image"])
def test_a_blittable_animation_is_drawn_once_and_its_frames_are_the_full_drawings(kind):
    assert both_ways(moving_line_under(kind)) == {"frames": 5, "full_draws": 1}


def test_a_change_the_frame_function_does_not_return_redraws_the_figure():
    assert both_ways(moving_line_under("unreturned")) == {"frames": 5, "full_draws": 5}


def test_an_animation_that_returns_nothing_or_clears_its_axes_is_drawn_in_full():
    fig = _figure()
    ax = fig.add_subplot()

    def draw(k):
        ax.clear()
        ax.plot([0, 1], [0, k], lw=4)
        ax.set_title(f"frame {k}")

    assert both_ways(FuncAnimation(fig, draw, frames=4)) == {"frames": 4, "full_draws": 4}


def test_blit_true_with_an_init_function_and_a_transparent_gif(monkeypatch):
    monkeypatch.setitem(matplotlib.rcParams, "savefig.transparent", True)
    fig = _figure()
    ax = fig.add_subplot()
    (dot,) = ax.plot([], [], "o", ms=20)
    ax.set(xlim=(0, 4), ylim=(0, 4))
    anim = FuncAnimation(fig, lambda k: (dot.set_data([k], [k]), [dot])[1], frames=4,
                         init_func=lambda: [dot], blit=True)
    assert both_ways(anim, transparency=True) == {"frames": 4, "full_draws": 1}


@pytest.mark.parametrize("number", ["07", "08"])
def test_showcases_drawn_once_have_the_full_drawings_pixels(number):
    """07: two axes and a legend over the moving curve; 08: strands under the axis and
    grid of their axes, which the full drawing puts above them."""
    anim = showcase.showcases()[number].build(frames=3)
    assert both_ways(anim, dpi=30) == {"frames": 3, "full_draws": 1}


def test_the_clip_is_laid_out_and_drawn_at_the_figures_dpi(tmp_path, monkeypatch):
    """A constrained layout runs once before the frames, even on a figure pyplot closed;
    without dpi the frames have the figure's dpi (not savefig.dpi)."""
    monkeypatch.setitem(matplotlib.rcParams, "savefig.dpi", 80)
    fig = plt.figure(figsize=(3.2, 2.4), dpi=50, layout="constrained")
    plt.close(fig)
    ax = fig.add_subplot()
    (line,) = ax.plot([0, 1], [0, 1])
    ax.set_ylabel("a long label", fontsize=20)
    before = ax.get_position().bounds
    info = clip_info(save_clip(FuncAnimation(fig, lambda k: [line], frames=2), tmp_path / "x.gif",
                               progress=False))
    assert (info["width"], info["height"]) == (160, 120)
    assert ax.get_position().bounds != pytest.approx(before, abs=0.01)  # moved by the layout

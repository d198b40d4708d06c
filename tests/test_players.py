"""Kernel-free players: the HTML is offline, deterministic and small; a frame shows before
any script runs; parameter players run the widget's own functions and flip at the limit."""

import base64
import io
import json
import re

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.animation import FuncAnimation
from matplotlib.backends.backend_agg import FigureCanvasAgg
from PIL import Image

from course_lib import players
from course_lib.lessons import kernel_free
from course_lib.plotting import animation_html

matplotlib.use("agg")


def _png(fig) -> bytes:
    return players.encode_png(fig, 40)


@pytest.fixture
def square_anim():
    fig, ax = plt.subplots(figsize=(2, 2), dpi=40)
    (dot,) = ax.plot([0], [0], "o")
    ax.set(xlim=(-1, 1), ylim=(-1, 1))

    def draw(j):
        dot.set_data([np.cos(j)], [np.sin(j)])
        return (dot,)

    return FuncAnimation(fig, draw, frames=5, interval=70)


def test_animation_player_has_every_frame_closes_the_figure_and_needs_no_network(square_anim):
    fig = square_anim._fig
    player = animation_html(square_anim)
    assert not plt.fignum_exists(fig.number)
    html = player._repr_html_()
    assert html.count("iVBORw0KGgo") == 5  # base64 of the PNG signature: one per frame
    assert '"interval": 70.0' in html
    assert "http" not in html and "<link" not in html  # no CDN, no font download
    # the first frame is a plain image with its size, so it shows before any script runs
    img = re.search(r'<img class="clp-img" width="(\d+)" height="(\d+)"[^>]* src="data:image/png',
                    html)
    assert img and (int(img[1]), int(img[2])) == (80, 80)
    # the controls are written by the script (from the JSON data), so that where scripts do
    # not run the reader sees the frame and a hint, not dead buttons
    static, data = html.split('<script type="application/json" class="clp-data">')
    assert "<button" not in static and "Run this cell" in static
    controls = json.loads(data.split("</script>")[0])["controls"]
    for act in ("first", "prev", "play", "next", "last"):
        assert f'data-act="{act}"' in controls
    assert repr(player) == "<animation player: 5 frames, frame 1 / 5 … frame 5 / 5>"


@pytest.fixture
def full_draws(monkeypatch):
    """How often a figure is drawn in full on an Agg canvas (one entry a drawing)."""
    drawn, draw = [], FigureCanvasAgg.draw
    monkeypatch.setattr(FigureCanvasAgg, "draw", lambda self: (draw(self), drawn.append(1))[0])
    return drawn


def _frames(player) -> list[np.ndarray]:
    """The player's frames, decoded to RGB arrays (ints)."""
    b64 = re.findall(r'(?:base64,|")([A-Za-z0-9+/=]{100,})"', player.html)
    return [np.asarray(Image.open(io.BytesIO(base64.b64decode(b))).convert("RGB")).astype(int)
            for b in b64]


def _busy_anim(returns: bool):
    """A laid-out figure with a title, a still curve, a moving line and dots under a framed
    legend and a moving text; the frame function returns what it moves (or nothing)."""
    fig, ax = plt.subplots(figsize=(3, 2.4), dpi=50, constrained_layout=True)
    x = np.linspace(0, 2 * np.pi, 60)
    ax.plot(x, np.cos(x), "k--", label="still")
    (line,) = ax.plot(x, np.sin(x), lw=3, label="wave")
    dots = ax.scatter(x[::6], np.sin(x[::6]), s=40, zorder=3)
    text = ax.text(0.5, 1.05, "", ha="center")
    ax.legend(loc="center", framealpha=0.9)
    ax.set(xlim=(0, 2 * np.pi), ylim=(-1.2, 1.2), title="moving")

    def draw(k):
        line.set_ydata(np.sin(x + 0.7 * k))
        dots.set_offsets(np.c_[x[::6], np.sin(x[::6] + 0.7 * k)])
        text.set_text(f"t = {k}")
        return (line, dots, text) if returns else None

    return FuncAnimation(fig, draw, frames=6, interval=50)


@pytest.mark.parametrize("returns", [True, False])
def test_animation_player_draws_only_what_moves_with_the_full_drawings_pixels(returns, full_draws,
                                                                             monkeypatch):
    """A blittable animation is drawn in full once, one that returns nothing once per frame
    (not twice); either way its frames are those of a full savefig per frame (the skip-raster
    test pass's path) up to palette rounding."""
    anim = _busy_anim(returns)
    fig = anim._fig
    player = players.animation_player(anim, close=False)
    assert len(full_draws) == (1 if returns else 6)
    assert "draw_idle" not in vars(fig.canvas)
    monkeypatch.setattr(players, "_draw_frames", players._save_in_full)  # savefig per frame
    full_draws.clear()
    reference = players.animation_player(_busy_anim(returns), close=False)
    plt.close("all")
    fast, full = _frames(player), _frames(reference)
    assert len(fast) == len(full) == 6
    for k, (a, b) in enumerate(zip(fast, full, strict=True)):
        assert a.shape == b.shape
        # the same artists in the same order; a 256-colour palette rounds by a few levels,
        # a missing artist or a wrong order differs by far more on many pixels
        differ = np.abs(a - b).max(axis=-1) > 12
        assert differ.sum() <= 3, f"frame {k}: {differ.sum()} pixels differ from the full drawing"


def test_the_savefig_path_renders_each_frame_once_and_restores_the_canvas(square_anim, monkeypatch):
    monkeypatch.setattr(players, "_draw_frames", players._save_in_full)
    fig = square_anim._fig
    draws = []
    fig.canvas.mpl_connect("draw_event", lambda event: draws.append(event))
    player = players.animation_player(square_anim, close=False)
    assert len(player.labels) == 5 and len(draws) == 5   # not twice per frame
    assert "draw_idle" not in vars(fig.canvas)           # the canvas redraws as before
    plt.close(fig)


def test_rgba_png_matches_encode_png_and_checks_colors():
    fig, ax = plt.subplots(figsize=(2, 2), dpi=40)
    ax.plot([0, 1], [0, 1], lw=3)
    fig.canvas.draw()
    rgba = fig.canvas.buffer_rgba()
    for colors in (0, 64):
        a = np.asarray(Image.open(io.BytesIO(players.rgba_png(rgba, colors))).convert("RGB"))
        b = np.asarray(Image.open(io.BytesIO(players.encode_png(fig, 40, colors))).convert("RGB"))
        assert a.shape == b.shape and np.abs(a.astype(int) - b).max() <= 2
    with pytest.raises(ValueError, match="colors"):
        players.rgba_png(rgba, 300)
    plt.close(fig)


def test_player_html_is_deterministic_and_escapes_script_end():
    fig = plt.figure(figsize=(1, 1), dpi=30)
    png = _png(fig)
    plt.close(fig)
    a = players.frames_html([png, png], ["a", "b"], ["</script><b>x", ""], kind="parameter")
    b = players.frames_html([png, png], ["a", "b"], ["</script><b>x", ""], kind="parameter")
    assert a == b
    data = a.split('class="clp-data">')[1].split("</script>")[0]
    assert "<\\/script>" in data  # the JSON cannot close its script element early
    assert "&lt;/script&gt;&lt;b&gt;x" in a  # the first caption is escaped text


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"pngs": []}, "at least one frame"),
    ({"labels": ["a"]}, "one entry per frame"),
    ({"kind": "movie"}, "kind must be"),
    ({"mode": "bounce"}, "mode must be one of"),
    ({"interval": 0}, "interval must be > 0"),
])
def test_frames_html_rejects_bad_input(kwargs, match):
    fig = plt.figure(figsize=(1, 1), dpi=30)
    png = _png(fig)
    plt.close(fig)
    args = {"pngs": [png, png], "labels": ["a", "b"], **kwargs}
    with pytest.raises(ValueError, match=match):
        players.frames_html(args.pop("pngs"), args.pop("labels"), **args)


def _compute(a, b=1.0):
    return {"a": a, "b": b, "stable": a < 2, "message": "grew"}


def _draw(result):
    fig, ax = plt.subplots(figsize=(3, 2), dpi=50)
    ax.plot([0, 1], [0, result["a"] * result["b"]])
    return fig


def test_parameter_player_labels_captions_and_budget():
    class R:
        def __init__(self, a):
            self.a, self.stable, self.message = a, a < 2, "grew"

    player = players.parameter_player(lambda a, b: R(a), lambda r: _draw({"a": r.a, "b": 1}),
                                      "a", [1.0, 3.0], fixed={"b": 2.0}, unit="m")
    assert player.labels == ["a = 1 m", "a = 3 m"]
    assert player.captions == ["stable", "UNSTABLE: grew"]
    assert not plt.get_fignums()
    big = players.parameter_player(_compute, _draw, "a", np.linspace(0, 3, 6), dpi=200,
                                   caption=lambda r: f"a = {r['a']}", max_bytes=40_000)
    assert big.nbytes <= 40_000
    with pytest.raises(ValueError, match="max_bytes"):
        players.parameter_player(_compute, _draw, "a", [1.0, 2.0], max_bytes=2_000)
    with pytest.raises(ValueError, match="also in fixed"):
        players.parameter_player(_compute, _draw, "a", [1.0], fixed={"a": 1.0})
    with pytest.raises(ValueError, match="at least one"):
        players.parameter_player(_compute, _draw, "a", [])


def test_stability_player_flips_at_dt_2_and_fits_the_budget():
    player = kernel_free.stability_player()
    verdicts = dict(zip(kernel_free.STABILITY_DTS, player.captions, strict=True))
    assert verdicts[1.9].startswith("stable") and verdicts[2.1].startswith("unstable")
    assert player.nbytes <= 300_000


def test_spring_player_flips_at_k_400():
    player = kernel_free.spring_player()
    verdicts = dict(zip(kernel_free.SPRING_KS, player.captions, strict=True))
    assert verdicts[350.0].startswith("stable") and verdicts[450.0].startswith("BLOWN UP")
    assert player.nbytes <= 300_000


@pytest.mark.roundoff  # 9000 and 9500 are 3 % either side of the limit
def test_hair_player_flips_between_9000_and_9500():
    player = kernel_free.hair_player(k_bends=(9000.0, 9500.0))
    assert player.captions[0].startswith("stable") and player.captions[1].startswith("BLOWN UP")


@pytest.mark.roundoff  # a flock's run amplifies round-off
def test_flocking_player_shows_the_alignment_step_unstable():
    """At 8 /s the step is unstable (f < -1), not merely overshooting (f < 0 already at 5 /s,
    where the flock still aligns): notebook 10, Section 5."""
    player = kernel_free.flocking_player(alignments=(5.0, 8.0))
    assert "one aligned flock" in player.captions[0]
    assert "unstable (f < -1)" in player.captions[1] and "overshoot" not in player.captions[1]

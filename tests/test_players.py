"""Kernel-free players: the HTML is offline, deterministic and small; a frame shows before
any script runs; parameter players run the widget's own functions and flip at the limit."""

import json
import re

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.animation import FuncAnimation

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


def test_animation_player_renders_each_frame_once_and_restores_the_canvas(square_anim):
    fig = square_anim._fig
    draws = []
    fig.canvas.mpl_connect("draw_event", lambda event: draws.append(event))
    player = players.animation_player(square_anim, close=False)
    assert len(player.labels) == 5 and len(draws) == 5   # not twice per frame
    assert "draw_idle" not in vars(fig.canvas)           # the canvas redraws as before
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

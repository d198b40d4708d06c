"""plotting.freeze_layout: an animation's figure is laid out once and kept, with every text
inside the figure (one pass of constrained layout left notebook 01's title outside)."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pytest

from course_lib.plotting import freeze_layout, use_course_style


def _whirlpool_like():
    """Notebook 01's animation figure: an equal-aspect axes, a title, a legend below."""
    use_course_style()
    fig, ax = plt.subplots(figsize=(4, 4.3), dpi=80, constrained_layout=True)
    ax.scatter(*np.random.default_rng(1).uniform(-2, 2, (2, 50)), s=5, label="particles")
    ax.plot([0, 1], [0, 1], label="a path")
    ax.set(xlabel="x (m)", ylabel="y (m)", aspect="equal", xlim=(-2.7, 2.7), ylim=(-2.7, 2.7))
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    ax.set_title("whirlpool, t = 0.00 s", fontsize=10)
    return fig, ax


def _texts_inside(fig) -> bool:
    fig.canvas.draw()
    box = fig.bbox
    texts = [t for t in fig.findobj(matplotlib.text.Text) if t.get_visible() and t.get_text()]
    return all(box.x0 - 0.5 <= e.x0 and e.x1 <= box.x1 + 0.5 and box.y0 - 0.5 <= e.y0
               and e.y1 <= box.y1 + 0.5 for e in (t.get_window_extent() for t in texts))


def test_one_pass_leaves_the_title_out_and_freeze_layout_brings_it_in():
    fig, ax = _whirlpool_like()
    fig.draw_without_rendering()                  # one pass, as the notebook did
    fig.set_layout_engine("none")
    assert not _texts_inside(fig), "one pass now suffices: update freeze_layout's docstring"
    plt.close(fig)
    fig, ax = _whirlpool_like()
    freeze_layout(fig)
    assert type(fig.get_layout_engine()).__name__ == "PlaceHolderLayoutEngine"
    kept = ax.get_position().bounds
    assert _texts_inside(fig)
    ax.set_title("whirlpool, t = 6.28 s")         # a frame changes the text: nothing moves
    fig.canvas.draw()
    assert ax.get_position().bounds == kept
    plt.close(fig)


@pytest.mark.parametrize("engine", [None, "none"])
def test_a_figure_without_a_layout_engine_is_left_alone(engine):
    fig = plt.figure(layout=engine)
    before = fig.get_layout_engine()
    freeze_layout(fig)
    assert fig.get_layout_engine() is before
    plt.close(fig)

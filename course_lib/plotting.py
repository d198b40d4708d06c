"""Plot style and animation helpers shared by the notebooks.

Imports matplotlib and, for animations, :mod:`course_lib.players`.
"""

from __future__ import annotations

import matplotlib as mpl

#: Colour for analytic / exact curves, drawn beside every numerical result.
EXACT_STYLE = {"color": "black", "linestyle": "--", "linewidth": 1.5}
#: One colour per integrator, so a method looks the same in every notebook.
METHOD_COLORS = {
    "forward_euler": "#d62728",
    "midpoint": "#1f77b4",
    "heun": "#17becf",
    "rk4": "#2ca02c",
    "backward_euler": "#9467bd",
    "trapezoidal": "#ff7f0e",
    "symplectic_euler": "#8c564b",
    "velocity_verlet": "#e377c2",
}
#: Readable names for legends.
METHOD_LABELS = {
    "forward_euler": "forward Euler",
    "midpoint": "midpoint (RK2)",
    "heun": "Heun",
    "rk4": "RK4",
    "backward_euler": "backward Euler",
    "trapezoidal": "trapezoidal",
    "symplectic_euler": "symplectic Euler",
    "velocity_verlet": "velocity Verlet",
}


def detached_figure(figsize: tuple[float, float]):
    """A figure with its own Agg canvas, outside pyplot: a widget that shows its figure
    itself owns it, and Jupyter's inline backend does not show it a second time."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig


def freeze_layout(fig, passes: int = 3) -> None:
    """Lay ``fig`` out with its layout engine (e.g. constrained layout) and keep that
    layout: an animation's frames then keep still axes and skip the layout pass.

    One pass is not always enough: with an equal-aspect axes, constrained layout's first
    pass left notebook 01's whirlpool title above the top of the figure, and the second
    moved the axes down to make room. So it runs up to ``passes`` times, until no axes
    moves; a figure without a layout engine is left as it is."""
    engine = fig.get_layout_engine()
    if engine is None or type(engine).__name__ == "PlaceHolderLayoutEngine":
        return
    before = None
    for _ in range(passes):
        fig.draw_without_rendering()
        now = [(ax.get_position(original=True).bounds, ax.get_position().bounds) for ax in fig.axes]
        if now == before:
            break
        before = now
    fig.set_layout_engine("none")


def use_course_style() -> None:
    """Set the course's matplotlib defaults: modest size and resolution, light grid."""
    mpl.rcParams.update({
        "figure.figsize": (7.0, 4.0),
        "figure.dpi": 80,
        "savefig.dpi": 80,
        "axes.grid": True,
        "grid.alpha": 0.3,
        "axes.spines.top": False,
        "axes.spines.right": False,
        "font.size": 11,
        "legend.frameon": False,
        "animation.embed_limit": 4.0,  # MB; our animations stay far below
    })


def animation_html(anim, *, default_mode: str = "loop", dpi: float | None = None):
    """Render a ``matplotlib.animation`` as a self-contained player and close its figure.

    The player (:func:`course_lib.players.animation_player`) needs no kernel and no network:
    its buttons are inline SVG, its frames PNG images. Its first frame is a plain image, so
    a picture shows as soon as the cell has run, even before its script starts (and in an
    untrusted notebook, where the controls stay inactive). Closing the figure keeps its last
    frame from being drawn a second time below the player. Keep frame counts and figure
    sizes small: every frame is embedded.

    Parameters
    ----------
    anim : matplotlib.animation.Animation
        The animation; its frame interval sets the playing speed.
    default_mode : {"loop", "once", "reflect"}
        What playing does at the last frame.
    dpi : float, optional
        Resolution of the frames (dots per inch); default the figure's.

    Returns
    -------
    course_lib.players.Player
        Displays itself as HTML in a notebook.
    """
    from .players import animation_player

    return animation_player(anim, mode=default_mode, dpi=dpi)

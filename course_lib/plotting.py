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

"""Plot style and animation helpers shared by the notebooks."""

from __future__ import annotations

import matplotlib as mpl
import matplotlib.pyplot as plt

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


def animation_html(anim, *, default_mode: str = "loop"):
    """Render a ``matplotlib.animation`` as self-contained HTML/JS and close its figure.

    The result plays in any browser without a kernel. Closing the figure keeps its last
    frame from being drawn a second time below the player. Keep frame counts and figure
    sizes small: every frame is embedded as a PNG.
    """
    from IPython.display import HTML

    html = anim.to_jshtml(default_mode=default_mode)
    plt.close(anim._fig)
    return HTML(html)

"""Notebook 03 (stability): the stability explorer, an ipywidgets view.

:func:`stability_explorer` wires four controls (problem, method by its readable name, a
logarithmic time step slider, the rate) to the pure computation
:func:`~course_lib.lessons.nb03_stability.run_experiment` and to the figure of
:class:`~course_lib.lessons.nb03_explorer_plot.ExperimentPlot`. Each update renders the
figure to a PNG shown in an image widget (no flicker, no page jump) and says "computing"
while it runs. Imports the lesson's modules, the view helpers and ipywidgets.
"""

from __future__ import annotations

from ..integrators import METHODS
from ..plotting import METHOD_LABELS
from ..widgets import ExplorerView, log_slider
from .nb03_explorer_plot import FIGSIZE as FIGSIZE
from .nb03_explorer_plot import MAX_DRAWN as MAX_DRAWN
from .nb03_explorer_plot import ExperimentPlot
from .nb03_explorer_plot import draw_experiment as draw_experiment
from .nb03_problems import PROBLEMS
from .nb03_stability import run_experiment


class StabilityExplorerView(ExplorerView):
    """:class:`course_lib.widgets.ExplorerView` that shows its figure in an image widget.

    ``draw`` must be an :class:`ExperimentPlot`. Every update sets a "computing" label
    first, recomputes, updates the figure's artists, renders it to PNG and replaces the
    image; the page keeps its layout while it happens.
    Without a kernel the stored output is a line of text, not a tree of widget reprs.
    """

    def __init__(self, compute, draw, controls, fixed=None):
        import ipywidgets as w

        self.status = w.HTML(value="", layout=w.Layout(min_width="9em"))
        self.image = w.Image(format="png")
        super().__init__(compute, draw, controls, fixed)
        self.widget = w.VBox([
            w.HBox([*self.controls.values(), self.status], layout=w.Layout(flex_flow="row wrap")),
            self.image,
        ])

    def update(self) -> None:
        """Recompute from the controls' values and redraw, saying so while it runs."""
        self.status.value = "<i>computing…</i>"
        try:
            self.result = self.compute(**self.params)
            self.figure = self.draw(self.result)
            self.image.value = self.draw.png()
        finally:
            self.status.value = ""

    def _repr_mimebundle_(self, **kwargs):
        bundle = self.widget._repr_mimebundle_(**kwargs)
        bundle["text/plain"] = ("Stability explorer (interactive): run this cell in a "
                                "Jupyter kernel to use it; the pictures above show its key states.")
        return bundle

    def _ipython_display_(self) -> None:
        from IPython.display import display

        display(self._repr_mimebundle_(), raw=True)


def stability_explorer(
    problem: str = "decay", method: str = "forward_euler", dt: float = 0.5, rate: float = 1.0
):
    """The interactive explorer: problem, method, rate and a logarithmic ``dt`` slider.

    Returns a :class:`StabilityExplorerView`; display it in a notebook. Its ``result`` is
    the latest :class:`~course_lib.lessons.nb03_stability.ExperimentResult`.
    """
    import ipywidgets as w

    controls = {
        "problem": w.Dropdown(options=[(label, key) for key, label in PROBLEMS.items()],
                              value=problem, description="problem"),
        "method": w.Dropdown(options=[(METHOD_LABELS[m], m) for m in METHODS],
                             value=method, description="method"),
        "dt": log_slider("dt (s)", dt, 0.01, 10.0),
        "rate": w.FloatSlider(value=rate, min=0.25, max=4.0, step=0.05,
                              description="k or ω (1/s)", continuous_update=False,
                              style={"description_width": "initial"}),
    }
    return StabilityExplorerView(run_experiment, ExperimentPlot(blit=True), controls)

"""An :class:`~course_lib.widgets.ExplorerView` that says when it is working.

While an update runs (compute, then redraw) a line under the controls reads "working…";
afterwards it says how long the update took, so a student who moves a slider always sees
that the widget heard. The line is plain text (no emoji: not every font has one).

:func:`load_backend` makes sure a widget's first picture shows in a fresh kernel.

Lesson layer: imports the view helpers only.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping

from ..widgets import ExplorerView


def load_backend() -> None:
    """Load matplotlib's backend now. A widget draws on a detached figure, which never
    makes pyplot load its backend; in a fresh kernel the inline backend, which registers
    the PNG display of figures, is then missing and the widget shows ``<Figure ...>`` text
    instead of its picture (until some other cell draws with pyplot)."""
    try:
        from IPython import get_ipython
    except ImportError:  # pragma: no cover
        return
    shell = get_ipython()
    if shell is None or getattr(shell, "kernel", None) is None:
        return                                  # outside a kernel: nothing to display
    from matplotlib.figure import Figure

    try:
        shell.display_formatter.formatters["image/png"].lookup_by_type(Figure)
        return                                  # loaded already (switching would close figures)
    except KeyError:
        pass
    import matplotlib
    import matplotlib.pyplot as plt

    plt.switch_backend(matplotlib.get_backend())


class BusyExplorerView(ExplorerView):
    """:class:`~course_lib.widgets.ExplorerView` with a status line.

    Attributes
    ----------
    status : ipywidgets.HTML
        "working…" during an update, then "updated in 42 ms".
    seconds : float
        Duration of the latest update (s).
    """

    def __init__(self, compute: Callable, draw: Callable, controls: Mapping,
                 fixed: Mapping | None = None):
        import ipywidgets as w

        load_backend()
        self.status = w.HTML(value="", layout=w.Layout(height="1.6em"))
        self.seconds = 0.0
        super().__init__(compute, draw, controls, fixed)
        head, output = self.widget.children
        self.widget.children = (head, self.status, output)

    def update(self) -> None:
        """Recompute and redraw, showing "working…" meanwhile."""
        self.status.value = "<span style='color:#b05000'><b>working…</b></span>"
        start = time.perf_counter()
        try:
            super().update()
        except Exception as exc:  # say what went wrong in the widget, not in the log
            self.status.value = f"<span style='color:#c00000'>error: {exc}</span>"
            raise
        self.seconds = time.perf_counter() - start
        self.status.value = (f"<span style='color:#606060'>updated in "
                             f"{1e3 * self.seconds:.0f} ms</span>")

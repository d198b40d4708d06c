"""An :class:`~course_lib.widgets.ExplorerView` that says when it is working.

While an update runs (compute, then redraw) a line under the controls reads "working…";
afterwards it says how long the update took, so a student who moves a slider always sees
that the widget heard. The line is plain text (no emoji: not every font has one).

Lesson layer: imports the view helpers only.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping

from ..widgets import ExplorerView


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

"""Solution notebooks: wall time to run each top to bottom in a fresh kernel (kernel start
included, as a student's "Restart and run all"), and the whole course.

The notebooks are executed in memory (nothing is written back) with ``nbclient``, in the
benchmark environment's own ``python3`` kernel, in their folder.
"""

from __future__ import annotations

import time
from pathlib import Path

import nbformat

from benchmarks.timing import Row

ROOT = Path(__file__).resolve().parents[1]
PER_NOTEBOOK = 20.0   # s
COURSE = 120.0        # s


def execute(nb, folder: Path, timeout: float = 600) -> float:
    """Seconds to execute ``nb`` (a NotebookNode) in ``folder``."""
    from nbclient import NotebookClient

    client = NotebookClient(nb, timeout=timeout, kernel_name="python3",
                            extra_arguments=["--log-level=ERROR"],
                            resources={"metadata": {"path": str(folder)}})
    start = time.perf_counter()
    client.execute()
    return time.perf_counter() - start


def run(quick: bool = False) -> list[Row]:
    if quick:                                             # the code path, on a one-cell notebook
        nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("import course_lib")])
        seconds = execute(nb, ROOT)
        return [Row("notebook execution (smoke test)", seconds, "runs", True)]
    rows, total = [], 0.0
    for path in sorted((ROOT / "solutions").glob("*.ipynb")):
        start = time.perf_counter()
        try:
            seconds = execute(nbformat.read(path, as_version=4), path.parent)
            note = ""
        except Exception as exc:                          # a failing cell fails the row
            seconds = time.perf_counter() - start
            note = f"stopped by an error: {type(exc).__name__}"
        total += seconds
        rows.append(Row(f"solution notebook {path.stem}", seconds, f"≤ {PER_NOTEBOOK:.0f} s",
                        seconds <= PER_NOTEBOOK and not note, note=note))
    complete = all(not r.note for r in rows)
    rows.append(Row(f"the whole course ({len(rows)} solution notebooks)", total,
                    f"≤ {COURSE:.0f} s", total <= COURSE and complete,
                    note="" if complete else "incomplete: a notebook stopped early"))
    return rows

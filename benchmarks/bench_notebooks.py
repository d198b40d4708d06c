"""Solution notebooks: time to run each top to bottom in a fresh kernel (kernel start
included, as a student's "Restart and run all"), and the whole course. The time is the CPU
time of the kernel (wall time in the note): on a shared machine the wall clock also counts
other processes.

The notebooks are executed in memory (nothing is written back) with ``nbclient``, in the
benchmark environment's own ``python3`` kernel, in their folder.
"""

from __future__ import annotations

import resource
import time
from pathlib import Path

import nbformat

from benchmarks.timing import Row

ROOT = Path(__file__).resolve().parents[1]
PER_NOTEBOOK = 20.0   # s
COURSE = 120.0        # s


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def execute(nb, folder: Path, timeout: float = 600) -> tuple[float, float]:
    """``(cpu, wall)`` seconds to execute ``nb`` (a NotebookNode) in ``folder``: the CPU
    time of the kernel process (counted once it has exited) and of this one, and the wall
    time. On a busy machine the CPU time estimates a quiet machine's wall time."""
    from nbclient import NotebookClient

    client = NotebookClient(nb, timeout=timeout, kernel_name="python3",
                            extra_arguments=["--log-level=ERROR"],
                            resources={"metadata": {"path": str(folder)}})
    cpu, wall = _children_cpu() + time.process_time(), time.perf_counter()
    try:
        client.execute()
    finally:                                              # also when a cell fails
        execute.last = (_children_cpu() + time.process_time() - cpu, time.perf_counter() - wall)
    return execute.last


def run(quick: bool = False) -> list[Row]:
    if quick:                                             # the code path, on a one-cell notebook
        nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("import course_lib")])
        seconds, _ = execute(nb, ROOT)
        return [Row("notebook execution (smoke test)", max(seconds, 1e-9), "runs", True)]
    rows, total = [], 0.0
    for path in sorted((ROOT / "solutions").glob("*.ipynb")):
        error = ""
        try:
            execute(nbformat.read(path, as_version=4), path.parent)
        except Exception as exc:                          # a failing cell fails the row
            error = f"; stopped by an error: {type(exc).__name__}"
        seconds, wall = execute.last
        total += seconds
        rows.append(Row(f"solution notebook {path.stem}", seconds, f"≤ {PER_NOTEBOOK:.0f} s",
                        seconds <= PER_NOTEBOOK and not error, note=f"wall {wall:.1f} s{error}"))
    complete = all("error" not in r.note for r in rows)
    rows.append(Row(f"the whole course ({len(rows)} solution notebooks)", total,
                    f"≤ {COURSE:.0f} s", total <= COURSE and complete,
                    note="" if complete else "incomplete: a notebook stopped early"))
    return rows

"""Every solution notebook survives "Run All" followed by re-running its cells in other orders.

Students re-run cells out of order all the time: a cell two screens up, the animation once
more, the figure after changing a later cell. A cell that only works right after the cell
above it (because a later cell rebinds a name it uses, or it mutates a shared array) then
raises, or draws something else. For every notebook in ``solutions/`` this test, in one
kernel per notebook,

1. runs every code cell top to bottom (as "Run All" does);
2. runs every code cell once more, bottom to top;
3. runs every code cell once more, in a seeded random order;

and fails with the list of cells that raised in steps 2-3 (a failure in step 1 is reported
as such). Cells tagged ``raises-exception`` (or marked ``# NBVAL_RAISES_EXCEPTION``) are
allowed to raise. Nothing is skipped. Notebooks run two at a time, one kernel each (the
machine has two cores).
"""

from __future__ import annotations

import os
import random
from concurrent.futures import ThreadPoolExecutor

import pytest
from notebook_helpers import SOLUTIONS, read

SEED = 2026
EXPECTED_TO_RAISE = "NBVAL_RAISES_EXCEPTION"
WORKERS = min(2, os.cpu_count() or 1)


def _first_line(source: str) -> str:
    line = next((s for s in source.splitlines() if s.strip() and not s.startswith("#")), "")
    return line[:70]


def _error_of(cell) -> str | None:
    for out in cell.get("outputs", []):
        if out.get("output_type") == "error":
            return f"{out.get('ename')}: {out.get('evalue')}"
    return None


def _rerun(path) -> list[str]:
    """Run All, then the two other orders, in one kernel; the cells that raised."""
    from nbclient import NotebookClient

    nb = read(path)
    client = NotebookClient(
        nb, timeout=240, kernel_name="python3", allow_errors=True,
        extra_arguments=["--log-level=ERROR"],
        resources={"metadata": {"path": str(path.parent)}},
    )
    cells = [
        (index, cell) for index, cell in enumerate(nb.cells)
        if cell.cell_type == "code" and cell.source.strip()
        and "raises-exception" not in cell.metadata.get("tags", [])
        and EXPECTED_TO_RAISE not in cell.source
    ]
    shuffled = list(cells)
    random.Random(SEED).shuffle(shuffled)
    passes = [("Run All", cells), ("reverse order", cells[::-1]),
              (f"random order (seed {SEED})", shuffled)]
    failures = []
    with client.setup_kernel():
        for name, order in passes:
            for index, cell in order:
                client.execute_cell(cell, index)
                error = _error_of(cell)
                if error:
                    failures.append(f"{name}: cell {index} ({_first_line(cell.source)!r}) "
                                    f"raised {error}")
            if name == "Run All" and failures:
                break  # the notebook does not even run top to bottom
    return failures


@pytest.fixture(scope="module")
def rerun_failures():
    """Every notebook's failures; two notebooks at a time, each kernel on its own core."""
    with ThreadPoolExecutor(max_workers=WORKERS) as pool:
        futures = {path: pool.submit(_rerun, path) for path in SOLUTIONS}
        return {path: future.exception() or future.result() for path, future in futures.items()}


@pytest.mark.parametrize("path", SOLUTIONS, ids=lambda p: p.name)
def test_cells_survive_rerun_in_any_order(path, rerun_failures):
    failures = rerun_failures[path]
    if isinstance(failures, BaseException):
        raise failures
    assert not failures, f"{path.name}:\n  " + "\n  ".join(failures)

"""The nbval plugin of ``make test``: re-run each solution's cells in other orders right
after nbval's Run All, and mark nbval's cells ``roundoff``. Loaded by the root ``conftest.py``.

Students re-run cells out of order all the time: a cell two screens up, the animation once
more, the figure after changing a later cell. A cell that only works right after the cell
above it (because a later cell rebinds a name it uses, or it mutates a shared array) then
raises. With ``--nbval-rerun=DIR`` every notebook under ``DIR`` that nbval runs gets one
more test, ``rerun in other orders``: in the kernel nbval has just run top to bottom, every
code cell runs once more bottom to top, then once more in a seeded random order, and the
test fails with the list of cells that raised. Cells marked to raise
(``NBVAL_RAISES_EXCEPTION``, tag ``raises-exception``) or skipped (``NBVAL_SKIP``) are left
out. Reusing nbval's kernel saves a third run of every notebook; the re-runs draw each
figure's artists but not its pixels (``tests/skip_raster_startup.py``). Every nbval cell is marked
``roundoff`` (stored outputs quote numbers), so ``pytest -m roundoff --nbval build/paired``
repeats them under the second rounding (the notebooks tests/paired.py writes).
"""

from __future__ import annotations

import os
import random
import shutil
from pathlib import Path
from queue import Empty

import pytest

RERUN_SEED = 2026
NO_PIXELS = (f"__import__('runpy').run_path({str(Path(__file__).with_name('skip_raster_startup.py'))!r}, "
             "run_name='course_kit_rerun')")
EXPECTED_TO_RAISE = ("NBVAL_RAISES_EXCEPTION", "NBVAL_SKIP")
TAGS_LEFT_OUT = {"raises-exception", "nbval-skip"}


def pytest_addoption(parser):
    parser.addoption("--nbval-rerun", action="append", default=[], metavar="DIR",
                     help="after nbval's Run All of each notebook under DIR, re-run its "
                          "cells bottom to top and in a seeded random order")
    parser.addoption("--nbval-rerun-orders", default="reverse,random", metavar="ORDERS",
                     help="which re-runs, comma-separated: reverse, random (default both)")
    parser.addoption("--nbval-skip-raster", action="append", default=[], metavar="DIR",
                     help="run the notebooks under DIR without rasterizing figures (every "
                          "PNG a blank pixel: tests/skip_raster_startup.py)")
    parser.addoption("--nbval-rerun-max-seconds", type=float, default=float("inf"),
                     metavar="S", help="leave out of the re-runs the cells whose Run All "
                     "took longer than S seconds (the long simulations; default: none)")


def rerun_cells(nb) -> list[tuple[int, str]]:
    """(index among the notebook's cells, source) of the code cells that are re-run."""
    return [(i, c.source) for i, c in enumerate(nb.cells)
            if c.cell_type == "code" and c.source.strip()
            and not TAGS_LEFT_OUT & set(c.metadata.get("tags", []))
            and not any(marker in c.source for marker in EXPECTED_TO_RAISE)]


def rerun_orders(cells: list, seed: int = RERUN_SEED,
                 wanted=("reverse", "random")) -> list[tuple[str, list]]:
    """The passes after Run All: bottom to top, then a seeded shuffle (those ``wanted``)."""
    shuffled = list(cells)
    random.Random(seed).shuffle(shuffled)
    orders = {"reverse": ("reverse order", cells[::-1]),
              "random": (f"random order (seed {seed})", shuffled)}
    unknown = set(wanted) - set(orders)
    if unknown:
        raise ValueError(f"--nbval-rerun-orders: unknown {sorted(unknown)}; choose from "
                         f"{sorted(orders)}")
    return [orders[w] for w in wanted]


def _first_line(source: str) -> str:
    return next((s for s in source.splitlines() if s.strip() and not s.startswith("#")), "")[:70]


class RerunItem(pytest.Item):
    """Re-run a notebook's cells in other orders in the kernel nbval ran it in."""

    def runtest(self):
        nbfile = self.parent
        if nbfile.nodeid in _failed_notebooks:
            pytest.skip("a cell failed in Run All: fix that first")
        kernel = nbfile.kernel
        timeout = self.config.option.nbval_cell_timeout
        failures = []
        wanted = self.config.getoption("nbval_rerun_orders").split(",")
        slow = _slow_cells(nbfile.nb, _durations.get(nbfile.nodeid, {}),
                           self.config.getoption("nbval_rerun_max_seconds"))
        cells = [(i, src) for i, src in rerun_cells(nbfile.nb) if i not in slow]
        # figures drawn, their pixels not (tests/skip_raster_startup.py): the outputs of the
        # re-runs are not compared, and Run All just rasterized every figure
        msg_id = kernel.execute_cell_input(NO_PIXELS, allow_stdin=False)
        reply = _reply(kernel, msg_id, timeout)
        kernel.await_idle(msg_id, timeout)
        assert reply["status"] == "ok", f"the re-runs' figure patch raised {reply.get('evalue')}"
        for name, order in rerun_orders(cells, wanted=wanted):
            for index, source in order:
                msg_id = kernel.execute_cell_input(source, allow_stdin=False)
                reply = _reply(kernel, msg_id, timeout)
                kernel.await_idle(msg_id, timeout)  # drain this cell's outputs
                if reply["status"] != "ok":
                    failures.append(f"{name}: cell {index} ({_first_line(source)!r}) raised "
                                    f"{reply.get('ename')}: {reply.get('evalue')}")
        assert not failures, f"{nbfile.path.name}:\n  " + "\n  ".join(failures)

    def reportinfo(self):
        return self.path, None, f"{self.path.name}: rerun in other orders"


def _reply(kernel, msg_id: str, timeout: float) -> dict:
    while True:
        try:
            msg = kernel.get_message(stream="shell", timeout=timeout)
        except Empty:
            raise TimeoutError(f"a cell took more than {timeout} s") from None
        if msg["parent_header"].get("msg_id") == msg_id:
            return msg["content"]


_failed_notebooks: set[str] = set()
#: notebook node id -> {nbval's cell number (among code cells): seconds its run took}
_durations: dict[str, dict[int, float]] = {}


def _slow_cells(nb, durations: dict[int, float], limit: float) -> set[int]:
    """Indices (among all cells) of the code cells whose Run All took over ``limit`` s."""
    code = [i for i, c in enumerate(nb.cells) if c.cell_type == "code"]
    return {code[n] for n, sec in durations.items() if sec > limit and n < len(code)}


def pytest_runtest_logreport(report):
    """Remember notebooks whose Run All failed (their rerun is skipped, not reported twice)
    and how long each cell took (the re-runs may leave the slowest out)."""
    if ".ipynb::" not in report.nodeid:
        return
    notebook, _, cell = report.nodeid.partition("::")
    if report.failed:
        _failed_notebooks.add(notebook)
    if report.when == "call" and cell.startswith("Cell "):
        _durations.setdefault(notebook, {})[int(cell.split()[1])] = report.duration


def pytest_configure(config):
    """Install the skip-raster startup file in this process's IPYTHONDIR (a temporary
    folder made by the root conftest); it acts only in kernels started with
    ``COURSE_KIT_SKIP_RASTER=1``."""
    if config.getoption("nbval_skip_raster", None):
        startup = Path(os.environ["IPYTHONDIR"]) / "profile_default" / "startup"
        startup.mkdir(parents=True, exist_ok=True)
        shutil.copy(Path(__file__).with_name("skip_raster_startup.py"), startup / "00-skip-raster.py")


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    """Before a notebook's first cell starts its kernel, say whether it rasterizes: the
    kernel inherits this process's environment."""
    dirs = [Path(d).resolve() for d in item.config.getoption("nbval_skip_raster", None) or []]
    if dirs and type(item).__name__ in ("IPyNbCell", "RerunItem"):
        path = item.path.resolve()
        skip = any(d == path.parent or d in path.parents for d in dirs)
        os.environ["COURSE_KIT_SKIP_RASTER"] = "1" if skip else "0"


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(session, config, items):
    """Mark nbval's cells ``roundoff``; append a rerun test to each notebook under a
    ``--nbval-rerun`` folder (after its last cell, so it shares the notebook's kernel)."""
    dirs = [Path(d).resolve() for d in config.getoption("nbval_rerun")]
    out, last = [], {}
    for item in items:
        if type(item).__name__ == "IPyNbCell":
            item.add_marker(pytest.mark.roundoff)
            last[item.parent] = len(out)
        out.append(item)
    for nbfile, position in sorted(last.items(), key=lambda kv: -kv[1]):
        if any(d == nbfile.path.parent or d in nbfile.path.parents for d in dirs):
            out.insert(position + 1, RerunItem.from_parent(nbfile, name="rerun in other orders"))
    items[:] = out

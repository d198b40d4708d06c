"""Every solution notebook survives "Run All" followed by re-running its cells in other orders.

The re-runs themselves are tests of the notebook run: ``make test`` runs nbval with
``--nbval-rerun=solutions`` (the plugin in ``tests/nbval_rerun.py``), so right after nbval
has run a solution top to bottom, its cells run again bottom to top (every cell after all
the later ones ran again; ``make test RERUN_ORDERS=reverse,random`` adds a seeded shuffle)
in the same kernel, and ``solutions/NN.ipynb::rerun in other orders`` fails with the cells
that raised. This file tests that plugin: which cells and orders it uses, that it
catches a cell broken by a later one, and that ``make test`` asks for it.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import tempfile

import nbformat
import pytest
from nbval_rerun import _slow_cells, rerun_cells, rerun_orders
from notebook_helpers import ROOT, SOLUTIONS, code_cells, read


def _notebook(*sources: str, tags: dict | None = None) -> nbformat.NotebookNode:
    nb = nbformat.v4.new_notebook()
    nb.metadata.kernelspec = {"name": "python3", "display_name": "Python 3",
                              "language": "python"}
    nb.cells = [nbformat.v4.new_code_cell(s) for s in sources]
    for index, cell_tags in (tags or {}).items():
        nb.cells[index].metadata["tags"] = cell_tags
    return nb


def test_every_code_cell_is_rerun_except_those_meant_to_raise_or_skipped():
    nb = _notebook("a = 1", "# NBVAL_RAISES_EXCEPTION\n1 / 0", "  ", "# NBVAL_SKIP\nslow()",
                   "b = a", "raise KeyError", tags={5: ["raises-exception"]})
    nb.cells.insert(1, nbformat.v4.new_markdown_cell("text"))
    assert [i for i, _ in rerun_cells(nb)] == [0, 5]


@pytest.mark.parametrize("path", SOLUTIONS, ids=lambda p: p.name)
def test_both_orders_rerun_every_cell_once(path):
    cells = rerun_cells(read(path))
    assert len(cells) >= len(code_cells(read(path))) - 3   # few cells are left out
    (first, reverse), (second, shuffled) = rerun_orders(cells)
    assert reverse == cells[::-1] and first == "reverse order"
    assert sorted(shuffled) == sorted(cells) and "seed" in second
    if len(cells) > 3:
        assert shuffled not in (cells, cells[::-1])


@pytest.fixture(scope="module")
def rerun_session() -> tuple[int, str, dict[str, str]]:
    """One pytest run (a subprocess, with a kernel per notebook) of three small notebooks
    with ``--nbval-rerun`` and ``--nbval-rerun-max-seconds=1``: ``nb`` runs top to bottom
    but not again, ``good`` does, ``slow`` has a slow cell (1.5 s) broken by a later one.
    Returns the exit code, the output and each notebook's failure lines (the ``E`` lines
    under its ``AssertionError: <name>.ipynb:``)."""
    build = ROOT / "build"
    build.mkdir(exist_ok=True)
    folder = tempfile.mkdtemp(prefix="rerun-", dir=build)
    try:
        nbformat.write(_notebook("x = 1", "y = x + 1", "x = 'text'"), f"{folder}/nb.ipynb")
        nbformat.write(_notebook("v = [1, 2]", "w = v[0]"), f"{folder}/good.ipynb")
        # the slow cell breaks the fast one after it; the fast one breaks the slow one
        nbformat.write(_notebook("x = 1", "import time; time.sleep(1.5); z = x + 1",
                                 "y = x + 1", "x = 'text'"), f"{folder}/slow.ipynb")
        # a figure saved in a cell (as a player saves its frames) that a later cell breaks:
        # the re-runs skip its pixels but still draw its artists, and so still fail
        nbformat.write(_notebook("import io\nimport matplotlib.pyplot as plt\n"
                                 "fig, ax = plt.subplots()\nline, = ax.plot([0, 1], [0, 1])",
                                 "line.set_ydata([1, 0])\npng = io.BytesIO()\n"
                                 "fig.savefig(png, format='png')\nsize = len(png.getvalue())",
                                 "line.set_xdata([0, 1, 2])"), f"{folder}/figure.ipynb")
        done = subprocess.run(
            [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-p", "no:xdist",
             "--nbval-lax", "--nbval-current-env", f"--nbval-rerun={folder}",
             "--nbval-rerun-max-seconds=1", folder, "-rA"],
            cwd=ROOT, capture_output=True, text=True, timeout=300)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    blocks: dict[str, str] = {}
    name = None
    for line in done.stdout.splitlines():
        found = re.match(r"E\s+AssertionError: (\w+)\.ipynb:", line)
        if found:
            name = found.group(1)
        elif not line.startswith("E"):
            name = None
        if name:
            blocks[name] = blocks.get(name, "") + line + "\n"
    return done.returncode, done.stdout, blocks


def test_a_cell_broken_by_a_later_cell_fails_the_rerun(rerun_session):
    """A notebook that runs top to bottom but not again: the rerun test names the cell."""
    returncode, out, blocks = rerun_session
    assert returncode == 1, out[-3000:]
    assert re.search(r"FAILED \S*/nb\.ipynb::rerun in other orders", out), out[-3000:]
    assert "reverse order: cell 1 ('y = x + 1') raised TypeError" in blocks["nb"], out[-3000:]
    assert re.search(r"PASSED \S*/good\.ipynb::rerun in other orders", out), out[-3000:]
    assert "good" not in blocks
    assert "13 passed" in out and "3 failed" in out   # 12 cells and one rerun; three reruns
    assert "reverse order: cell 1 ('line.set_ydata([1, 0])') raised ValueError" in blocks["figure"]


def test_the_reruns_draw_figures_without_their_pixels(rerun_session):
    """In the re-runs a saved PNG is one blank pixel (Run All already drew it) but the
    figure's artists are still drawn: the broken figure above fails, as it would drawn."""
    _, out, blocks = rerun_session
    assert "shape mismatch" in blocks["figure"], out[-3000:]


def test_make_test_reruns_the_solutions():
    makefile = (ROOT / "Makefile").read_text()
    assert "--nbval-rerun=solutions" in makefile
    assert re.search(r"^RERUN_ORDERS \?= reverse", makefile, re.M)
    assert "--nbval-rerun-max-seconds=$(RERUN_MAX_SECONDS)" in makefile


def test_the_orders_can_be_chosen_and_unknown_ones_are_named():
    cells = [(0, "a"), (1, "b"), (2, "c")]
    assert [name for name, _ in rerun_orders(cells, wanted=["reverse"])] == ["reverse order"]
    with pytest.raises(ValueError, match=r"unknown.*'sideways'.*'random', 'reverse'"):
        rerun_orders(cells, wanted=["sideways"])


def test_the_slowest_cells_can_be_left_out_of_the_reruns(rerun_session):
    """``--nbval-rerun-max-seconds`` leaves out the cells whose Run All took longer (numbered
    by nbval among code cells, mapped back to the notebook's cells); the rest still re-run,
    so a quick cell broken by a later one is still caught."""
    nb = _notebook("a = 1", "slow = 2", "b = a")
    nb.cells.insert(1, nbformat.v4.new_markdown_cell("text"))
    assert _slow_cells(nb, {0: 0.1, 1: 5.0, 2: 0.2}, 1.0) == {2}
    assert _slow_cells(nb, {0: 0.1, 1: 5.0, 2: 0.2}, float("inf")) == set()
    # in a real run (the fixture's slow.ipynb): left out, the slow cell no longer fails the
    # rerun, the fast one still does
    _, out, blocks = rerun_session
    assert re.search(r"FAILED \S*/slow\.ipynb::rerun in other orders", out), out[-3000:]
    assert "reverse order: cell 2 ('y = x + 1') raised TypeError" in blocks["slow"], out[-3000:]
    assert "cell 1 (" not in blocks["slow"], blocks["slow"]

"""Shared helpers for tests that read the course notebooks."""

from __future__ import annotations

import re
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parents[1]
SOLUTIONS = sorted((ROOT / "solutions").glob("*.ipynb"))
CHECK_IMPORT = re.compile(r"from course_lib\.check import (nb\d+)")


def read(path: Path) -> nbformat.NotebookNode:
    return nbformat.read(path, as_version=4)


def code_cells(nb) -> list:
    return [c for c in nb.cells if c.cell_type == "code" and c.source.strip()]


def markdown(name: str, folder: str = "solutions") -> str:
    """The markdown cells of notebook ``name`` (a file name in ``folder``), joined by newlines."""
    nb = read(ROOT / folder / name)
    return "\n".join(c.source for c in nb.cells if c.cell_type == "markdown")


def check_module(nb) -> str | None:
    for cell in code_cells(nb):
        m = CHECK_IMPORT.search(cell.source)
        if m:
            return m.group(1)
    return None


def printed_holds(value: float, fmt: str, text: str, spread: float) -> None:
    """Assert that ``format(value, fmt) == text`` and that it prints ``text`` on any machine.

    ``spread`` (same units as ``value``) bounds how far another rounding (another SIMD
    kernel, another BLAS, another CPU) can move ``value``: an error estimate of the kind
    "n steps × eps × scale" for a smooth computation, or a few iterations out of a total for
    an iteration count. The value must lie farther than ``spread`` from every edge at which
    its printed digits would change; otherwise the notebook must print fewer digits.
    """
    assert format(value, fmt) == text, f"prints {format(value, fmt)!r}, the notebook says {text!r}"
    for sign in (-1.0, 1.0):
        moved = value + sign * spread
        assert format(moved, fmt) == text, (
            f"{value!r} prints {text!r} here, but another rounding within ±{spread:g} "
            f"would print {format(moved, fmt)!r}: print fewer digits")


def cpu_only_clock(what: str = "the timing"):
    """A stand-in ``time`` module for running a notebook's timing cell: ``process_time``
    works and counts its reads, every wall clock raises. Returns ``(clock, reads)``."""
    import time
    import types

    reads: list[int] = []

    def process_time():
        reads.append(1)
        return time.process_time()

    def wall(*_):
        raise AssertionError(f"{what} read a wall clock")

    clock = types.SimpleNamespace(process_time=process_time, perf_counter=wall, time=wall,
                                  monotonic=wall, perf_counter_ns=wall, time_ns=wall)
    return clock, reads


def drive_kept_figure(view, moves):
    """Drive a widget whose figure keeps its background (``widgets.BlitPlot``) through
    ``moves``, ``(control, value)`` pairs, as a student does, by setting ``.value``.

    After each move the picture must equal a full redraw of the same figure (fewer than
    0.2 % of the pixels differ: anti-aliasing at the edges of kept artists). Yields
    ``(control, value, result, redrawn)``; ``redrawn`` says whether the move drew the whole
    figure (its background) rather than only what moves.
    """
    import io

    import numpy as np
    from PIL import Image

    canvas, draws = view.draw.fig.canvas, []
    real_draw = canvas.draw
    canvas.draw = lambda: (draws.append(1), real_draw())[1]
    for name, value in moves:
        before = len(draws)
        view.controls[name].value = value
        redrawn = len(draws) > before
        shown = np.asarray(Image.open(io.BytesIO(view.image.value))).astype(int)
        view.draw._key = None                        # forget the background: a full redraw
        after = len(draws)
        full = np.asarray(Image.open(io.BytesIO(view.draw.png()))).astype(int)
        assert len(draws) == after + 1, "a forced redraw draws the figure once"
        assert shown.shape == full.shape and np.mean(np.any(shown != full, axis=-1)) < 2e-3, \
            (name, value)
        yield name, value, view.result, redrawn

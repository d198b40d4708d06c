"""Case data of notebook 10's check of the uniform-grid neighbour search, and how the
check measures an answer's cost.

- :func:`grid_cases`: point sets that break the usual shortcuts of a grid (pairs at exactly
  the radius in diagonal cells, coincident points, clusters) and two of the same density,
  2000 and 8000 points, on which the cost is measured;
- :func:`measured`: runs an answer and returns its result, the peak memory it held and the
  bytes it allocated in all (tracemalloc, sampled at every line of the answer's own code),
  stopping it after :func:`line_limit` lines.

Imports NumPy and the standard library only.
"""

from __future__ import annotations

import sys
import tracemalloc

import numpy as np

#: Lines of Python an answer may run on a case of N points: max(LINES_AT_LEAST, LINES_PER_POINT N).
#: A grid that loops in Python over the occupied cells runs about 25 lines per point (180,000
#: for 8000 points); one that loops over every point's candidates too, about 70 (550,000 for
#: 8000 points, 72,000 for 300 points in two tight clusters). Testing all pairs one by one in
#: Python runs three lines per pair, N²/2 pairs (6 × 10⁶ for 2000 points), and is stopped.
LINES_PER_POINT, LINES_AT_LEAST = 100, 250_000


def line_limit(n: int) -> int:
    """Lines of Python an answer may run on ``n`` points."""
    return max(LINES_AT_LEAST, LINES_PER_POINT * n)


class TooLong(BaseException):
    """Raised in an answer that runs more than :func:`line_limit` lines (a BaseException,
    so that the answer's own ``except Exception`` does not swallow it)."""


def measured(func, *args) -> tuple[object, int, int]:
    """``func(*args)``, the peak memory it held (bytes) and the bytes it allocated in
    total, sampled at every line of the answer's own code: the peak since the previous
    line, above what was held then, summed. Byte counts, not seconds: the same verdict on
    every machine. Stops the answer (:class:`TooLong`) after :func:`line_limit` lines."""
    limit, lines, total, peak_all, held = line_limit(len(args[0])), 0, 0, 0, 0

    def line(frame, event, arg):
        nonlocal lines, total, peak_all, held
        if event == "line":
            lines += 1
            if lines > limit:
                raise TooLong
            current, peak = tracemalloc.get_traced_memory()
            total, peak_all, held = total + peak - held, max(peak_all, peak), current
            tracemalloc.reset_peak()
        return line

    def calls(frame, event, arg):
        module = frame.f_globals.get("__name__", "") or ""
        return None if module.startswith(("numpy", "scipy", "course_lib", "importlib")) else line

    previous = sys.gettrace()
    tracemalloc.start()
    held = tracemalloc.get_traced_memory()[0]
    sys.settrace(calls)
    try:
        out = func(*args)
    finally:
        sys.settrace(previous)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    return out, max(peak_all, peak), total + peak - held


def grid_cases(seed: int):
    """Point sets that break the usual shortcuts of a grid search (radius in m), and two of
    the same density, the second with four times the points (the cost of the search)."""
    rng = np.random.default_rng(seed)
    yield "3-4-5: a pair at exactly the radius (5 m) in diagonal cells, one just beyond", \
        np.array([[0.0, 0.0], [3.0, 4.0], [3.0, np.nextafter(4.0, 5.0) + 1e-9], [-3.0, -4.0]]), 5.0
    yield "a row of points exactly one radius apart", np.column_stack((0.5 * np.arange(12.0),
                                                                        np.zeros(12))), 0.5
    yield "coincident points and negative coordinates", np.array(
        [[-1.2, -0.3], [-1.2, -0.3], [-0.3, -1.1], [0.4, 0.2], [-2.9, -2.9], [-2.2, -2.1]]), 1.0
    yield "one point", np.array([[1.0, 2.0]]), 1.0
    yield "no pair at all", np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]]), 1.0
    yield "300 points in two tight clusters and a sparse cloud", np.concatenate((
        rng.normal(0.0, 0.3, (120, 2)), rng.normal(5.0, 0.2, (80, 2)),
        rng.uniform(-10.0, 15.0, (100, 2)))), 0.7
    yield "2000 points in a 50 m square, radius 1 m", rng.uniform(0.0, 50.0, (2000, 2)), 1.0
    yield "8000 points in a 100 m square, radius 1 m", rng.uniform(0.0, 100.0, (8000, 2)), 1.0

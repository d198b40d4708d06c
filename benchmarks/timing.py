"""Timing helpers and the table row shared by every benchmark module.

Every comparison follows one protocol: the implementations are first checked to give the
same answer (to 1e-10, relative to the largest entry), then timed in *interleaved rounds*
(one round runs each implementation in turn, so a busy machine slows them alike), and
we report the median time of each and the median of the per-round ratios.

Computations run serially in this process are timed with the CPU time of this thread
(:data:`CPU`): on a shared machine the wall clock also counts the time other processes
hold the core, which is noise for a comparison of serial code. Widgets and notebooks are
timed on CPU time too (a widget update on this thread, a notebook on its kernel's
process), with the wall clock (:data:`WALL`), what a student waits, in the row's note.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

#: Relative tolerance of the equality check run before any timing.
EQUAL_RTOL = 1e-10
#: Clocks: CPU time of the calling thread (user + system), and the wall clock.
CPU = time.thread_time
WALL = time.perf_counter


@dataclass
class Row:
    """One line of the table (times in seconds; ``None`` where not measured)."""

    case: str
    course_lib: float | None
    target: str
    ok: bool | None
    naive: float | None = None
    numba: float | None = None
    ratio: str = ""
    note: str = ""


@dataclass
class Timing:
    """Median time per call (s) of each implementation, and per-round ratios."""

    median: dict[str, float]
    rounds: dict[str, list[float]] = field(repr=False)

    def ratio(self, a: str, b: str) -> float:
        """Median over rounds of ``time[a] / time[b]``."""
        return statistics.median(x / y for x, y in zip(self.rounds[a], self.rounds[b], strict=True))


def check_equal(results: dict[str, np.ndarray], reference: str, rtol: float = EQUAL_RTOL) -> None:
    """Raise ``AssertionError`` unless every result equals ``results[reference]`` to
    ``rtol`` relative to the reference's largest entry."""
    ref = np.asarray(results[reference], dtype=float)
    scale = max(float(np.max(np.abs(ref))), np.finfo(float).tiny)
    for name, value in results.items():
        err = float(np.max(np.abs(np.asarray(value, dtype=float) - ref))) / scale
        if not err <= rtol:
            raise AssertionError(f"{name} differs from {reference} by {err:.2e} (relative), "
                                 f"more than {rtol:g}: not timed")


def interleaved(impls: dict[str, Callable[[], object]], rounds: int = 15,
                inner: dict[str, int] | int = 1, warmup: bool = True,
                clock: Callable[[], float] = CPU) -> Timing:
    """Time each callable ``inner`` times per round, for ``rounds`` interleaved rounds, on
    ``clock`` (:data:`CPU` by default)."""
    if isinstance(inner, int):
        inner = dict.fromkeys(impls, inner)
    if warmup:
        for f in impls.values():
            f()
    per_round: dict[str, list[float]] = {name: [] for name in impls}
    for _ in range(rounds):
        for name, f in impls.items():
            n = inner[name]
            start = clock()
            for _ in range(n):
                f()
            per_round[name].append((clock() - start) / n)
    return Timing({k: statistics.median(v) for k, v in per_round.items()}, per_round)


def median_time(func: Callable[[], object], repeat: int = 7, number: int = 1,
                clock: Callable[[], float] = CPU) -> float:
    """Median time (s, CPU time of this thread by default, like every computation row) of
    ``func()`` over ``repeat`` runs of ``number`` calls."""
    return interleaved({"f": func}, rounds=repeat, inner=number, clock=clock).median["f"]


def fmt_time(seconds: float | None) -> str:
    """A time with a unit that keeps three significant figures readable."""
    if seconds is None:
        return "–"
    if seconds >= 1.0:
        return f"{seconds:.2f} s"
    if seconds >= 1e-3:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds * 1e6:.3g} µs"

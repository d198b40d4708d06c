"""Run every ``benchmarks/bench_*.py`` and compare with its targets.

Each module defines ``run() -> list[Result]``. Timings are the median of repeated runs
(``timeit``), so a busy machine shifts them less than a single measurement would.
The exit status is 1 if any benchmark misses its target.
"""

from __future__ import annotations

import importlib
import pkgutil
import sys
from dataclasses import dataclass
from pathlib import Path


@dataclass
class Result:
    name: str
    seconds: float
    target: float | None = None

    @property
    def ok(self) -> bool:
        return self.target is None or self.seconds <= self.target


def median_time(func, repeat: int = 15, number: int = 1) -> float:
    """Median wall time (s) of ``func()`` over ``repeat`` runs of ``number`` calls."""
    import statistics
    import timeit

    func()  # warm up caches and imports
    times = timeit.repeat(func, repeat=repeat, number=number)
    return statistics.median(times) / number


def main() -> int:
    here = Path(__file__).parent
    failed = 0
    for info in sorted(pkgutil.iter_modules([str(here)]), key=lambda m: m.name):
        if not info.name.startswith("bench_"):
            continue
        module = importlib.import_module(f"benchmarks.{info.name}")
        for r in module.run():
            target = f"target ≤ {r.target * 1e3:.1f} ms" if r.target is not None else "no target"
            flag = "ok  " if r.ok else "SLOW"
            failed += not r.ok
            print(f"{flag} {r.name:<55} {r.seconds * 1e3:9.2f} ms   ({target})")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

"""``make bench``: every benchmark in one table, printed and written to ``LATEST.md``.

Each ``benchmarks/bench_*.py`` defines ``run(quick=False) -> list[Row]``. Columns: the
course_lib time, a naive Python loop, a compiled numba loop (when numba is installed, in
the separate ``.venv-bench`` that ``make bench`` builds), the ratios, the target from the
issues and pass/fail. BLAS runs on one thread (set before NumPy loads), so every column is
serial like the numba reference; on a small shared machine threads only add contention.
The exit status is 1 if any row misses its target.

Usage: ``python -m benchmarks [--quick] [--only NAME ...] [--out FILE]``.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import importlib  # noqa: E402
import pkgutil  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import traceback  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from pathlib import Path  # noqa: E402

HERE = Path(__file__).parent


@dataclass
class Result:
    """Older row form, still accepted: a time (s) against a time target (s)."""

    name: str
    seconds: float
    target: float | None = None

    @property
    def ok(self) -> bool:
        return self.target is None or self.seconds <= self.target


def median_time(func, repeat: int = 15, number: int = 1) -> float:
    """Median CPU time (s) of ``func()`` (see :func:`benchmarks.timing.median_time`)."""
    from benchmarks.timing import median_time as timed

    return timed(func, repeat, number)


def as_rows(results) -> list:
    """Table rows from a module's results (:class:`~benchmarks.timing.Row` or :class:`Result`)."""
    from benchmarks.timing import Row

    rows = []
    for r in results:
        if isinstance(r, Row):
            rows.append(r)
        else:
            target = "–" if r.target is None else f"≤ {r.target * 1e3:.3g} ms"
            rows.append(Row(r.name, r.seconds, target, None if r.target is None else r.ok))
    return rows


def run_module(name: str, quick: bool = False) -> list:
    """Run ``benchmarks.<name>``; modules whose ``run()`` takes no ``quick`` run in full."""
    import inspect

    module = importlib.import_module(f"benchmarks.{name}")
    takes_quick = "quick" in inspect.signature(module.run).parameters
    return as_rows(module.run(quick=quick) if takes_quick else module.run())


def machine() -> str:
    """CPU model, cores, Python and library versions."""
    import numpy
    import scipy

    from benchmarks.reference import NUMBA

    cpu = platform.processor() or "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    numba = f"numba {NUMBA}" if NUMBA else "numba not installed (column skipped)"
    return (f"{cpu}, {os.cpu_count()} cores; Python {platform.python_version()}, "
            f"NumPy {numpy.__version__}, SciPy {scipy.__version__}, {numba}; "
            f"BLAS threads {os.environ.get('OPENBLAS_NUM_THREADS')}. Computations: CPU time "
            f"of the benchmark thread; widgets and notebooks: CPU time too (wall time in the notes)")


def table(rows) -> str:
    from benchmarks.timing import fmt_time

    lines = ["| case | course_lib | naive loop | numba | measured | target | pass |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        verdict = "–" if r.ok is None else ("pass" if r.ok else "**FAIL**")
        measured = r.ratio + (f" ({r.note})" if r.note and r.ratio else r.note)
        lines.append(f"| {r.case} | {fmt_time(r.course_lib)} | {fmt_time(r.naive)} | "
                     f"{fmt_time(r.numba)} | {measured} | {r.target} | {verdict} |")
    return "\n".join(lines)


def modules(only=None) -> list[str]:
    names = sorted(m.name for m in pkgutil.iter_modules([str(HERE)]) if m.name.startswith("bench_"))
    return [n for n in names if not only or any(o in n for o in only)]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="tiny sizes, one round (smoke test)")
    parser.add_argument("--only", nargs="*", help="run only the bench modules matching these")
    parser.add_argument("--out", default=str(HERE / "LATEST.md"), help="markdown file to write")
    args = parser.parse_args(argv)
    rows, failures = [], 0
    start = time.perf_counter()
    for name in modules(args.only):
        print(f"running {name} ...", file=sys.stderr, flush=True)
        try:
            rows += run_module(name, args.quick)
        except Exception:                     # a broken case is a failed row, not a crash
            from benchmarks.timing import Row

            traceback.print_exc()
            rows.append(Row(f"{name} (crashed: see log)", None, "runs", False))
    failures = sum(r.ok is False for r in rows)
    text = (f"Machine: {machine()}\n\n{table(rows)}\n\n"
            f"{len(rows) - failures} of {len(rows)} rows pass; benchmarks took "
            f"{time.perf_counter() - start:.0f} s ({time.strftime('%Y-%m-%d')}).\n")
    print(text)
    if not args.quick:
        Path(args.out).write_text("# Latest `make bench`\n\n" + text)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

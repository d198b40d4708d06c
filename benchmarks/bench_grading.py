"""Grading a synthetic class on a Dask ``LocalCluster``: throughput and 1 → 2 worker speedup.

The class is :func:`course_lib.instructor.synth.synth_class` (notebook 05, demonstration
cells left out): every kind of answer once, then kinds drawn with the generator's weights
(right, wrong, crashing, looping, tampering, huge output, missing). Limits: 10 s per cell,
3 s per exercise (a looping answer costs its 3 s), 1 GB.

- **Throughput**: submissions graded per minute of CPU, all processes counted (the
  client, the scheduler, the Dask worker and every sandboxed worker it started), with one
  worker of one thread. A full notebook of the kit costs a few seconds more of CPU each.
- **Speedup**: wall time with one worker over wall time with two (one thread each),
  measured in one run on the same class, each worker warmed first (its imports and its
  sandbox runtime, made once per worker in a real run too). The gradings alternate
  1, 2, 1, 2 workers and each count keeps its faster run: on a shared virtual machine one
  grading of 16 took 29 to 34 s within minutes. It needs two idle cores; the note gives
  the load average, since on a shared machine other processes take the second core.

``quick=True`` (the test suite's smoke run) grades one submission once on this machine
without a cluster; the Dask path itself, and that a local run and a cluster write the same
gradebook, are tested in tests/test_grading_cluster.py.
"""

from __future__ import annotations

import os
import resource
import tempfile
import time
from pathlib import Path

from benchmarks.timing import Row

ROOT = Path(__file__).resolve().parents[1]


def _cpu() -> float:
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def _warm() -> None:
    """What a worker does once before its first submission: import the grader, make its runtime."""
    from course_lib.instructor import cluster

    cluster.prepare_worker()


def _grade(folder: Path, out: Path, workers: int) -> tuple[float, float]:
    """Wall and CPU seconds (all processes) to grade ``folder`` on ``workers`` Dask workers
    (``workers=0``: on this machine without Dask, the quick smoke test's way)."""
    from distributed import Client, LocalCluster

    from course_lib.instructor.grade import grade_class
    from course_lib.instructor.sandbox import Limits

    limits = Limits(deadline=60, cell_s=10, exercise_s=3, memory_mb=1024)
    cpu0 = _cpu()
    if workers == 0:
        start = time.perf_counter()
        grade_class([folder], out, solutions=ROOT / "solutions", limits=limits, progress=False, jobs=1)
        return time.perf_counter() - start, _cpu() - cpu0
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        client.wait_for_workers(workers)
        client.run(_warm)
        start = time.perf_counter()
        grade_class([folder], out, solutions=ROOT / "solutions", limits=limits, progress=False,
                    scheduler=client)
        wall = time.perf_counter() - start
    return wall, _cpu() - cpu0  # the workers have exited: their CPU is counted


def run(quick: bool = False) -> list[Row]:
    from course_lib.instructor.synth import synth_class

    n = 1 if quick else 16
    with tempfile.TemporaryDirectory() as tmp:
        made = synth_class(Path(tmp) / "class", n, solutions=ROOT / "solutions")
        wall1, cpu1 = _grade(made["submissions"], Path(tmp) / "one.csv", 0 if quick else 1)
        if quick:  # a smoke test: one grading (the same gradebook twice is tested elsewhere)
            wall2, same = wall1, True
        else:
            wall2, _ = _grade(made["submissions"], Path(tmp) / "two.csv", 2)
            again1, _ = _grade(made["submissions"], Path(tmp) / "one-again.csv", 1)
            again2, _ = _grade(made["submissions"], Path(tmp) / "two-again.csv", 2)
            wall1, wall2 = min(wall1, again1), min(wall2, again2)
            names = ("one.csv", "two.csv", "one-again.csv", "two-again.csv")
            books = [(Path(tmp) / f).read_bytes() for f in names]
            same = all(b == books[0] for b in books)
    per_minute = n / (cpu1 / 60)
    speedup = wall1 / wall2
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    course = 1000 * 11 / per_minute / 60
    return [
        Row(f"grading throughput: synthetic class of {n} (notebook 05), 1 Dask worker",
            cpu1 / n, "≥ 20 submissions per core-minute", per_minute >= 20,
            ratio=f"{per_minute:.1f} per core-minute",
            note=f"CPU of all processes; 1,000 students × 11 notebooks ≈ {course:.0f} core-hours "
                 f"at this rate; wall {wall1:.1f} s"),
        Row(f"grading speedup, LocalCluster 1 → 2 workers (same {n} submissions)", wall2,
            "≥ 1.7× on a quiet 2-core machine", speedup >= 1.7 and same,
            ratio=f"{speedup:.2f}×",
            note=f"wall {wall1:.1f} s → {wall2:.1f} s, the faster of two runs each; "
                 f"gradebooks identical: {same}; load average {load} on {os.cpu_count()} cores"),
    ]

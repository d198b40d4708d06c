"""Grading a class: every student, every expected exercise, one row each, in parallel.

:func:`grade_class` reads the kit's assignments (:mod:`.kit`), the roster and each
student's files (:mod:`.submissions`), scans each notebook without running it
(:mod:`.scan`), runs it in a sandboxed worker (:mod:`.sandbox`) and judges the recorded
values with the kit's checks (:mod:`.verdicts`), one submission at a time in
:func:`.task.grade_task`. Submissions are graded concurrently:
here (one worker process each, ``jobs`` at a time) or as tasks on a Dask cluster
(:mod:`.cluster`). This process alone writes the gradebook: rows are appended to the CSV
and to the journal (:mod:`.journal`) as each submission finishes, so an interrupted run
leaves a valid gradebook of what was graded and resumes where it stopped; the file is
rewritten in a stable order at the end, whatever the order of completion. Then come the
feedback files and the class report (:mod:`.feedback`, :mod:`.report`).

Nothing here raises because of a submission: any failure becomes rows with a status.
Imports: the standard library, tqdm, and this package's modules.
"""

from __future__ import annotations

import csv
import os
import sys
import warnings
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path

from .kit import Assignment, load_kit
from .runtime import Runtime
from .sandbox import Limits
from .submissions import Student, choose, normalized, students
from .task import Task, grade_task
from .verdicts import FIELDS, Row

__all__ = ["Task", "default_solutions", "grade_class", "grade_notebook", "grade_paths", "grade_task"]


def default_solutions() -> Path:
    """``solutions/`` in the current folder, else beside the installed course_lib."""
    here = Path("solutions")
    if here.is_dir():
        return here
    import course_lib

    return Path(course_lib.__file__).resolve().parents[1] / "solutions"


def _assignments(roster: list[Student], kit: dict[str, Assignment],
                 names: list[str] | None) -> list[Assignment]:
    if names:
        unknown = [n for n in names if n not in kit]
        broken = {n: why for n, why in getattr(kit, "skipped", {}).items() if n in unknown}
        if broken:
            raise ValueError(f"assignment: the kit's {sorted(broken)} cannot be loaded: {broken}")
        if unknown:
            raise ValueError(f"assignment: unknown {unknown}; valid choices: {sorted(kit)}")
        return [kit[n] for n in names]
    seen = {normalized(p.name) for s in roster for p in s.files}
    chosen = [a for name, a in kit.items() if name.lower() in seen]
    if not chosen:
        raise ValueError("assignment: no submitted file is named after an assignment of the kit; "
                         f"pass --assignment with one of {sorted(kit)}")
    return chosen


def _local(tasks: list[Task], runtime: Runtime, kit, limits: Limits, jobs: int | None):
    """``(index, rows)`` of each task as it finishes, graded by a pool of threads here
    (each thread drives one sandboxed worker process)."""
    with ThreadPoolExecutor(max_workers=jobs or os.cpu_count() or 1) as pool:
        futures = {pool.submit(_call_grade_task, t, runtime, kit, limits): i for i, t in enumerate(tasks)}
        try:
            for future in as_completed(futures):
                yield futures[future], future.result()
        finally:
            for f in futures:
                f.cancel()


def _call_grade_task(task, runtime, kit, limits):
    return grade_task(task, runtime, kit, limits)  # looked up at call time (tests replace it)


def _header(kit, expected: list[Assignment], limits: Limits) -> dict:
    from dataclasses import asdict

    from .journal import grading_modules, library_files, library_fingerprint

    code = library_files(grading_modules(sorted({a.check_module for a in expected})))
    return {"library": library_fingerprint(code), "limits": asdict(limits),
            "assignments": {a.name: [[e.name, e.check, e.points] for e in a.exercises] for a in expected},
            "ids": {a.name: sorted(a.cell_ids) for a in expected}}


def grade_class(paths: list[Path], out_csv: Path, *, solutions: Path | None = None,
                assignments: list[str] | None = None, limits: Limits | None = None,
                jobs: int | None = None, feedback_dir: Path | None = None,
                report: Path | None = None, progress: bool = True,
                only: list[str] | None = None, scheduler=None, resume: bool = True) -> list[Row]:
    """Grade every student under ``paths``; write the CSV, feedback files and class report.

    ``only`` restricts the run to these students (to regrade a few). ``scheduler`` (the
    address of a ``dask.distributed`` scheduler, or a ``distributed.Client``) grades each
    submission as one task on that cluster (:mod:`.cluster`); without it, ``jobs`` threads
    here each drive one sandboxed worker. Either way this process alone writes the
    gradebook, and the journal (:mod:`.journal`) lets an interrupted run resume: with
    ``resume`` (the default) submissions an earlier interrupted run graded are not graded
    again. Returns the rows (one per student, assignment and exercise), sorted.
    """
    if isinstance(scheduler, str):  # an address: connect before anything is written
        from .cluster import connect

        with connect(scheduler) as client:
            return grade_class(paths, out_csv, solutions=solutions, assignments=assignments, limits=limits,
                               jobs=jobs, feedback_dir=feedback_dir, report=report, progress=progress,
                               only=only, scheduler=client, resume=resume)
    from .journal import Journal, file_digest

    kit = load_kit(solutions or default_solutions())
    roster = students([Path(p) for p in paths])
    if only:
        missing = sorted(set(only) - {s.name for s in roster})
        if missing:
            raise ValueError(f"student: {missing} not found; valid: {[s.name for s in roster][:20]}")
        roster = [s for s in roster if s.name in only]
    expected = _assignments(roster, kit, assignments)
    tasks = [Task(s.name, a, (c := choose(s, a, kit)).path, c.note) for s in roster for a in expected]
    limits = limits or Limits()
    out_csv = Path(out_csv)
    out_csv.parent.mkdir(parents=True, exist_ok=True)
    journal = Journal(out_csv, _header(kit, expected, limits))
    earlier = journal.load() if resume else {}
    digests = [file_digest(t.path, t.note) for t in tasks]
    kept, todo = [], []
    for i, t in enumerate(tasks):
        key = (t.student, t.assignment.name)
        if key in earlier and earlier[key][0] == digests[i]:
            kept.append((key, digests[i], earlier[key][1]))
        else:
            todo.append(i)
    journal.start(kept)
    if kept:
        print(f"resuming: {len(kept)} of {len(tasks)} submissions were graded by an interrupted run "
              f"({journal.path.name}); grading the other {len(todo)}", file=sys.stderr)
    rows: list[Row] = [r for _, _, rs in kept for r in rs]
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(tasks), initial=len(kept), unit="notebook", desc="grading", file=sys.stderr)
    runtime = results = None
    try:
        with out_csv.open("w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=FIELDS)
            writer.writeheader()
            writer.writerows(r.csv() for r in rows)
            fh.flush()
            pending = [tasks[i] for i in todo]
            if scheduler is not None:
                from .cluster import grade_on_cluster

                results = grade_on_cluster(pending, kit, limits, scheduler)
            else:
                runtime = Runtime()
                if not runtime.landlock:
                    warnings.warn("this kernel has no Landlock: student code runs with the resource limits "
                                  "but can read and write any file the grader's user can (see "
                                  "docs/INSTRUCTORS.md)", stacklevel=2)
                results = _local(pending, runtime, kit, limits, jobs)
            seen: set[int] = set()
            for j, done in results:
                if j in seen:  # a task the cluster ran twice: its first result stands
                    continue
                seen.add(j)
                task = pending[j]
                journal.append((task.student, task.assignment.name), digests[todo[j]], done)
                rows += done
                writer.writerows(r.csv() for r in done)
                fh.flush()
                if bar:
                    bar.update()
    finally:
        if results is not None:
            results.close()  # cancels what has not started (on an interruption)
        if bar:
            bar.close()
        journal.close()
        if runtime is not None:
            runtime.cleanup()
    order = {a.name: i for i, a in enumerate(expected)}
    ex_order = {(a.name, e.name): i for a in expected for i, e in enumerate(a.exercises)}
    rows.sort(key=lambda r: (r.student, order[r.assignment], ex_order[(r.assignment, r.exercise)]))
    tmp = out_csv.with_name(out_csv.name + ".tmp")
    with tmp.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=FIELDS)
        writer.writeheader()
        writer.writerows(r.csv() for r in rows)
    os.replace(tmp, out_csv)
    if feedback_dir is not None:
        from .feedback import write_feedback

        write_feedback(rows, Path(feedback_dir))
    if report is not None:
        from .report import write_report

        write_report(rows, Path(report), feedback_dir=feedback_dir)
    journal.remove()
    return rows


def grade_paths(paths: list[Path], out_csv: Path, **options) -> list[dict]:
    """:func:`grade_class` returning plain CSV rows (dicts)."""
    return [r.csv() for r in grade_class(paths, out_csv, **options)]


def grade_notebook(path: Path, assignment: str | None = None, **options) -> list[dict]:
    """Grade one notebook file (its assignment found from its name or content)."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        return grade_paths([Path(path)], Path(tmp) / "grades.csv", progress=False,
                           assignments=[assignment] if assignment else None, **options)

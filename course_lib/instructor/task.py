"""Grading one submission: the rows of one student's assignment, never an exception.

:func:`grade_task` reads the notebook (:mod:`.submissions`), tells which assignment it is
(:mod:`.kit`), scans it without running it (:mod:`.scan`), runs it in a sandboxed worker
(:mod:`.sandbox`) and judges the recorded values with the kit's checks
(:mod:`.verdicts`). The same function grades here (:mod:`.grade`'s pool of threads) and
on a Dask worker (:mod:`.cluster`), so both write the same rows.
Imports: the standard library and this package's modules.
"""

from __future__ import annotations

import re
import sys
import traceback
from dataclasses import dataclass
from pathlib import Path

from .kit import Assignment
from .runtime import Runtime
from .sandbox import Limits, Run, run_submission
from .scan import answer_binding, tamper_findings
from .submissions import Unreadable, read_notebook
from .verdicts import Row, judge


@dataclass
class Task:
    student: str
    assignment: Assignment
    path: Path | None
    note: str


def _rows(task: Task, status: str, message: str, **details) -> list[Row]:
    return [Row(task.student, task.assignment.name, e.name, status, e.points, message,
                str(task.path or ""), details={"note": task.note, **details})
            for e in task.assignment.exercises]


def _missing_reason(nb, run: Run, name: str) -> tuple[str, str, dict]:
    pattern = re.compile(rf"^\s*def\s+{re.escape(name)}\s*\(", re.M)
    for cell in nb.code:
        if pattern.search(cell.source):
            info = run.cells.get(cell.index, {})
            if info.get("status") in ("syntax", "error", "timeout", "killed"):
                what = {"syntax": "does not compile", "timeout": "ran out of time",
                        "killed": "stopped the process"}.get(info["status"], "raised an error")
                return ("error", f"cell {cell.index}, which defines {name}, {what}: "
                        f"{(info.get('error') or '').strip().splitlines()[-1:]}",
                        {"traceback": info.get("error") or ""})
    return "missing", f"the notebook does not define {name}()", {}


def grade_task(task: Task, runtime: Runtime, kit: dict[str, Assignment], limits: Limits) -> list[Row]:
    """Rows for one student's assignment; never raises."""
    try:
        return _grade_task(task, runtime, kit, limits)
    except Exception as exc:  # a grader bug must not lose the student: report it in the rows
        print(traceback.format_exc(), file=sys.stderr)
        return _rows(task, "error", f"internal grader error ({type(exc).__name__}: {exc}); "
                     "please report it")


def _grade_task(task: Task, runtime: Runtime, kit: dict[str, Assignment], limits: Limits) -> list[Row]:
    a = task.assignment
    if task.path is None:
        return _rows(task, "missing", task.note)
    try:
        nb = read_notebook(task.path)
    except Unreadable as exc:
        return _rows(task, "unreadable", f"{task.path.name}: {exc}")
    from .kit import identify

    found = identify(nb.cells, kit)
    if found not in (None, a.name):
        return _rows(task, "wrong-assignment", f"{task.path.name} is notebook {found}, not {a.name}")
    if not nb.code:
        return _rows(task, "missing", f"{task.path.name} has no code cells")
    findings = [str(f) for f in tamper_findings(nb.cells)]
    bindings = {e.name: answer_binding(nb.cells, e.name, a.check(e)) for e in a.exercises}
    run = run_submission(runtime, task.path, nb.code, a.check_module, a.exercises, limits)
    shared = {"note": "; ".join(filter(None, [task.note, nb.note])), "run": run, "notebook": nb,
              "findings": findings}
    results = []
    for e in a.exercises:
        record = run.exercises.get(e.name)
        details: dict = {}
        if run.setup_error:
            status, message = "error", f"the grader could not run the notebook: {run.setup_error}"[:400]
        elif record is None:
            status = "timeout" if run.out_of_time else "error"
            message = (f"the notebook used up its {limits.deadline:g} s before this exercise was checked"
                       if run.out_of_time else "the notebook's process stopped before this exercise")
        elif record.get("lost"):
            status = "timeout" if record.get("timeout") else "error"
            message = f"while checking {e.name}: {record['lost']}"
        elif not record.get("found"):
            status, message, details = _missing_reason(nb, run, e.name)
        elif not record.get("callable"):
            status, message = "error", f"{e.name} is a {record.get('type')}, not a function"
        else:
            status, message, details = judge(a.check(e), record, limits.exercise_s)
            itself = str(record.get("module", "")).startswith("course_lib")
            reference = bindings[e.name].reference or (
                f"uses the reference: {e.name} is a course_lib function" if itself else None) or (
                record.get("library") if str(record.get("library", "")).startswith("uses the reference")
                else None)
            if reference and status in ("correct", "incorrect", "error"):
                status, message = "incorrect", reference
        results.append((e, status, message, details))
    evidence = [run.violation] if run.violation else findings + run.changes
    evidence += [f"{e.name}: {message.removeprefix('tampering: ')}"
                 for e, status, message, _ in results if status == "tampered"]
    rows = []
    for e, status, message, details in results:
        if evidence and (status != "tampered" or run.violation or findings or run.changes):
            more = len(evidence) - 1
            message = (f"tampering: {evidence[0]}" + (f" (and {more} more)" if more > 0 else "")
                       + f"; without it the verdict would be: {status}")
            status = "tampered"
        counts = details.get("counts", (0, 0))
        details["cell"] = bindings[e.name].cell
        rows.append(Row(task.student, a.name, e.name, status, e.points, message, str(task.path),
                        counts[0], counts[1], details={**shared, **details, "changes": run.changes}))
    return rows

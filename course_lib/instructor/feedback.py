"""Feedback for each student: a Markdown page and an annotated copy of each notebook.

``<dir>/<student>.md`` lists, per assignment, every exercise with its verdict and points,
then for each exercise the cases the check passed and failed with their hints, the error
that stopped it (the student's part of the traceback), what the function printed, and
notes about running the notebook (cells that raised or were stopped, output cut short,
tampering found). ``<dir>/<student>/<assignment>.ipynb`` is the submitted notebook with
what each cell printed or raised in the grader's run, and the grader's verdict in a
Markdown cell after each exercise. Imports: nbformat, the standard library.
"""

from __future__ import annotations

import re
from collections import defaultdict
from pathlib import Path

import nbformat

from .verdicts import Row

ICONS = {"correct": "✓", "incorrect": "✗", "pending": "○", "error": "💥", "timeout": "⌛",
         "missing": "❔", "tampered": "🚫", "wrong-assignment": "🔀", "unreadable": "📄"}


def safe_name(name: str) -> str:
    """A student or assignment name usable as a file name."""
    return re.sub(r"[^\w.-]", "_", name).strip(".") or "_"


def _fence(text: str, limit: int = 3000) -> str:
    text = text.rstrip()
    if len(text) > limit:
        text = text[:limit] + "\n… (cut)"
    return "```text\n" + text.replace("```", "ʼʼʼ") + "\n```\n"


def _exercise_section(row: Row) -> list[str]:
    d = row.details
    out = [f"### {row.exercise} — {ICONS.get(row.status, '')} {row.status}", "", row.message, ""]
    for case in d.get("passed_cases", []):
        out.append(f"- ✓ {case}")
    for case in d.get("failed_cases", []):
        first, *rest = case.splitlines()
        out.append(f"- ✗ {first}")
        out += [f"  {line.strip()}" for line in rest]
    if d.get("passed_cases") or d.get("failed_cases"):
        out.append("")
    if d.get("traceback"):
        out += ["Where it stopped:", "", _fence(d["traceback"])]
    if d.get("output"):
        cut = f" ({d['dropped']} more characters not kept)" if d.get("dropped") else ""
        out += [f"Your function printed{cut}:", "", _fence(d["output"], 1500)]
    return out


def _notes(rows: list[Row]) -> list[str]:
    d = rows[0].details
    run = d.get("run")
    notes = [d["note"]] if d.get("note") else []
    notes += [f"tampering found: {f}" for f in d.get("findings", [])]
    notes += [f"changed while running: {c}" for c in d.get("changes", [])]
    if run is not None:
        for index, info in sorted(run.cells.items()):
            if info.get("status") not in (None, "ok"):
                last = (info.get("error") or "").strip().splitlines()[-1:] or [""]
                notes.append(f"cell {index}: {info['status']} — {last[0]}")
            if info.get("dropped"):
                notes.append(f"cell {index}: printed {info['dropped']} characters more than kept")
        notes += run.notes
    return notes


def student_markdown(student: str, rows: list[Row]) -> str:
    """The feedback page of one student."""
    by_assignment: dict[str, list[Row]] = defaultdict(list)
    for r in rows:
        by_assignment[r.assignment].append(r)
    lines = [f"# Feedback for {student}", "", "| assignment | points |", "|---|---|"]
    for name, rs in by_assignment.items():
        lines.append(f"| {name} | {sum(r.points for r in rs)} / {sum(r.possible for r in rs)} |")
    for name, rs in by_assignment.items():
        lines += ["", f"## {name} — {sum(r.points for r in rs)} / {sum(r.possible for r in rs)} points", ""]
        if rs[0].file:
            lines += [f"Graded file: `{Path(rs[0].file).name}`", ""]
        lines += ["| exercise | verdict | points |", "|---|---|---|"]
        lines += [f"| `{r.exercise}` | {ICONS.get(r.status, '')} {r.status} | {r.points} / {r.possible} |"
                  for r in rs]
        lines.append("")
        if len({(r.status, r.message) for r in rs}) == 1 and not rs[0].details.get("failed_cases"):
            lines += [f"{ICONS.get(rs[0].status, '')} {rs[0].message}", ""]  # one verdict for all
        else:
            for r in rs:
                lines += _exercise_section(r)
        notes = _notes(rs)
        if notes:
            lines += ["### Notes on running your notebook", ""] + [f"- {n}" for n in notes] + [""]
    return "\n".join(lines) + "\n"


def annotated_notebook(rows: list[Row]) -> nbformat.NotebookNode | None:
    """The submission with the grader's outputs and verdicts, or None if it was not run."""
    d = rows[0].details
    nb_in, run = d.get("notebook"), d.get("run")
    if nb_in is None or run is None:
        return None
    verdict_after: dict[int, list[Row]] = defaultdict(list)
    for r in rows:
        if r.details.get("cell") is not None:
            verdict_after[r.details["cell"]].append(r)
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    for cell in nb_in.cells:
        if cell.kind == "code":
            new = nbformat.v4.new_code_cell(cell.source)
            info = run.cells.get(cell.index, {})
            if info.get("output"):
                new.outputs.append(nbformat.v4.new_output("stream", name="stdout", text=info["output"]))
            if info.get("status") not in (None, "ok"):
                trace = (info.get("error") or "").splitlines()
                new.outputs.append(nbformat.v4.new_output("error", ename=str(info["status"]), evalue="",
                                                          traceback=trace))
        elif cell.kind == "markdown":
            new = nbformat.v4.new_markdown_cell(cell.source)
        else:
            new = nbformat.v4.new_raw_cell(cell.source)
        nb.cells.append(new)
        for r in verdict_after.get(cell.index, []):
            nb.cells.append(nbformat.v4.new_markdown_cell(
                f"**Grader — `{r.exercise}`: {ICONS.get(r.status, '')} {r.status}** "
                f"({r.points} / {r.possible})\n\n{r.message}"))
    return nb


def write_feedback(rows: list[Row], directory: Path) -> list[Path]:
    """Write every student's Markdown page and annotated notebooks; return the pages."""
    directory.mkdir(parents=True, exist_ok=True)
    by_student: dict[str, list[Row]] = defaultdict(list)
    for r in rows:
        by_student[r.student].append(r)
    pages = []
    for student, rs in by_student.items():
        page = directory / f"{safe_name(student)}.md"
        page.write_text(student_markdown(student, rs), encoding="utf-8")
        pages.append(page)
        per_assignment: dict[str, list[Row]] = defaultdict(list)
        for r in rs:
            per_assignment[r.assignment].append(r)
        for assignment, ars in per_assignment.items():
            nb = annotated_notebook(ars)
            if nb is not None:
                folder = directory / safe_name(student)
                folder.mkdir(exist_ok=True)
                nbformat.write(nb, folder / f"{safe_name(assignment)}.ipynb")
    return pages

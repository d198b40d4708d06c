"""Grade submitted notebooks by running them and reading the exercise checks' verdicts.

Each submission is executed in a fresh kernel with errors allowed (a broken cell costs
only the exercises that depend on it); a final cell, added by the grader, prints
:func:`course_lib.check.summary` as JSON. Points are awarded per exercise whose check
passed all cases.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import nbformat

_SUMMARY_CELL = (
    "import json as _json\n"
    "from course_lib import check as _check\n"
    "print('@@GRADE@@' + _json.dumps(_check.summary()))"
)


def grade_notebook(path: Path, timeout: int = 120) -> dict[str, dict]:
    """Execute one submission and return ``{exercise: verdict}`` from its checks."""
    from nbclient import NotebookClient

    path = Path(path)
    nb = nbformat.read(path, as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell(_SUMMARY_CELL))
    client = NotebookClient(
        nb, timeout=timeout, kernel_name="python3", allow_errors=True, extra_arguments=["--log-level=ERROR"],
        resources={"metadata": {"path": str(path.parent)}},
    )
    client.execute()
    for out in nb.cells[-1].get("outputs", []):
        text = out.get("text", "")
        if "@@GRADE@@" in text:
            return json.loads(text.split("@@GRADE@@", 1)[1])
    raise RuntimeError(f"{path}: the grading cell printed nothing (did the kernel die?)")


def grade_paths(paths: list[Path], out_csv: Path) -> list[dict]:
    """Grade every notebook under ``paths`` (files or folders); write one CSV row per exercise.

    Returns the rows: submission, exercise, status, cases passed/total, points earned/possible.
    """
    files: list[Path] = []
    for p in map(Path, paths):
        files += sorted(p.rglob("*.ipynb")) if p.is_dir() else [p]
    files = [f for f in files if ".ipynb_checkpoints" not in f.parts]
    rows = []
    for f in files:
        for exercise, verdict in grade_notebook(f).items():
            earned = verdict["points"] if verdict["status"] == "correct" else 0
            rows.append({
                "submission": str(f), "exercise": exercise, "status": verdict["status"],
                "passed": verdict["passed"], "total": verdict["total"],
                "points": earned, "possible": verdict["points"],
            })
    out_csv = Path(out_csv)
    with out_csv.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=["submission", "exercise", "status", "passed",
                                                "total", "points", "possible"])
        writer.writeheader()
        writer.writerows(rows)
    return rows

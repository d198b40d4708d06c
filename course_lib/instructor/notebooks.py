"""Generate student notebooks from solutions, and execute notebooks in place.

Solution regions follow nbgrader's markers. In a code cell::

    def step(f, t, y, dt):
        ### BEGIN SOLUTION
        return y + dt * f(t, y)
        ### END SOLUTION

becomes, in the student version::

    def step(f, t, y, dt):
        # YOUR CODE HERE
        raise NotImplementedError()

In a markdown cell the region becomes ``YOUR ANSWER HERE``. Outputs and execution counts
are cleared; cell ids are kept so the two versions stay aligned.
"""

from __future__ import annotations

import copy
import re
from pathlib import Path

import nbformat

BEGIN = "### BEGIN SOLUTION"
END = "### END SOLUTION"
_MARKER = re.compile(r"^(\s*)(### (BEGIN|END) SOLUTION)\s*$")


class MarkerError(ValueError):
    """A solution region is unpaired or nested."""


def strip_solution(source: str, *, code: bool, where: str = "cell") -> str:
    """Replace every solution region of ``source`` by the student stub."""
    out: list[str] = []
    inside = False
    for lineno, line in enumerate(source.splitlines(), 1):
        m = _MARKER.match(line)
        if m:
            indent, kind = m.group(1), m.group(3)
            if kind == "BEGIN":
                if inside:
                    raise MarkerError(f"{where}, line {lineno}: {BEGIN} inside another region")
                inside = True
                if code:
                    out += [f"{indent}# YOUR CODE HERE", f"{indent}raise NotImplementedError()"]
                else:
                    out.append(f"{indent}YOUR ANSWER HERE")
            else:
                if not inside:
                    raise MarkerError(f"{where}, line {lineno}: {END} without a {BEGIN}")
                inside = False
            continue
        if BEGIN in line or END in line:
            raise MarkerError(f"{where}, line {lineno}: a solution marker must stand alone on its line")
        if not inside:
            out.append(line)
    if inside:
        raise MarkerError(f"{where}: {BEGIN} is never closed by {END}")
    return "\n".join(out)


def make_student_notebook(nb: nbformat.NotebookNode, name: str = "notebook") -> nbformat.NotebookNode:
    """Return the student version of a solution notebook (the input is not modified)."""
    student = copy.deepcopy(nb)
    for index, cell in enumerate(student.cells):
        where = f"{name}, cell {index}"
        cell.source = strip_solution(cell.source, code=cell.cell_type == "code", where=where)
        if cell.cell_type == "code":
            cell.outputs = []
            cell.execution_count = None
            for key in ("execution", "collapsed", "scrolled"):
                cell.metadata.pop(key, None)
    student.metadata.pop("widgets", None)
    return student


def make_student_versions(solutions: Path, notebooks: Path) -> list[Path]:
    """Write the student version of every ``solutions/*.ipynb`` into ``notebooks/``.

    Student notebooks without a solution counterpart are removed, so the two folders pair.
    """
    solutions, notebooks = Path(solutions), Path(notebooks)
    notebooks.mkdir(parents=True, exist_ok=True)
    written = []
    names = set()
    for src in sorted(solutions.glob("*.ipynb")):
        nb = nbformat.read(src, as_version=4)
        dst = notebooks / src.name
        nbformat.write(make_student_notebook(nb, src.name), dst)
        written.append(dst)
        names.add(src.name)
    for stale in notebooks.glob("*.ipynb"):
        if stale.name not in names:
            stale.unlink()
    return written


def execute_notebook(path: Path, timeout: int = 300) -> None:
    """Run a notebook top to bottom in its own folder and store the outputs in place.

    Uses kernel ``python3`` and strips per-cell timing metadata, so re-executing an
    unchanged notebook changes nothing but what the code really prints. The kernelspec is
    stored as ipykernel writes it (so JupyterLab does not mark the notebook modified on
    opening it), and the notebook is signed, so the instructor's own copy opens trusted.
    """
    from nbclient import NotebookClient
    from nbformat.sign import NotebookNotary

    path = Path(path)
    nb = nbformat.read(path, as_version=4)
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3 (ipykernel)",
                                 "language": "python"}
    client = NotebookClient(
        nb, timeout=timeout, kernel_name="python3", record_timing=False,
        extra_arguments=["--log-level=ERROR"],
        resources={"metadata": {"path": str(path.parent)}},
    )
    client.execute()
    for cell in nb.cells:
        cell.metadata.pop("execution", None)
    nb.metadata.pop("widgets", None)
    NotebookNotary().sign(nb)
    nbformat.write(nb, path)


def extract_figures(path: Path, outdir: Path) -> list[Path]:
    """Save every PNG output of an executed notebook as ``outdir/<name>_cell<k>_<j>.png``,
    so figures can be looked at without a browser."""
    import base64

    path, outdir = Path(path), Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    nb = nbformat.read(path, as_version=4)
    saved = []
    for k, cell in enumerate(nb.cells):
        for j, out in enumerate(cell.get("outputs", [])):
            data = out.get("data", {})
            if "image/png" in data:
                dst = outdir / f"{path.stem}_cell{k:02d}_{j}.png"
                dst.write_bytes(base64.b64decode(data["image/png"]))
                saved.append(dst)
    return saved

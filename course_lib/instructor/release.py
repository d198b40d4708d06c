"""The student release: what students receive, with no solution text (``make release``).

:func:`build_release` writes, into a fresh folder: the student version of every solution
notebook (regenerated, so it cannot be stale), the ``course_lib`` package (its reference
implementations are part of the library students use; no notebook, cache or checkpoint
comes along), the setup files (``pyproject.toml``, ``requirements*.txt``/``.in``,
``environment.yml``, ``LICENSE``), a student ``Makefile`` (``make lab``) and a student
``README.md``. ``solutions/``, tests, benchmarks and instructor docs stay behind.

:func:`secret_lines` lists the lines of every solution region that appear nowhere in the
student notebooks; the tests scan the release for them.
Imports: nbformat, the standard library, :mod:`.notebooks`.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import nbformat

from .notebooks import BEGIN, END, make_student_notebook

MARKER = ".course-release"
SETUP_FILES = ("pyproject.toml", "requirements.txt", "requirements.in", "environment.yml", "LICENSE")

MAKEFILE = """\
# Student kit: `make lab` sets up .venv (first time only) and opens JupyterLab.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
ROOT_FLAG := $(shell [ "$$(id -u)" = 0 ] && echo --allow-root)
LAB_ARGS ?=

.PHONY: setup lab clean

setup: $(STAMP)

$(STAMP): requirements.txt pyproject.toml
\t@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
\t$(BIN)/python -m pip install --quiet --disable-pip-version-check -r requirements.txt
\t$(BIN)/python -m pip install --quiet --disable-pip-version-check --no-deps -e .
\t@touch $(STAMP)

lab: $(STAMP)
\t$(BIN)/jupyter lab --ServerApp.ip=127.0.0.1 --ServerApp.root_dir=$(CURDIR) \\
\t\t--LabApp.default_url=/lab/tree/{first} $(ROOT_FLAG) $(LAB_ARGS)

clean:
\trm -rf $(VENV) *.egg-info
"""

README = """\
# Physics-based animation: the student kit

Notebooks on particle systems and time integration, and the small library they use
(`course_lib`). You need Python 3.11 or newer and `make`.

```bash
make lab     # set up .venv (first time only), then open JupyterLab on the first notebook
```

Open the printed `http://127.0.0.1:8888/lab?token=…` link if no browser opens. Without
`make`: `python3 -m venv .venv && .venv/bin/pip install -r requirements.txt && .venv/bin/pip
install --no-deps -e . && .venv/bin/jupyter lab`.

## The notebooks

{table}

Work through them in order. Each one derives an idea, computes it and compares it with
theory; the exercises are functions to complete where a cell says `# YOUR CODE HERE`.

## Exercises and checks

- Replace `raise NotImplementedError()` with your code and run the cell: the check right
  below prints ✓ (correct, with what was verified), ✗ (what failed, with a hint for the
  usual mistake) or ○ (not attempted yet). A blank notebook runs top to bottom.
- **Write the computation yourself.** `course_lib` holds the library's own version of
  most exercises (it is what the checks compare with). An answer that calls it (for
  example `cl.forward_euler` inside `forward_euler_step`), or any function of
  `course_lib.check`, is reported as *uses the reference* and earns no points. NumPy and
  SciPy are fine, and so are the library functions the exercise text offers as tools.
- Grading runs your notebook again in a sandbox and calls your functions itself: only the
  functions you define under the exercise's name count. Printing, changing or replacing
  the checks changes nothing, and is reported as tampering.

## Handing in

Hand in each notebook under its own file name (for example `02_forward_euler.ipynb`),
saved from Jupyter, with its code cells in place. Keep the function names of the
exercises. Each exercise cell should run on its own after the first (imports) cell.
"""


def _title(nb: nbformat.NotebookNode) -> str:
    for cell in nb.cells:
        if cell.cell_type == "markdown" and cell.source.strip():
            return cell.source.strip().splitlines()[0].lstrip("# ").strip()
    return ""


def build_release(out: Path, kit: Path | None = None) -> Path:
    """Write the student release into ``out`` (replacing an earlier release there)."""
    kit = Path(kit) if kit else Path(__file__).resolve().parents[2]
    out = Path(out).resolve()
    if out == kit.resolve() or kit.resolve().is_relative_to(out):
        raise ValueError(f"out: {out} would contain the kit; choose a folder such as dist/student")
    if out.exists():
        if not (out / MARKER).exists() and any(out.iterdir()):
            raise ValueError(f"out: {out} exists and is not an earlier release; remove it or choose another")
        shutil.rmtree(out)
    (out / "notebooks").mkdir(parents=True)
    rows = []
    for src in sorted((kit / "solutions").glob("*.ipynb")):
        nb = make_student_notebook(nbformat.read(src, as_version=4), src.name)
        nbformat.write(nb, out / "notebooks" / src.name)
        rows.append(f"| `notebooks/{src.name}` | {_title(nb)} |")
    if not rows:
        raise ValueError(f"kit: no notebook in {kit / 'solutions'}")
    shutil.copytree(kit / "course_lib", out / "course_lib", ignore=shutil.ignore_patterns(
        "__pycache__", "*.pyc", ".ipynb_checkpoints", "*.ipynb", "*.egg-info"))
    for name in SETUP_FILES:
        if (kit / name).exists():
            shutil.copy2(kit / name, out / name)
    first = sorted((out / "notebooks").glob("*.ipynb"))[0]
    (out / "Makefile").write_text(MAKEFILE.replace("{first}", f"notebooks/{first.name}"))
    table = "| notebook | topic |\n|---|---|\n" + "\n".join(rows)
    (out / "README.md").write_text(README.replace("{table}", table))
    (out / MARKER).write_text("built by python -m course_lib.instructor release\n")
    return out


def solution_regions(source: str) -> list[list[str]]:
    """The lines inside each ``### BEGIN SOLUTION`` … ``### END SOLUTION`` region."""
    regions, current = [], None
    for line in source.splitlines():
        if line.strip() == BEGIN:
            current = []
        elif line.strip() == END and current is not None:
            regions.append(current)
            current = None
        elif current is not None:
            current.append(line)
    return regions


def secret_lines(solutions: Path, min_length: int = 8) -> dict[str, str]:
    """Solution-region lines (stripped) that no student notebook shows, with their notebook."""
    secrets, public = {}, set()
    for src in sorted(Path(solutions).glob("*.ipynb")):
        nb = nbformat.read(src, as_version=4)
        public |= {ln.strip() for c in make_student_notebook(nb).cells for ln in c.source.splitlines()}
        for cell in nb.cells:
            for region in solution_regions(cell.source):
                for line in region:
                    text = line.strip()
                    if len(text) >= min_length and not text.startswith("#") and re.search(r"\w", text):
                        secrets.setdefault(text, src.name)
    return {line: where for line, where in secrets.items() if line not in public}

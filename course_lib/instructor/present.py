"""``make present NB=03_stability``: a notebook's demos as a full-page app (lecture mode).

Usage::

    python -m course_lib.instructor.present 03_stability [--port 8866] [--token T]
                                            [--no-browser] [--source solutions]

Builds a *lecture notebook* from the solution notebook and serves it with Voila on
127.0.0.1 with a token. The lecture notebook holds only the demo cells: the cells tagged
``demo``, or, when none is tagged, every cell whose stored output is a live widget. Each
demo is headed by its section's title. The earlier cells a demo needs (found by the names
it uses: imports, data, helper functions) run first with their output captured, so the
page shows the demos and nothing else; Voila hides the code. Imports the standard library,
nbformat and IPython (to read cells written with ``%`` magics).
"""

from __future__ import annotations

import argparse
import ast
import builtins
import os
import re
import secrets
import shutil
import socket
import sys
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parents[2]
WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
DEMO_TAG = "demo"


#: Magics whose argument is code: their code counts when looking for names.
_CODE_MAGICS = r"(?:time|timeit|prun|capture)"


def _python(source: str) -> str:
    """The cell as plain Python: code under ``%time``-like magics unwrapped, other magics
    turned into ``get_ipython()`` calls."""
    from IPython.core.inputtransformer2 import TransformerManager

    lines = source.splitlines()
    if lines and re.match(rf"%%{_CODE_MAGICS}\b", lines[0]):
        lines = lines[1:]
    lines = [re.sub(rf"^(\s*)%{_CODE_MAGICS}\s+(?:-\S+\s+)*", r"\1", ln) for ln in lines]
    return TransformerManager().transform_cell("\n".join(lines))


def names_used_and_defined(source: str) -> tuple[set[str], set[str]]:
    """Global names a cell reads and names it binds (imports, assignments, defs)."""
    try:
        tree = ast.parse(_python(source))
    except SyntaxError:
        return set(), set()
    used, bound = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name):
            (used if isinstance(node.ctx, ast.Load) else bound).add(node.id)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            bound.update((a.asname or a.name).split(".")[0] for a in node.names)
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            bound.add(node.name)
    return used - set(dir(builtins)) - {"get_ipython"}, bound


def demo_indices(nb: nbformat.NotebookNode) -> list[int]:
    """Cells tagged ``demo``, else the code cells whose stored output is a live widget."""
    tagged = [i for i, c in enumerate(nb.cells) if DEMO_TAG in c.metadata.get("tags", [])]
    if tagged:
        return tagged
    return [i for i, c in enumerate(nb.cells) if c.cell_type == "code" and any(
        WIDGET_VIEW in out.get("data", {}) for out in c.get("outputs", []))]


def support_indices(nb: nbformat.NotebookNode, demos: list[int]) -> list[int]:
    """Earlier code cells the demos need: the first code cell (the imports) and, going
    backwards, every cell binding a name that a needed cell reads."""
    code = [i for i, c in enumerate(nb.cells) if c.cell_type == "code"]
    needed_cells = set(code[:1])
    for demo in demos:
        needed, _ = names_used_and_defined(nb.cells[demo].source)
        for i in reversed([i for i in code if i < demo]):
            used, bound = names_used_and_defined(nb.cells[i].source)
            if bound & needed:
                needed_cells.add(i)
                needed |= used
    return sorted(needed_cells - set(demos))


def _section_title(nb: nbformat.NotebookNode, index: int) -> str | None:
    for cell in reversed(nb.cells[:index]):
        if cell.cell_type == "markdown":
            heads = re.findall(r"^#{1,3}\s+.+$", cell.source, re.M)
            if heads:
                return heads[-1]
    return None


def lecture_notebook(nb: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """The notebook Voila serves: title, then each demo under its section's heading."""
    demos = demo_indices(nb)
    if not demos:
        raise ValueError("the notebook has no demo: tag cells 'demo' or store a live widget")
    support = support_indices(nb, demos)
    title = next((m.group(0) for c in nb.cells if c.cell_type == "markdown"
                  for m in [re.search(r"^#\s+.+$", c.source, re.M)] if m), "# Demo")
    cells = [nbformat.v4.new_markdown_cell(title)]
    shown_titles = {title}
    for i in sorted(set(support) | set(demos)):
        if i in demos:
            head = _section_title(nb, i)
            if head and head not in shown_titles:
                cells.append(nbformat.v4.new_markdown_cell(head))
                shown_titles.add(head)
            cells.append(nbformat.v4.new_code_cell(nb.cells[i].source))
        else:  # runs, shows nothing
            # %%capture hides what the cell prints; closing its figures keeps the inline
            # backend from showing them once the cell is done
            cells.append(nbformat.v4.new_code_cell(
                f"%%capture\n{nb.cells[i].source}\n__import__('matplotlib.pyplot').pyplot.close('all')"))
    lecture = nbformat.v4.new_notebook(cells=cells, metadata=nb.metadata)
    lecture.metadata.pop("widgets", None)
    return lecture


def find_notebook(name: str, source: Path) -> Path:
    """``03_stability``, ``03`` or a path, resolved to a notebook in ``source``."""
    path = Path(name)
    if path.suffix == ".ipynb" and path.exists():
        return path
    candidates = sorted(Path(source).glob(f"{path.stem}*.ipynb"))
    if len(candidates) != 1:
        choices = [p.stem for p in sorted(Path(source).glob("[0-9][0-9]_*.ipynb"))]
        raise ValueError(f"NB={name!r} names {len(candidates)} notebooks in {source}; "
                         f"choose one of {choices}")
    return candidates[0]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def voila_command(notebook: Path, port: int, token: str, *, browser: bool = False) -> list[str]:
    """The Voila command line: localhost, a token, the light theme."""
    voila = shutil.which("voila", path=str(Path(sys.executable).parent)) or "voila"
    return [voila, str(notebook), f"--port={port}", "--Voila.ip=127.0.0.1", f"--token={token}",
            "--theme=light", "--template=course", *([] if browser else ["--no-browser"])]


def voila_env() -> dict:
    """The environment for Voila: the course's settings (jupyter_config/voila.py) and its
    page template (jupyter_data/voila/templates/course: Voila's "lab" page without the CDN
    stylesheets and the Mermaid loader) first."""
    config, data = os.environ.get("JUPYTER_CONFIG_PATH"), os.environ.get("JUPYTER_PATH")
    return {**os.environ,
            "JUPYTER_CONFIG_PATH": os.pathsep.join(filter(None, [str(ROOT / "jupyter_config"), config])),
            "JUPYTER_PATH": os.pathsep.join(filter(None, [str(ROOT / "jupyter_data"), data]))}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m course_lib.instructor.present",
                                     description="Serve a notebook's demos with Voila.")
    parser.add_argument("notebook", nargs="?", help="e.g. 03_stability")
    parser.add_argument("--source", type=Path, default=ROOT / "solutions")
    parser.add_argument("--out", type=Path, default=ROOT / "build" / "present")
    parser.add_argument("--port", type=int, default=0, help="default: a free port")
    parser.add_argument("--token", default=None, help="default: a random token")
    parser.add_argument("--no-browser", dest="browser", action="store_false")
    args = parser.parse_args(argv)
    try:
        if not args.notebook:
            raise ValueError("say which notebook, e.g. `make present NB=03_stability`")
        src = find_notebook(args.notebook, args.source)
        nb = nbformat.read(src, as_version=4)
        lecture = lecture_notebook(nb)
    except ValueError as exc:
        print(f"present: {exc}", file=sys.stderr)
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    dst = args.out / src.name
    from nbformat.sign import NotebookNotary

    NotebookNotary().sign(lecture)  # our own notebook: trusted (Voila would warn otherwise)
    nbformat.write(lecture, dst)
    port, token = args.port or free_port(), args.token or secrets.token_urlsafe(24)
    print(f"present: {src.name}, {len(demo_indices(nb))} demo cell(s); open\n"
          f"    http://127.0.0.1:{port}/?token={token}\n(Ctrl-C to stop)", flush=True)
    cmd = voila_command(dst, port, token, browser=args.browser)
    os.execve(cmd[0], cmd, voila_env())  # Voila takes over this process (and Ctrl-C)


if __name__ == "__main__":
    sys.exit(main())

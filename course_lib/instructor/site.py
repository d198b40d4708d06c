"""``make site``: a static, offline HTML site of the executed solution notebooks.

Usage::

    python -m course_lib.instructor.site [--out build/site] [--only 03_stability ...]
                                         [--no-execute] [--with-solutions] [--jobs 2]

Each solution notebook is executed afresh (so the widgets' state is stored and their
controls and last picture show on the page), a kernel-free explorer is added beside a
widget that has none yet (:mod:`course_lib.lessons.kernel_free`), exercise answers are
hidden unless ``--with-solutions``, and the page is written by
:mod:`course_lib.instructor.site_pages`. JavaScript and fonts are vendored from npm into
``_static`` (:mod:`course_lib.instructor.site_assets`); the build fails if any page would
load an asset from the network. ``--no-execute`` uses the stored outputs (faster; widgets
without stored state are left out). Imports nbformat, nbclient and the site modules.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import nbformat

from . import site_assets, site_pages

ROOT = Path(__file__).resolve().parents[2]
WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
#: An asset (script, style, image, frame) loaded from another host: not allowed on the site.
REMOTE_ASSET = re.compile(
    r"<(?:script|link|img|iframe|source|audio|video)\b[^>]*?\b(?:src|href)\s*=\s*[\"']?"
    r"(?:https?:)?//", re.I)


def execute(path: Path, timeout: int = 600) -> nbformat.NotebookNode:
    """Run a notebook in its own folder and return it with outputs and widget state."""
    from nbclient import NotebookClient

    nb = nbformat.read(path, as_version=4)
    NotebookClient(nb, timeout=timeout, kernel_name="python3", record_timing=False,
                   store_widget_state=True, extra_arguments=["--log-level=ERROR"],
                   resources={"metadata": {"path": str(Path(path).parent)}}).execute()
    return nb


def _execute_json(path: str, timeout: int) -> str:
    """The executed notebook as JSON, or ``"error: ..."`` naming the failing cell."""
    from nbclient.exceptions import CellExecutionError, CellTimeoutError

    try:
        return nbformat.writes(execute(Path(path), timeout))
    except (CellExecutionError, CellTimeoutError) as exc:
        parts = str(exc).split("------------------\n")  # message, cell source, output
        source = parts[1].strip().splitlines()[0][:70] if len(parts) > 1 else "?"
        what = f"{getattr(exc, 'ename', type(exc).__name__)} {getattr(exc, 'evalue', '')}"
        return f"error: {Path(path).stem}: {what.strip()} in the cell starting {source!r}"


def has_player(nb: nbformat.NotebookNode) -> bool:
    """Whether some output already holds a kernel-free parameter player."""
    return any('data-kind="parameter"' in str(out.get("data", {}).get("text/html", ""))
               for cell in nb.cells if cell.cell_type == "code" for out in cell.outputs)


def add_player(nb: nbformat.NotebookNode, stem: str) -> bool:
    """Give the notebook its kernel-free explorer, if it has a player in
    :data:`course_lib.lessons.kernel_free.PLAYERS` and none in its outputs: a cell that
    calls the player but holds no output (a notebook not executed) gets the player as
    its output; without such a cell, one is inserted after the first widget cell."""
    from course_lib.lessons import kernel_free

    make = kernel_free.PLAYERS.get(stem)
    if make is None or has_player(nb):
        return False
    call = f"kernel_free.{make.__name__}("
    cell = next((c for c in nb.cells if c.cell_type == "code" and call in c.source), None)
    where = next((i for i, c in enumerate(nb.cells) if c.cell_type == "code" and any(
        WIDGET_VIEW in out.get("data", {}) for out in c.outputs)), None)
    if cell is None and where is None:
        return False
    import matplotlib

    matplotlib.use("agg")
    from course_lib.plotting import use_course_style

    use_course_style()
    player = make()
    if cell is None:
        cell = nbformat.v4.new_code_cell(
            f"# NBVAL_IGNORE_OUTPUT\nfrom course_lib.lessons import kernel_free\n"
            f"kernel_free.{make.__name__}()")
        nb.cells.insert(where + 1, cell)
    cell.outputs = [nbformat.v4.new_output(
        "execute_result", {"text/html": player.html, "text/plain": repr(player)},
        execution_count=None)]
    return True


def check_offline(folder: Path) -> list[str]:
    """Every page of ``folder`` that loads a script, style or image from another host."""
    return [str(p) for p in sorted(Path(folder).glob("*.html"))
            if REMOTE_ASSET.search(p.read_text(encoding="utf-8"))]


def build(out: Path, source: Path, *, only=None, run: bool = True, solutions: bool = False,
          jobs: int = 1, readme: Path | None = None, log=print) -> list[Path]:
    """Build the site into ``out`` (emptied first); return the pages written, index first."""
    out, source = Path(out), Path(source)
    paths = sorted(source.glob("[0-9][0-9]_*.ipynb"))
    if only:
        wanted = {Path(n).stem for n in only}
        unknown = wanted - {p.stem for p in paths}
        if unknown:
            raise ValueError(f"--only: no notebook {sorted(unknown)} in {source}; "
                             f"choose among {[p.stem for p in paths]}")
        paths = [p for p in paths if p.stem in wanted]
    if out.exists():
        shutil.rmtree(out)
    site_assets.copy_assets(out / "_static")
    log(f"assets vendored into {out / '_static'}")
    t0 = time.perf_counter()
    if run:
        with ProcessPoolExecutor(max_workers=max(1, jobs)) as pool:
            texts = list(pool.map(_execute_json, [str(p) for p in paths], [600] * len(paths)))
        failed = [t[len("error: "):] for t in texts if t.startswith("error: ")]
        if failed:
            raise RuntimeError("not published, these notebooks do not run:\n  " +
                               "\n  ".join(failed) + "\n(`make execute NB=...` shows the error)")
        notebooks = [nbformat.reads(t, as_version=4) for t in texts]
        log(f"executed {len(paths)} notebooks in {time.perf_counter() - t0:.0f} s")
    else:
        notebooks = [nbformat.read(p, as_version=4) for p in paths]
    pages = [(p.stem, site_pages.title_of(nb, p.stem)) for p, nb in zip(paths, notebooks, strict=True)]
    written = []
    for (stem, _), nb in zip(pages, notebooks, strict=True):
        if add_player(nb, stem):
            log(f"{stem}: added its kernel-free explorer (the notebook has none yet)")
        dropped = site_pages.drop_stateless_widgets(nb)
        page_nb = nb if solutions else site_pages.reader_version(nb, stem)
        dst = out / f"{stem}.html"
        dst.write_text(site_pages.notebook_page(page_nb, stem, site_pages.nav_html(pages, stem)),
                       encoding="utf-8")
        written.append(dst)
        note = f", {dropped} widget view(s) without stored state left out" if dropped else ""
        log(f"{dst.name}: {dst.stat().st_size / 1e6:.2f} MB{note}")
    index = out / "index.html"
    index.write_text(site_pages.index_page(readme or ROOT / "README.md", pages, solutions=solutions),
                     encoding="utf-8")
    remote = check_offline(out)
    if remote:
        raise RuntimeError(f"these pages load assets from the network: {remote}")
    return [index, *written]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m course_lib.instructor.site",
                                     description="Build the static course site (offline).")
    parser.add_argument("--out", type=Path, default=ROOT / "build" / "site")
    parser.add_argument("--source", type=Path, default=ROOT / "solutions")
    parser.add_argument("--only", nargs="+", metavar="NOTEBOOK", help="e.g. 03_stability")
    parser.add_argument("--no-execute", dest="run", action="store_false",
                        help="use the stored outputs instead of executing the notebooks")
    parser.add_argument("--with-solutions", dest="solutions", action="store_true",
                        help="publish the exercise answers too (default: hidden)")
    parser.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1),
                        help="notebooks executed at once")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    try:
        pages = build(args.out, args.source, only=args.only, run=args.run,
                      solutions=args.solutions, jobs=args.jobs)
    except (site_assets.AssetError, ValueError, RuntimeError) as exc:
        print(f"site: {exc}", file=sys.stderr)
        return 1
    print(f"site: {len(pages)} pages in {args.out} ({time.perf_counter() - t0:.0f} s); "
          f"open {pages[0]} in a browser, or publish the folder as is")
    return 0


if __name__ == "__main__":
    sys.exit(main())

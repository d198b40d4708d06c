"""Shared helpers for tests that read the course notebooks."""

from __future__ import annotations

import re
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parents[1]
SOLUTIONS = sorted((ROOT / "solutions").glob("*.ipynb"))
CHECK_IMPORT = re.compile(r"from course_lib\.check import (nb\d+)")


def read(path: Path) -> nbformat.NotebookNode:
    return nbformat.read(path, as_version=4)


def code_cells(nb) -> list:
    return [c for c in nb.cells if c.cell_type == "code" and c.source.strip()]


def check_module(nb) -> str | None:
    for cell in code_cells(nb):
        m = CHECK_IMPORT.search(cell.source)
        if m:
            return m.group(1)
    return None

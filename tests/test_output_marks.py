"""Every stored output, and every source line, of the solutions and the student versions
uses marks that every font draws (no colour-emoji code points): read from the files, so
it covers every notebook and every cell, not only the ones the browser tests open.

The browser tests check the outputs a widget draws live (tests/browser/test_browser_lab.py).
"""

from __future__ import annotations

import nbformat
import pytest
from notebook_helpers import ROOT
from output_marks import EMOJI, emoji_in

NOTEBOOKS = sorted((ROOT / "solutions").glob("*.ipynb")) + sorted((ROOT / "notebooks").glob("*.ipynb"))


def stored_text(cell) -> str:
    parts = [cell.source]
    for out in cell.get("outputs", []):
        parts.append(str(out.get("text", "")))
        for mime, value in out.get("data", {}).items():
            if mime.startswith("text/"):
                parts.append(value if isinstance(value, str) else "".join(value))
    return "".join(parts)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_no_emoji_only_marks(path):
    nb = nbformat.read(path, as_version=4)
    found = {i: emoji_in(stored_text(c)) for i, c in enumerate(nb.cells)}
    found = {i: m for i, m in found.items() if m}
    assert not found, f"{path.name}: cells use emoji-only marks (empty boxes without an emoji font): {found}"


def test_the_pattern_catches_what_it_should():
    assert emoji_in("stable ✅ and ❌ 🚀") == ["✅", "❌", "🚀"]
    assert not EMOJI.search("stable ✓ unstable ✗ pending ○ → ≤ ± × π Δt ω² · – —")


@pytest.mark.parametrize("path", sorted((ROOT / "solutions").glob("*.ipynb")), ids=lambda p: p.stem)
def test_no_stored_error_or_warning(path):
    """A solution stores no error and no stderr (a warning): strict nbval then fails on
    any new stderr in a compared cell, so Run All stays clean without a browser."""
    nb = nbformat.read(path, as_version=4)
    bad = [(i, o.get("name", o.output_type)) for i, c in enumerate(nb.cells)
           for o in c.get("outputs", [])
           if o.output_type == "error" or (o.output_type == "stream" and o.get("name") == "stderr")]
    assert not bad, f"{path.name}: stored errors or stderr in cells {bad}"

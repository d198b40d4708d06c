"""The showcase animation of every notebook, and rendering them into clips.

:func:`showcases` maps each notebook's number (``"01"`` ... ) to a :class:`Showcase`: the
function that builds that notebook's ``matplotlib.animation.Animation``. Notebooks 01-11
have theirs in :mod:`.showcase_scenes`. A lesson module ``course_lib/lessons/nbNN_*.py``
that defines a module-level ``showcase_animation()`` joins the registry by itself (found
by reading the file, not by importing it) and takes precedence for its notebook, so a new
notebook's author adds a showcase without editing this module.

:func:`render_showcases` builds each (or some) and saves it with
:func:`course_lib.clips.save_clip` as ``<out>/NN_<topic>.mp4`` (or ``.gif``); it is
what ``make clips`` and ``python -m course_lib.instructor clips`` run.
"""

from __future__ import annotations

import ast
import importlib
import re
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
#: The notebooks 01-11 by number: their name and their builder in :mod:`.showcase_scenes`.
BUILT_IN = {"01": "01_vector_fields", "02": "02_forward_euler", "03": "03_stability",
            "04": "04_beyond_euler", "05": "05_newtons_second_law", "06": "06_forces",
            "07": "07_springs", "08": "08_hair_chains", "09": "09_particle_systems",
            "10": "10_flocking", "11": "11_cloth"}
_LESSON = re.compile(r"^nb(\d\d)_(\w+)\.py$")


@dataclass(frozen=True)
class Showcase:
    """Where a notebook's showcase animation comes from."""

    number: str
    name: str
    module: str
    function: str

    def build(self, **options):
        """The animation (a new one at each call)."""
        return getattr(importlib.import_module(self.module), self.function)(**options)


def _defines_showcase(path: Path) -> bool:
    try:
        tree = ast.parse(path.read_bytes())
    except (OSError, SyntaxError, ValueError):
        return False
    return any(isinstance(node, ast.FunctionDef) and node.name == "showcase_animation" for node in tree.body)


def showcases() -> dict[str, Showcase]:
    """Every notebook's showcase by number, sorted (see the module docstring)."""
    found = {number: Showcase(number, name, f"{__package__}.showcase_scenes", f"nb{number}")
             for number, name in BUILT_IN.items()}
    for path in sorted(HERE.glob("nb[0-9][0-9]_*.py")):
        match = _LESSON.match(path.name)
        if match and _defines_showcase(path):
            number = match.group(1)
            name = BUILT_IN.get(number) or _notebook_name(number) or f"{number}_{match.group(2)}"
            found[number] = Showcase(number, name, f"{__package__}.{path.stem}", "showcase_animation")
    return dict(sorted(found.items()))


def _notebook_name(number: str) -> str | None:
    """The kit's notebook of that number (``solutions/NN_*.ipynb`` beside the package), if any."""
    names = sorted(p.stem for p in (HERE.parents[1] / "solutions").glob(f"{number}_*.ipynb"))
    return names[0] if names else None


def select(only=None) -> list[Showcase]:
    """The showcases asked for: numbers (``8``, ``"08"``) or names (``08_hair_chains``)."""
    table = showcases()
    if not only:
        return list(table.values())
    chosen = []
    for item in only:
        key = str(item).strip()
        hit = table.get(key.zfill(2)) if key.isdigit() else next(
            (s for s in table.values() if s.name == key or s.name.startswith(key)), None)
        if hit is None:
            raise ValueError(f"only: no showcase for {item!r}; valid choices: "
                             f"{[s.number for s in table.values()]} or {[s.name for s in table.values()]}")
        chosen.append(hit)
    return chosen


def render_showcases(out: Path, only=None, fmt: str = "mp4", dpi: float | None = None,
                     progress: bool = True) -> list[Path]:
    """Build and save each chosen showcase as ``out/<name>.<fmt>``; return the paths."""
    from ..clips import save_clip

    if fmt not in ("mp4", "gif"):
        raise ValueError(f"fmt: unknown clip format {fmt!r}; valid choices: ['gif', 'mp4']")
    written = []
    for showcase in select(only):
        anim = showcase.build()
        written.append(save_clip(anim, Path(out) / f"{showcase.name}.{fmt}", dpi=dpi, progress=progress))
    return written

"""Notebook 08, sixth read: the dashed slope guides of cell 11 sit a decade below the data
they match (the slope-4 guide was drawn on the planar curl and hid it), as notebook 05's do."""

import re

import numpy as np
from notebook_helpers import ROOT, markdown, read

from course_lib.lessons import nb08_hair_chains as lesson

NAME = "08_hair_chains.ipynb"


def guide_levels() -> dict[int, float]:
    """{slope: level} of the guides ``level * angles**slope`` the twist-energy cell draws."""
    nb = read(ROOT / "solutions" / NAME)
    (cell,) = [c.source for c in nb.cells if c.cell_type == "code" and "twist_energy" in c.source]
    found = re.findall(r"ax_e\.loglog\(angles, ([0-9.e+-]+) \* angles\*\*(\d)", cell)
    return {int(p): float(level) for level, p in found}


def test_the_guides_sit_a_decade_below_the_data_they_match():
    levels = guide_levels()
    assert sorted(levels) == [2, 4]
    shapes = lesson.twist_shapes()
    angles = np.geomspace(1e-3, 0.3, 24)
    energy = {name: lesson.twist_energy(shapes[name], angles)
              for name in ("planar curl", "zigzag", "helix")}
    # each guide is a decade (between 0.05 and 0.2) below the lowest curve of its slope, at
    # every angle: close enough to compare slopes by eye, far enough to hide nothing
    for slope, lowest in ((2, energy["helix"]), (4, np.minimum(energy["planar curl"], energy["zigzag"]))):
        ratio = levels[slope] * angles**slope / lowest
        assert np.all((0.05 < ratio) & (ratio < 0.2)), (slope, ratio.min(), ratio.max())


def test_the_prose_says_where_the_guides_are():
    for folder in ("solutions", "notebooks"):
        text = re.sub(r"\s+", " ", markdown(NAME, folder))
        assert ("the dashed guides, a decade below the helix and the planar curl, have slopes "
                "2 and 4") in text

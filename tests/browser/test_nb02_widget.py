"""Notebook 02's spiral explorer in JupyterLab, as a student meets it (issue 23, item 3).

The student version, as ``make lab`` serves it: run the imports and the explorer's cell,
move the logarithmic dt slider, and see a new picture and a new result in the kernel (the
spiral's growth and the error at T = π for the new step). The solution opened without a
kernel shows the kernel-free player beside the explorer's cell.
"""

from __future__ import annotations

import json
import time

import labpage

NAME = "02_forward_euler"
PROBE = """
import gc, json
from course_lib.widgets import PictureView
views = [v for v in gc.get_objects() if isinstance(v, PictureView) and "dt" in v.controls]
r = views[-1].result
print(json.dumps([r.dt, r.growth, r.growth_theory, r.error]))
"""


def test_spiral_explorer_answers_its_slider(page, lab):
    try:
        labpage.open_notebook(page, lab, f"notebooks/{NAME}.ipynb")
        labpage.rerun(page, labpage.find_cell(page, "nb02_spiral_view as spiral_view"))
        index = labpage.find_cell(page, "spiral_view.spiral_explorer(")
        labpage.rerun(page, index)
        assert labpage.problems(page) == [], "the imports or the explorer's cell raised"
        scope = labpage.cell(page, index)
        scope.locator(".widget-slider").first.wait_for()
        before = labpage.picture(scope)
        assert before.startswith("data:image/png") or before.startswith("blob:"), before[:40]
        start = time.monotonic()
        labpage.set_slider(page, scope, "dt (s)", 0.05)
        after = labpage.wait_new_picture(scope, before)
        seconds = time.monotonic() - start
        assert after != before
        dt, growth, theory, error = json.loads(labpage.kernel_run(page, PROBE))
        assert abs(dt - 0.05) < 1e-3 * 0.05
        assert abs(growth / theory - 1) < 1e-12 and 1.1 < growth < 1.2
        assert 0.05 < error < 0.1                       # Section 4: about π dt / 2
        print(f"spiral explorer: slider to new picture in {1e3 * seconds:.0f} ms (wall)")
    finally:
        lab.shutdown_kernels()


def test_solution_shows_the_player_beside_the_explorer(page, lab):
    try:
        labpage.open_notebook(page, lab, f"solutions/{NAME}.ipynb", kernel=False)
        kinds = page.evaluate(f"""() => {labpage.NB}.content.widgets.map(c => {{
            if (c.model.type !== 'code') return '';
            return Array.from({{length: c.model.outputs.length}}, (_, j) =>
                Object.keys(c.model.outputs.get(j).data || {{}}).join(',')).join(';');
          }})""")
        player = labpage.find_cell(page, "spiral_view.spiral_player(")
        widget = labpage.find_cell(page, "spiral_view.spiral_explorer(")
        assert "text/html" in kinds[player] and 0 < widget - player <= 3
        img = labpage.cell(page, player).locator(".jp-OutputArea-output img").first
        img.wait_for(timeout=15_000)
        assert img.evaluate("i => i.naturalWidth") > 0, "the player shows no frame"
    finally:
        lab.shutdown_kernels()

"""Notebook 04's follower explorer in JupyterLab, as a student meets it (issue 23, item 3).

The student version, as ``make lab`` serves it: run the imports and the explorer's cell,
move the logarithmic κ dt slider across RK4's limit (2.785), and see a new picture and a
new verdict in the kernel. The solution opened without a kernel shows the kernel-free
player beside the explorer's cell.
"""

from __future__ import annotations

import json
import time

import labpage

NAME = "04_beyond_euler"
PROBE = """
import gc, json
from course_lib.widgets import PictureView
views = [v for v in gc.get_objects() if isinstance(v, PictureView) and "kappa_dt" in v.controls]
r = views[-1].result
print(json.dumps([r.kappa_dt, r.stable, r.R]))
"""


def test_follower_explorer_answers_its_slider(page, lab):
    try:
        labpage.open_notebook(page, lab, f"notebooks/{NAME}.ipynb")
        labpage.rerun(page, labpage.find_cell(page, "nb04_follower_view as follower_view"))
        index = labpage.find_cell(page, "follower_view.follower_explorer(")
        labpage.rerun(page, index)
        assert labpage.problems(page) == [], "the imports or the explorer's cell raised"
        scope = labpage.cell(page, index)
        scope.locator(".widget-slider").first.wait_for()
        pictures = [labpage.picture(scope)]
        seconds = []
        for value in (2.7, 2.9):                       # RK4 stable, then unstable
            start = time.monotonic()
            labpage.set_slider(page, scope, "κ dt", value)
            pictures.append(labpage.wait_new_picture(scope, pictures[-1]))
            seconds.append(time.monotonic() - start)
            kappa_dt, stable, R = json.loads(labpage.kernel_run(page, PROBE))
            assert abs(kappa_dt - value) < 1e-3 * value
            assert stable["rk4"] is (value < 2.785) and stable["backward_euler"]
            assert not stable["forward_euler"] and abs(R["trapezoidal"]) < 1
        assert len(set(pictures)) == 3
        print("follower explorer: slider to new picture in "
              + ", ".join(f"{1e3 * s:.0f}" for s in seconds) + " ms (wall)")
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
        player = labpage.find_cell(page, "follower_view.follower_player(")
        widget = labpage.find_cell(page, "follower_view.follower_explorer(")
        assert "text/html" in kinds[player] and 0 < widget - player <= 3
        img = labpage.cell(page, player).locator(".jp-OutputArea-output img").first
        img.wait_for(timeout=15_000)
        assert img.evaluate("i => i.naturalWidth") > 0, "the player shows no frame"
    finally:
        lab.shutdown_kernels()

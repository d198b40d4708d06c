"""Notebook 05's energy-band explorer, as a student meets it (issue 23, item 3).

The student version, as ``make lab`` serves it: run the imports and the explorer's cell, move the
logarithmic dt slider across symplectic Euler's limit ω dt = 2 and see a new picture and a
new verdict in the kernel (stable, then unstable); the band widths the kernel computed for
the new step are the theory's. The kernel-free player beside it, opened from a file with
the network blocked, scrubs across the same limit.
"""

from __future__ import annotations

import json
import time

import labpage

NAME = "05_newtons_second_law"
PROBE = """
import gc, json
from course_lib.widgets import ExplorerView
views = [v for v in gc.get_objects() if isinstance(v, ExplorerView) and "dt" in v.controls
         and type(v.result).__name__ == "EnergyBands"]
r = views[-1].result
print(json.dumps([r.dt, r.stable, r.verdict, list(r.spread["velocity_verlet"])]))
"""


def test_energy_explorer_answers_its_slider_across_the_limit(page, lab):
    try:
        labpage.open_notebook(page, lab, f"notebooks/{NAME}.ipynb")
        labpage.rerun(page, labpage.find_cell(page, "from course_lib.check import nb05 as check"))
        index = labpage.find_cell(page, "nb05_energy_view.energy_explorer(")
        labpage.rerun(page, index)
        assert labpage.problems(page) == [], "the explorer's cell raised"
        scope = labpage.cell(page, index)
        scope.locator(".widget-slider").first.wait_for()
        pictures = [labpage.wait_new_picture(scope, "")]        # the first picture
        assert pictures[0].startswith(("data:image/png", "blob:")), pictures[0][:40]
        start = time.monotonic()
        labpage.set_slider(page, scope, "dt (s)", 1.9)
        pictures.append(labpage.wait_new_picture(scope, pictures[-1]))
        seconds = time.monotonic() - start
        dt, stable, verdict, (low, high) = json.loads(labpage.kernel_run(page, PROBE))
        assert abs(dt - 1.9) < 2e-2 * 1.9 and stable and verdict.startswith("stable")
        # Verlet's band is [1 - ω² dt²/4, 1], sampled (theory within a fraction of a percent)
        assert abs(low - (1 - dt**2 / 4)) < 5e-3 and abs(high - 1.0) < 1e-9
        assert labpage.verdict(page, "dt", dt) == "stable"
        labpage.set_slider(page, scope, "dt (s)", 2.1)
        pictures.append(labpage.wait_new_picture(scope, pictures[-1]))
        dt, stable, verdict, _ = json.loads(labpage.kernel_run(page, PROBE))
        assert dt > 2.0 and not stable and verdict.startswith("unstable")
        assert labpage.verdict(page, "dt", dt) == "unstable"
        assert len(set(pictures)) == 3
        print(f"energy explorer: slider to new picture in {1e3 * seconds:.0f} ms (wall)")
    finally:
        lab.shutdown_kernels()


def test_kernel_free_player_crosses_the_limit_offline(page, tmp_path):
    from course_lib.lessons import nb05_energy_view

    path = tmp_path / "player.html"
    nb05_energy_view.energy_player().save(path)
    page.goto(path.as_uri())
    player = page.locator(".clp[data-kind=parameter]")
    player.wait_for()
    page.wait_for_function("(p) => p.getAttribute('data-ready') === '1'",
                           arg=player.element_handle())
    labels = player.evaluate("p => JSON.parse(p.querySelector('.clp-data').textContent).labels")
    assert labels[0] == "dt = 0.02 s" and labels[-1] == "dt = 2.1 s"
    slider, caption = player.locator(".clp-slider"), player.locator(".clp-caption")
    slider.fill(str(labels.index("dt = 1.9 s")))
    assert caption.inner_text().startswith("stable")
    before = player.locator("img").get_attribute("src")
    player.locator("[data-act=next]").click()
    assert player.locator(".clp-label").inner_text() == "dt = 2.1 s"
    assert caption.inner_text().startswith("unstable")
    assert player.locator("img").get_attribute("src") != before
    assert player.locator("img").evaluate("i => i.naturalWidth") > 0
    assert page.blocked == [] and page.errors == []

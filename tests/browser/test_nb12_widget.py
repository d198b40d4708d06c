"""Notebook 12's frame explorer, as a student meets it (issue 19).

The student version, as ``make lab`` serves it: run the imports and the explorer's cell,
move the iterations slider of fast mass-springs (stiffness ×100) from 10 to 40 and see a
new picture, and a frame the kernel computed closer to the converged one. The
kernel-free player beside it, opened from a file with the network blocked, scrubs XPBD's
small steps, and its captions say the stretch falls.
"""

from __future__ import annotations

import json
import re
import time

import labpage

NAME = "12_constraints_and_large_steps"
PROBE = """
import gc, json
from course_lib.widgets import ExplorerView
views = [v for v in gc.get_objects() if isinstance(v, ExplorerView) and "iterations" in v.controls
         and type(v.result).__name__ == "FrameResult"]
r = views[-1].result
print(json.dumps([r.params["method"], r.params["iterations"], r.stable, r.peak, r.reference_peak]))
"""


def test_frame_explorer_answers_its_slider(page, lab):
    try:
        labpage.open_notebook(page, lab, f"notebooks/{NAME}.ipynb")
        labpage.rerun(page, labpage.find_cell(page, "from course_lib.check import nb12 as check"))
        index = labpage.find_cell(page, "drawings.frame_explorer(")
        labpage.rerun(page, index)
        assert labpage.problems(page) == [], "the explorer's cell raised"
        scope = labpage.cell(page, index)
        scope.locator(".widget-slider").first.wait_for()
        pictures = [labpage.wait_new_picture(scope, "")]
        method, its, stable, peak10, ref = json.loads(labpage.kernel_run(page, PROBE))
        assert (method, its, stable) == ("fast_mass_spring", 10, True)
        start = time.monotonic()
        labpage.set_slider(page, scope, "iterations", 40)
        pictures.append(labpage.wait_new_picture(scope, pictures[-1]))
        seconds = time.monotonic() - start
        method, its, stable, peak40, ref40 = json.loads(labpage.kernel_run(page, PROBE))
        assert its == 40 and stable and ref40 == ref
        assert abs(peak40 - ref) < abs(peak10 - ref)            # closer to the converged frame
        print(f"frame explorer: slider to new picture in {1e3 * seconds:.0f} ms (wall)")
    finally:
        lab.shutdown_kernels()


def test_kernel_free_player_scrubs_xpbd_small_steps_offline(page, tmp_path):
    from course_lib.lessons import nb12_drawings

    path = tmp_path / "player.html"
    nb12_drawings.frame_player(iterations=(1, 10, 40)).save(path)
    page.goto(path.as_uri())
    player = page.locator(".clp[data-kind=parameter]")
    player.wait_for()
    page.wait_for_function("(p) => p.getAttribute('data-ready') === '1'",
                           arg=player.element_handle())
    labels = player.evaluate("p => JSON.parse(p.querySelector('.clp-data').textContent).labels")
    assert labels == ["iterations = 1", "iterations = 10", "iterations = 40"]
    slider, caption = player.locator(".clp-slider"), player.locator(".clp-caption")
    peaks = []
    for k in range(3):
        slider.fill(str(k))
        peaks.append(float(re.search(r"peak strain ([\d.]+) %", caption.inner_text()).group(1)))
    assert peaks[0] > peaks[1] > peaks[2]
    assert player.locator("img").evaluate("i => i.naturalWidth") > 0
    assert page.blocked == [] and page.errors == []

"""A student's first hour in JupyterLab (issue 13), replayed in Chromium.

Each notebook with a widget (the student version, as ``make lab`` serves it on a fresh
machine) must open unmodified; its imports and its widget's cell must run without an error
or a warning, and the widget must answer a control moved across a stability limit with a
new verdict and a new picture (and a sign that it worked, for the slow ones). Animations
must show a frame before any click, play on the first click and not make the page jump;
cells re-run out of order must not raise. Outputs must use marks every font has, and the
first launch must be quiet.

That every notebook runs top to bottom without an error or a warning is proved without a
browser, and more cheaply, by the notebooks stage of ``make test``: strict nbval of each
solution compares every stream, stderr included, and the student versions run under nbval
too. The marks of stored outputs are read from the files (tests/test_output_marks.py).
"""

from __future__ import annotations

import re
import time

import labpage
import pytest
from output_marks import emoji_in

#: notebook -> (cell needle, [(label, value) set first], (control, label), before, after,
#:              verdicts expected, busy status expected)
WIDGETS = {
    "03_stability": ("stability_explorer", [], ("dt", "dt (s)"), 1.9, 2.1, True, False),
    "06_forces": ("steering_view", [], ("strength", "strength"), 2.0, 5.0, False, False),
    "07_springs": ("spring_explorer", [("dt (s)", 0.1)], ("k", "k (N/m)"), 350.0, 450.0, True, True),
    "08_hair_chains": ("held_strand_explorer", [], ("k_bend", "k_bend (N/m)"), 9000.0, 9500.0,
                       True, True),
    "10_flocking": ("flock_explorer", [], ("alignment", "alignment"), 5.0, 8.0, True, False),
}

def output_text(page) -> str:
    return page.evaluate(f"""() => {labpage.NB}.content.widgets.map(c => c.model.type !== 'code'
        ? '' : Array.from({{length: c.model.outputs.length}}, (_, j) => {{
            const o = c.model.outputs.get(j).toJSON();
            return [o.text || '', (o.data || {{}})['text/plain'] || ''].join('');
        }}).join('')).join('')""")


def open_unmodified(page, lab, name: str) -> None:
    labpage.open_notebook(page, lab, f"notebooks/{name}.ipynb")
    assert not labpage.is_dirty(page), (
        f"{name} turns 'modified' as soon as it opens: its stored kernelspec or language_info "
        "differs from what the kernel reports (re-run `make execute` and `make student`)")


def open_and_run_widget(page, lab, name: str, needle: str) -> int:
    """Open the student version, run its first code cell (the imports) and the widget's
    cell, as a student who jumps to the widget does. Returns the widget cell's index."""
    open_unmodified(page, lab, name)
    labpage.rerun(page, labpage.find_cell(page, "import "))
    index = labpage.find_cell(page, needle)
    labpage.rerun(page, index)
    assert labpage.problems(page) == [], f"{name}: the imports or the widget's cell raised or warned"
    return index


def check_marks(page, name: str) -> None:
    marks = emoji_in(output_text(page))
    assert not marks, f"{name}: outputs use {marks}, an empty box without an emoji font"


def check_animations(page) -> int:
    """Every animation player shows a frame before any click; the first click plays it and
    the page does not jump. Returns how many players were checked."""
    count = page.evaluate(f"""() => {labpage.NB}.content.widgets.filter(c =>
        c.model.type === 'code' && c.model.sharedModel.source.includes('animation_html')).length""")
    index = -1
    for _ in range(count):
        index = page.evaluate(f"""(start) => {labpage.NB}.content.widgets.findIndex((c, i) =>
            i > start && c.model.type === 'code'
            && c.model.sharedModel.source.includes('animation_html'))""", index)
        player = labpage.cell(page, index).locator(".clp[data-kind=animation]")
        player.wait_for()
        img = player.locator("img.clp-img")
        size = img.evaluate("i => [i.naturalWidth, i.getBoundingClientRect().height]")
        assert size[0] > 0 and size[1] > 50, f"cell {index}: no frame before any click ({size})"
        assert player.get_attribute("data-frame") == "0"
        # the controls at the top of the view, the cell's top above it: a click that
        # selected the cell would scroll the cell's top into view
        player.locator(".clp-bar").evaluate("""b => new Promise(done => {
            b.scrollIntoView({block: 'start'});  // then two frames: scrolled and laid out
            requestAnimationFrame(() => requestAnimationFrame(done)); })""")
        y0 = img.bounding_box()["y"]
        player.locator("[data-act=play]").click()
        page.wait_for_function("(el) => el.getAttribute('data-frame') !== '0'",
                               arg=player.element_handle(), timeout=5000)
        assert player.get_attribute("data-playing") == "1", "the first click did not play"
        assert abs(img.bounding_box()["y"] - y0) < 5, "the page jumped when the player started"
        player.locator("[data-act=play]").click()  # pause
        assert player.get_attribute("data-playing") is None
    return count


@pytest.mark.parametrize("name", sorted(WIDGETS))
def test_widget_notebook_runs_and_its_widget_crosses_the_limit(page, lab, name):
    needle, first, (control, label), before, after, verdicts, busy = WIDGETS[name]
    try:
        open_and_run_widget(page, lab, name, needle)
        scope = labpage.cell(page, labpage.find_cell(page, needle, widget=True))
        scope.locator(".widget-slider").first.wait_for()
        pic = labpage.picture(scope)
        for lab_text, value in [*first, (label, before)]:
            labpage.set_slider(page, scope, lab_text, value)
            pic = labpage.wait_new_picture(scope, pic)
        if verdicts:
            assert labpage.verdict(page, control, before) == "stable"
        labpage.set_slider(page, scope, label, after)
        new_pic = labpage.wait_new_picture(scope, pic)
        assert new_pic != pic
        if verdicts:
            assert labpage.verdict(page, control, after) == "unstable"
        if busy:  # the slow widgets say that they worked, and how long it took
            status = scope.locator(".widget-html").all_inner_texts()
            assert any(re.search(r"updated in|working", s) for s in status), status
        if name == "07_springs":  # readable method names, as in notebook 03
            options = scope.locator("select option").all_inner_texts()
            assert options and not any("_" in o for o in options), options
        check_marks(page, name)
    finally:
        lab.shutdown_kernels()


def test_animation_shows_a_frame_and_plays_on_the_first_click(page, lab):
    try:
        open_unmodified(page, lab, "01_vector_fields")
        anim = labpage.find_cell(page, "animation_html")
        # only the cells the animation reads (imports, the whirlpool, the tracked particle
        # `far`), as a student who jumps to it: that every cell above runs clean is the
        # notebooks stage's claim (nbval), and the other cells' figures only cost rendering
        for needle in ("import ", "whirl_traj = ", "far = "):
            labpage.rerun(page, labpage.find_cell(page, needle))
        labpage.rerun(page, anim)
        assert labpage.problems(page) == [], "the cells the animation needs raised or warned"
        assert check_animations(page) >= 1
        # re-running cells out of order (the whirlpool's cell, the one two above it, then it
        # again) raises nothing and leaves one player, no stray figure
        for i in (anim, anim - 2, anim):
            labpage.rerun(page, i)
        assert labpage.problems(page) == [], "re-running cells out of order raised"
        assert len(labpage.outputs_of(page, anim)) == 1, labpage.outputs_of(page, anim)
        check_marks(page, "01_vector_fields")
    finally:
        lab.shutdown_kernels()


@pytest.mark.fresh_lab
def test_first_launch_is_quiet(page, lab):
    """No news prompt in the page; no encryption warning, skipped-server list or
    deprecation warning in the terminal (the lab log, kernels included)."""
    answered: list[str] = []
    page.on("response", lambda r: answered.append(r.url))
    labpage.open_notebook(page, lab, "notebooks/02_forward_euler.ipynb")
    # JupyterLab asks about news once it is restored and has loaded the announcements'
    # config section and the notification settings; then a probe notification of ours is
    # shown after any such prompt (toasts are made in the order they are emitted)
    needed = ("/api/config/jupyterlabapputilsextensionannouncements", "/lab/api/settings")
    deadline = time.monotonic() + 30
    while (missing := [n for n in needed if not any(n in u for u in answered)]) \
            and time.monotonic() < deadline:
        page.wait_for_timeout(100)
    assert not missing, f"JupyterLab never loaded {missing}"
    page.evaluate("""async () => { await window.jupyterapp.restored;
        await window.jupyterapp.commands.execute('apputils:notify',
            {message: 'browser-test probe', type: 'info', options: {autoClose: false}}); }""")
    page.locator(".Toastify__toast", has_text="browser-test probe").wait_for()
    toasts = page.locator(".jp-Notification-Toast, .Toastify__toast").all_inner_texts()
    assert not any("news" in t.lower() for t in toasts), toasts
    lab.shutdown_kernels()
    log = lab.log.read_text()
    for noise in ("without encryption", "Skipped non-installed", "DeprecationWarning",
                  "websocket_ping_timeout"):
        assert noise not in log, f"`make lab` prints {noise!r}:\n{log[-2000:]}"


@pytest.mark.parametrize("name", ["01_vector_fields", *sorted(WIDGETS)])
def test_solution_opened_without_running_shows_its_pictures(page, lab, name):
    """On a fresh machine a stored solution is untrusted: its animations must still show a
    frame, and a picture of each widget's key states must sit beside the widget."""
    try:
        labpage.open_notebook(page, lab, f"solutions/{name}.ipynb", kernel=False)
        found = page.evaluate(f"""() => {labpage.NB}.content.widgets.map(c => {{
            if (c.model.type !== 'code') return '';
            const kinds = Array.from({{length: c.model.outputs.length}}, (_, j) =>
                Object.keys(c.model.outputs.get(j).data || {{}}).join(','));
            const src = c.model.sharedModel.source;
            return (src.includes('animation_html') ? 'A' : '')
                + (kinds.some(k => k.includes('widget-view')) ? 'W' : '')
                + (kinds.some(k => k.includes('image/png') || k.includes('text/html')) ? 'P' : '');
          }})""")
        for i, kind in enumerate(found):
            if "W" in kind:
                assert any("P" in k for k in found[max(0, i - 3):i] + found[i + 1:i + 4]), (
                    f"{name}, cell {i}: no picture of the widget's key states beside it")
            if "A" in kind:
                # (the sanitizer of an untrusted notebook keeps the image, not our attributes)
                player = labpage.cell(page, i).locator(".jp-OutputArea-output img").first
                player.wait_for(timeout=15_000)
                assert player.evaluate("i => i.naturalWidth") > 0, f"{name}, cell {i}: no frame"
    finally:
        lab.shutdown_kernels()

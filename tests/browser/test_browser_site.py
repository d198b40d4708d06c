"""The static site, opened from its folder with the network blocked: math, figures, saved
widgets, animations and the kernel-free explorers all work (issue 11)."""

from __future__ import annotations

import pytest

from conftest import SAVED_WIDGET, SITE_PAGES

pytestmark = pytest.mark.xdist_group("site")  # one worker builds it

PAGES = SITE_PAGES  # the session fixture ``site`` (conftest) builds them from stored outputs


def open_page(page, site, name: str) -> None:
    page.goto((site / name).as_uri())
    page.wait_for_load_state("load")
    page.wait_for_function("() => window.MathJax && MathJax.startup && MathJax.startup.promise")
    page.evaluate("() => MathJax.startup.promise")


def test_index_links_every_page_and_needs_no_network(page, site):
    page.goto((site / "index.html").as_uri())
    links = page.locator("table a").evaluate_all("as => as.map(a => a.getAttribute('href'))")
    assert [f"{p}.html" for p in PAGES] == [h for h in links if h.endswith(".html")]
    assert page.blocked == []


def test_page_renders_math_figures_widgets_and_the_explorer_offline(page, site):
    open_page(page, site, "03_stability.html")
    assert page.locator("mjx-container").count() > 20, "math was not typeset"
    assert page.locator(".MathJax_Error, mjx-merror").count() == 0
    sizes = page.evaluate("() => Array.from(document.images).map(i => i.naturalWidth)")
    assert len(sizes) >= 5 and min(sizes) > 0, f"a figure did not load: {sizes}"
    player = page.locator(".clp[data-kind=parameter]")
    assert player.count() == 1 and player.get_attribute("data-ready") == "1"
    slider, caption = player.locator(".clp-slider"), player.locator(".clp-caption")
    labels = player.evaluate("p => JSON.parse(p.querySelector('.clp-data').textContent).labels")
    k = labels.index("dt = 1.9 s")
    slider.fill(str(k))
    assert caption.inner_text().startswith("stable")
    before = player.locator("img").get_attribute("src")
    player.locator("[data-act=next]").click()  # dt = 2.1 s: across the limit 2/k
    assert player.locator(".clp-label").inner_text() == "dt = 2.1 s"
    assert caption.inner_text().startswith("unstable")
    assert player.locator("img").get_attribute("src") != before
    assert page.blocked == [] and page.errors == []


def test_saved_widget_state_renders_offline(page, site):
    """A widget's saved state (stored by an executed notebook) is drawn by the vendored
    widget manager: the notebooks' live widgets get it when ``make site`` executes them."""
    open_page(page, site, f"{SAVED_WIDGET}.html")
    slider = page.locator(".widget-slider").first
    slider.wait_for()
    assert slider.locator(".widget-readout").inner_text() == "0.50"
    assert page.blocked == [] and page.errors == []


def test_animation_plays_offline(page, site):
    open_page(page, site, "01_vector_fields.html")
    player = page.locator(".clp[data-kind=animation]").first
    player.scroll_into_view_if_needed()
    assert player.locator("img").evaluate("i => i.naturalWidth") > 0
    player.locator("[data-act=play]").click()
    page.wait_for_function("(p) => p.getAttribute('data-frame') !== '0'",
                           arg=player.element_handle(), timeout=5000)
    icons = player.locator(".clp-btn svg").count()
    assert icons == 5, "the buttons' icons are inline SVG, drawn without a font download"
    assert page.blocked == [] and page.errors == []

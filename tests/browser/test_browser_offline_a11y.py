"""A reader who turns on MathJax's accessibility features gets them offline too (issue 20).

The static site is opened from disk with the network blocked, with MathJax's menu settings
already on (speech, Braille, the explorer, and a language other than English), the way a
screen-reader user leaves them: they persist in the browser's storage. MathJax then loads
the Speech Rule Engine's maps for that language and for Nemeth Braille; left to their
defaults those come from a CDN (``cdn.jsdelivr.net``), and from ``file://`` a JSON fetch
is refused by Chromium. The site points the engine at its own copies (see
``course_lib.instructor.site_assets.SRE_FEATURE_JS``).
"""

from __future__ import annotations

import json

import pytest

# the site fixture (conftest) is built once, on the worker that runs the site tests
pytestmark = pytest.mark.xdist_group("site")


def _open_with_settings(page, site, **settings) -> None:
    page.add_init_script(f"localStorage.setItem('MathJax-Menu-Settings', {json.dumps(json.dumps(settings))})")
    requested: list[str] = []
    page.on("request", lambda r: requested.append(r.url))
    page.requested = requested
    page.goto((site / "03_stability.html").as_uri())
    page.wait_for_function("() => window.MathJax && MathJax.startup && MathJax.startup.promise")
    page.evaluate("() => MathJax.startup.promise")


def _labels(page) -> list[str]:
    page.wait_for_function("() => document.querySelectorAll('mjx-container [aria-label], "
                           "mjx-container[aria-label]').length > 0", timeout=30_000)
    return page.evaluate("() => Array.from(document.querySelectorAll('mjx-container[aria-label], "
                         "mjx-container [aria-label]')).map(e => e.getAttribute('aria-label'))")


def test_speech_and_braille_work_from_disk_with_the_network_blocked(page, site):
    _open_with_settings(page, site, explorer=True, speech=True, braille=True, viewBraille=True,
                        locale="de")
    labels = [x for x in _labels(page) if x]
    # R(z), the amplification factor, read aloud in German
    assert any("Klammer auf z Klammer zu" in x for x in labels), labels[:5]
    # Braille: what the explorer's Braille region asks the engine for (Nemeth code)
    braille = page.evaluate("""async () => {
        const S = MathJax._.a11y.sre.Sre;
        await S.setupEngine({locale: 'nemeth', modality: 'braille', domain: 'default', style: 'default'});
        await S.sreReady();
        return S.toSpeech('<math><mi>x</mi><mo>=</mo><mn>2</mn></math>'); }""")
    assert braille == "⠭⠀⠨⠅⠀⠼⠆", braille  # x = 2 in Nemeth
    assert page.blocked == [], f"asked the network for {page.blocked}"
    local = [u.split("_static/")[-1] for u in page.requested if "/sre/" in u]
    assert {"sre/maps/base.js", "sre/maps/de.js", "sre/maps/nemeth.js"} <= set(local), local
    where = page.evaluate("() => [window.SREfeature.json, window.SREfeature.xpath]")
    assert all(w.startswith(site.as_uri()) for w in where), where
    assert page.errors == []


def test_english_speech_is_the_default_and_stays_local(page, site):
    _open_with_settings(page, site, explorer=True, speech=True)
    labels = [x for x in _labels(page) if x]
    assert any("left parenthesis z right parenthesis" in x for x in labels), labels[:5]
    assert page.blocked == [] and page.errors == []

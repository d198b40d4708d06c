"""Lecture mode (``make present NB=03_stability``): Voila on 127.0.0.1 with a token shows
the demo only, and its widget answers a control moved across the stability limit."""

from __future__ import annotations

import sys

import labpage
import pytest

from conftest import ROOT, TOKEN, free_port, fresh_jupyter_env, server

pytestmark = pytest.mark.xdist_group("voila")  # one worker builds it


@pytest.fixture(scope="module")
def voila(browser, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("present")
    port = free_port()
    cmd = [sys.executable, "-m", "course_lib.instructor.present", "03_stability",
           f"--port={port}", f"--token={TOKEN}", "--no-browser", f"--out={tmp}"]
    base = f"http://127.0.0.1:{port}"
    log = tmp / "voila.log"
    with server(cmd, fresh_jupyter_env(tmp / "home"), ROOT, log,
                f"tcp://127.0.0.1:{port}"):
        yield base, log


def test_lecture_mode_needs_the_token(voila):
    import urllib.request

    base, _ = voila
    with urllib.request.urlopen(f"{base}/", timeout=60) as r:  # no token: the login page
        body = r.read().decode()
        assert r.geturl().startswith(f"{base}/login")
    assert "Stability" not in body


def test_lecture_mode_shows_the_demo_and_it_answers(page, voila):
    base, log = voila
    page.goto(f"{base}/?token={TOKEN}")
    scope = page.locator("body")
    page.locator(".widget-slider").first.wait_for(timeout=120_000)
    assert page.locator(".jp-InputArea-editor:visible").count() == 0, "code is shown"
    assert page.locator(".widget-slider").count() == 2  # the explorer's dt and rate only
    heads = page.locator("h1, h2, h3").all_inner_texts()
    assert heads[0].startswith("03") and len(heads) == 2, heads
    pic = labpage.wait_new_picture(scope, "")
    labpage.set_slider(page, scope, "dt (s)", 1.9)
    stable = labpage.wait_new_picture(scope, pic)
    labpage.set_slider(page, scope, "dt (s)", 2.1)
    unstable = labpage.wait_new_picture(scope, stable)
    assert unstable not in (pic, stable)
    assert page.errors == []
    # the course's page template drops Voila's CDN stylesheets (Font Awesome) and Mermaid
    assert page.blocked == [], f"lecture mode asked the network for {page.blocked}"
    text = log.read_text()
    for noise in ("without encryption", "websocket_ping_timeout", "is not trusted"):
        assert noise not in text, f"`make present` prints {noise!r}"

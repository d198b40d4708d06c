"""Browser tests: Playwright driving Debian's Chromium against JupyterLab, the site and Voila.

Run with ``make test-browser`` (part of ``make test``, on two pytest-xdist workers) or
``pytest tests/browser``; a plain ``pytest tests`` leaves this folder out. Each worker has
its own browser and JupyterLab (session fixtures ``browser``, ``lab``; a fresh ``page`` per
test). Tests are spread one by one (``--dist loadgroup``); a module whose fixture is costly
to build twice (the site, Voila) keeps its tests on one worker with
``pytestmark = pytest.mark.xdist_group("name")``. Servers bind port 0 or ``free_port()``.
Chromium is Debian's (``/usr/bin/chromium``): when it is missing and we are root it is
installed with apt-get (one worker at a time), otherwise every test is skipped with a
message saying how to enable them. No browser is ever downloaded. A failing test leaves a
screenshot in ``build/browser-screenshots/``.
"""

from __future__ import annotations

import contextlib
import importlib.util
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
# helpers shared with the unit tests (output_marks.py) live one folder up
sys.path.insert(0, str(HERE.parent))
CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--no-first-run",
                 "--disable-quic"]
SHOTS = ROOT / "build" / "browser-screenshots"
TOKEN = "course-browser-test"
SITE_PAGES = ["01_vector_fields", "03_stability"]


def _asked_for(config) -> bool:
    """Whether this folder (or a file in it) was named on the command line."""
    targets = [Path(str(a).split("::")[0]).resolve() for a in config.args]
    return any(t == HERE or HERE in t.parents for t in targets)


def pytest_configure(config):
    """A run stopped with SIGTERM (a CI timeout) still stops its servers: the signal becomes
    a KeyboardInterrupt, after which pytest runs the fixtures' teardown."""

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    if _asked_for(config):
        signal.signal(signal.SIGTERM, interrupt)
    config.addinivalue_line("markers", "fresh_lab: the test loads JupyterLab in a fresh page "
                            "instead of the worker's shared JupyterLab window")


def pytest_ignore_collect(collection_path, config):
    """Collect this folder only when asked for by path (``pytest tests/browser``)."""
    return not _asked_for(config)


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(config, items):
    """Keep each ``xdist_group`` on one worker under pytest 9. pytest-xdist 3.8 marks a
    group by appending ``@name`` to ``item._nodeid``, which pytest 9 no longer reads (the
    id lives in ``item._id``): the groups were silently split and the site built on both
    workers. We append the suffix where pytest 9 keeps the id, once."""
    if not getattr(config.option, "loadgroup", False):  # set on xdist workers only
        return
    for item in items:
        names = sorted({str(m.args[0] if m.args else m.kwargs.get("name", "default"))
                        for m in item.iter_markers("xdist_group")})
        if not names or "@" in item.nodeid.rpartition("]")[2].rpartition("::")[2]:
            continue
        grouped = f"{item.nodeid}@{'_'.join(names)}"
        if hasattr(item, "_id"):
            from _pytest.nodeid import NodeId

            item._id = NodeId.parse(grouped)
        else:
            item._nodeid = grouped


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item, call):
    report = yield
    if report.when == "call":
        item.failed_call = report.failed
    return report


def _chromium_missing() -> str | None:
    """None when Chromium is there (installing it with apt-get if we may), else why not."""
    spec = importlib.util.spec_from_file_location("kit_chromium", ROOT / "tools" / "chromium.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.ensure()


@pytest.fixture(scope="session")
def browser():
    why = _chromium_missing()
    if why:
        pytest.skip(why)
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("browser tests skipped: the `playwright` package is missing "
                    "(`make setup` installs requirements.txt)")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        yield b
        b.close()


def _local(url: str) -> bool:
    return url.startswith(("file:", "data:", "blob:", "http://127.0.0.1", "ws://127.0.0.1"))


def _new_page(browser):
    """A page (1400 x 900) in its own context with the network blocked beyond this machine
    (files, data and blob URLs, 127.0.0.1); uncaught script errors are collected in
    ``page.errors`` and blocked URLs in ``page.blocked``. Returns (context, page)."""
    context = browser.new_context(viewport={"width": 1400, "height": 900})
    blocked: list[str] = []

    def route(r):
        if _local(r.request.url):
            r.continue_()
        else:
            blocked.append(r.request.url)
            r.abort()

    context.route("**/*", route)
    pg = context.new_page()
    pg.blocked, pg.errors = blocked, []
    pg.on("pageerror", lambda e: pg.errors.append(str(e)))
    pg.set_default_timeout(60_000)
    return context, pg


def _shoot(pg, request) -> None:
    if getattr(request.node, "failed_call", False):
        SHOTS.mkdir(parents=True, exist_ok=True)
        with contextlib.suppress(Exception):
            pg.screenshot(path=str(SHOTS / f"{request.node.name}.png"))


@pytest.fixture(scope="session")
def _lab_window(browser, lab):
    """One page per worker with JupyterLab loaded (loading it takes 7 to 13 s of a test on
    this machine; opening a notebook in it 1.5 s): the tests that use ``lab`` open their
    notebooks in it with ``labpage.open_notebook`` (JupyterLab's own docmanager:open)."""
    context, pg = _new_page(browser)
    pg.goto(f"{lab.base}/lab?reset&token={TOKEN}")
    pg.wait_for_function("() => window.jupyterapp && window.jupyterapp.shell", timeout=120_000)
    pg.evaluate("() => window.jupyterapp.restored")
    yield pg
    context.close()


@pytest.fixture
def page(browser, request):
    """A fresh page (see ``_new_page``). A test that uses ``lab`` gets instead the worker's
    JupyterLab window, emptied after the test (its notebooks disposed unsaved, dialogs
    dismissed, kernels shut down), unless marked ``fresh_lab`` (a student's first launch)."""
    if "lab" in request.fixturenames and not request.node.get_closest_marker("fresh_lab"):
        lab = request.getfixturevalue("lab")
        pg = request.getfixturevalue("_lab_window")
        pg.blocked.clear()
        pg.errors.clear()
        yield pg
        _shoot(pg, request)
        pg.evaluate("""() => {
            document.querySelectorAll('.jp-Dialog .jp-mod-reject').forEach(b => b.click());
            for (const w of Array.from(window.jupyterapp.shell.widgets('main'))) w.dispose();
          }""")
        lab.shutdown_kernels()
        return
    context, pg = _new_page(browser)
    yield pg
    _shoot(pg, request)
    context.close()


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _answers(url: str) -> bool:
    """``url`` answers 200, or, for ``tcp://host:port``, the port accepts a connection."""
    with contextlib.suppress(OSError):
        if url.startswith("tcp://"):
            host, port = url[6:].split(":")
            with socket.create_connection((host, int(port)), timeout=2):
                return True
        with urllib.request.urlopen(url, timeout=5) as r:
            return r.status == 200
    return False


def wait_http(url, proc: subprocess.Popen, log: Path, timeout: float = 90) -> str:
    """Wait until ``url`` answers (see ``_answers``); ``url`` may be a function of the log's
    text that returns the URL once the server has printed it (None before). Returns it."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise RuntimeError(f"server exited:\n{log.read_text()[-3000:]}")
        now = url(log.read_text()) if callable(url) else url
        if now is not None and _answers(now):
            return now
        time.sleep(0.2)
    raise RuntimeError(f"no answer from {url}:\n{log.read_text()[-3000:]}")


@contextlib.contextmanager
def server(cmd: list[str], env: dict, cwd: Path, log: Path, ready_url):
    """Run a server (its own process group, output in ``log``) until the ``with`` ends;
    ready once ``ready_url`` answers (a URL, or a function of the log text as in
    ``wait_http``). Yields the process; its ``ready_url`` attribute is the URL that answered."""
    with log.open("w") as out:
        proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=out, stderr=subprocess.STDOUT,
                                start_new_session=True)
        try:
            proc.ready_url = wait_http(ready_url, proc, log)
            yield proc
        finally:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGTERM)
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)


def fresh_jupyter_env(home: Path) -> dict:
    """A student's first launch: empty Jupyter config and data folders, the course's
    settings on JUPYTER_CONFIG_PATH (as ``make lab`` sets them)."""
    for d in ("config", "data", "runtime"):
        (home / d).mkdir(parents=True, exist_ok=True)
    return {**os.environ, "JUPYTER_CONFIG_DIR": str(home / "config"),
            "JUPYTER_DATA_DIR": str(home / "data"), "JUPYTER_RUNTIME_DIR": str(home / "runtime"),
            "JUPYTER_CONFIG_PATH": str(ROOT / "jupyter_config"), "JUPYTER_PLATFORM_DIRS": "1"}


class Lab:
    """A running JupyterLab: ``url(path)``, its log, and the folder it serves."""

    def __init__(self, base: str, root: Path, log: Path):
        self.base, self.root, self.log = base, root, log

    def url(self, path: str) -> str:
        return f"{self.base}/lab/tree/{path}?reset&token={TOKEN}"

    def shutdown_kernels(self) -> None:
        import json

        req = urllib.request.Request(f"{self.base}/api/sessions?token={TOKEN}")
        with urllib.request.urlopen(req, timeout=10) as r:
            sessions = json.load(r)
        for s in sessions:
            urllib.request.urlopen(urllib.request.Request(
                f"{self.base}/api/sessions/{s['id']}?token={TOKEN}", method="DELETE"), timeout=10)


@pytest.fixture(scope="session")
def lab(browser, tmp_path_factory):
    """JupyterLab as ``make lab`` starts it (same settings), on a copy of the notebooks (so
    autosave cannot touch the repository), for a student on a fresh machine."""
    root = tmp_path_factory.mktemp("lab")
    for folder in ("notebooks", "solutions"):
        shutil.copytree(ROOT / folder, root / folder)
    bindir = Path(sys.executable).parent
    # port 0: the system picks a free port and the log names it (no race for a port)
    cmd = [str(bindir / "jupyter"), "lab", "--no-browser", "--port=0",
           "--ServerApp.ip=127.0.0.1", f"--ServerApp.root_dir={root}",
           f"--IdentityProvider.token={TOKEN}", "--LabApp.expose_app_in_browser=True"]
    if os.geteuid() == 0:
        cmd.append("--allow-root")
    log = root / "lab.log"

    def status_url(text: str) -> str | None:
        found = re.search(r"http://127\.0\.0\.1:(\d+)/", text)
        return found and f"http://127.0.0.1:{found.group(1)}/api/status?token={TOKEN}"

    with server(cmd, fresh_jupyter_env(root / "home"), root, log, status_url) as proc:
        yield Lab(proc.ready_url.split("/api/")[0], root, log)


#: The one page of the test site whose notebook is executed: a saved ipywidgets slider.
SAVED_WIDGET = "00_saved_widget"


@pytest.fixture(scope="session")
def site(browser, tmp_path_factory):
    """The site of notebooks 01 and 03 built from their stored outputs (``make site
    --no-execute``), once per run: the site and accessibility tests share it, and their
    modules are in the ``site`` xdist group, so one worker builds it while the other drives
    JupyterLab. Not executed afresh (that took 41 to 91 s): the notebook stage already
    checks with strict nbval that the stored outputs are what a fresh run gives, and
    ``tests/test_site.py`` builds a tiny notebook with ``run=True``. Stored notebooks keep no
    widget state, so their live widgets are left out; the page ``SAVED_WIDGET``, a one-slider
    notebook executed here (a kernel start, ~2 s), carries a saved widget state instead."""
    import nbformat

    from course_lib.instructor import site as builder

    root = tmp_path_factory.mktemp("site")
    source = root / "source"
    source.mkdir()
    for stem in SITE_PAGES:
        shutil.copy(ROOT / "solutions" / f"{stem}.ipynb", source)
    widget = source / f"{SAVED_WIDGET}.ipynb"
    nbformat.write(nbformat.v4.new_notebook(
        cells=[nbformat.v4.new_markdown_cell("# A saved widget"),
               nbformat.v4.new_code_cell("import ipywidgets\n"
                                         "ipywidgets.FloatSlider(value=0.5, description='k')")],
        metadata={"kernelspec": {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}}), widget)
    nbformat.write(builder.execute(widget), widget)
    out = root / "site"
    builder.build(out, source, run=False, log=lambda *a: None)
    return out

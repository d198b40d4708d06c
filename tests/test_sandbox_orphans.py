"""A sandboxed submission dies with its grader: a worker that loses its parent (a grader or
Dask worker killed mid-run) ends its whole process group, even when the student's code
sleeps in a loop that swallows the time-limit alarm (no CPU used, so no rlimit stops it)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import nbformat
import pytest
from notebook_helpers import ROOT

pytestmark = pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc (Linux)")


def _children(pid: int) -> list[int]:
    out = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmdline = (entry / "cmdline").read_bytes()
        except OSError:
            continue
        ppid = int(stat.rsplit(")", 1)[1].split()[1])
        if ppid == pid and b"worker.py" in cmdline:
            out.append(int(entry.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_a_sleeping_submission_dies_with_its_grader(tmp_path):
    nb = nbformat.read(ROOT / "notebooks" / "02_forward_euler.ipynb", as_version=4)
    stubborn = textwrap.dedent("""\
        import time
        open("looping", "w").close()  # for the test: the loop has begun
        while True:
            try:
                time.sleep(0.2)
            except BaseException:
                pass
        """)
    nb.cells.insert(1, nbformat.v4.new_code_cell(stubborn))
    path = tmp_path / "mallory" / "02_forward_euler.ipynb"
    path.parent.mkdir()
    nbformat.write(nb, path)
    grader = subprocess.Popen(
        [sys.executable, "-c", "import sys; from course_lib.instructor import grade_notebook; "
                               "grade_notebook(sys.argv[1], '02_forward_euler')", str(path)],
        cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        workers: list[int] = []
        deadline = time.monotonic() + 120
        while not workers and time.monotonic() < deadline and grader.poll() is None:
            time.sleep(0.2)
            workers = _children(grader.pid)
        assert workers, "the grader never started a sandboxed worker"
        marker = Path(f"/proc/{workers[0]}/cwd/looping")
        while not marker.exists() and time.monotonic() < deadline:
            time.sleep(0.2)
        assert marker.exists(), "the student's loop never started"
        os.kill(grader.pid, signal.SIGKILL)
        grader.wait()
        deadline = time.monotonic() + 10
        while any(_alive(w) for w in workers) and time.monotonic() < deadline:
            time.sleep(0.1)
        left = [w for w in workers if _alive(w)]
        assert not left, f"worker {left} outlived its grader"
    finally:
        if grader.poll() is None:
            grader.kill()
        for w in _children(grader.pid):
            os.kill(w, signal.SIGKILL)

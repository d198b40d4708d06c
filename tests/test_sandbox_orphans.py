"""A sandboxed submission dies with its grader: a worker that loses its parent (a grader or
Dask worker killed mid-run) ends its whole process group, even when the student's code
sleeps in a loop that swallows the time-limit alarm (no CPU used, so no rlimit stops it).
With the fork server the chain is longer (the server ends when its grader's socket closes;
each monitor then kills its worker's group); both ways are tested."""

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


def _descendants(pid: int) -> list[int]:
    """Every process below ``pid``: the fork server, its monitors and the workers, or the
    workers the grader started itself."""
    parents = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                parents[int(entry.name)] = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except OSError:
                continue
    found, todo = [], [pid]
    while todo:
        parent = todo.pop()
        children = [p for p, pp in parents.items() if pp == parent]
        found += children
        todo += children
    return found


def _looping(pids: list[int]) -> bool:
    for p in pids:
        try:
            if Path(f"/proc/{p}/cwd/looping").exists():
                return True
        except OSError:
            continue
    return False


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.parametrize("forks", [True, False], ids=["fork server", "python -I -S"])
def test_a_sleeping_submission_dies_with_its_grader(tmp_path, forks):
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
        [sys.executable, "-c", "import sys; from course_lib.instructor import forkserver, grade_notebook; "
                               f"forkserver.SUPPORTED = {forks}; "
                               "grade_notebook(sys.argv[1], '02_forward_euler')", str(path)],
        cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        below: list[int] = []
        deadline = time.monotonic() + 120
        while not _looping(below) and time.monotonic() < deadline and grader.poll() is None:
            time.sleep(0.2)
            below = _descendants(grader.pid)
        assert _looping(below), "the student's loop never started in a process of the grader's"
        os.kill(grader.pid, signal.SIGKILL)
        grader.wait()
        deadline = time.monotonic() + 10
        while any(_alive(p) for p in below) and time.monotonic() < deadline:
            time.sleep(0.1)
        left = [p for p in below if _alive(p)]
        assert not left, f"processes {left} (worker, fork server or monitor) outlived their grader"
    finally:
        if grader.poll() is None:
            grader.kill()
        for p in _descendants(grader.pid):
            os.kill(p, signal.SIGKILL)

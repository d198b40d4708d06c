"""The fork server (course_lib/instructor/forkserver.py) gives each submission the process
that ``python -I -S worker.py`` gave it: the same folder, environment, session, limits,
descriptors and signal handlers, a clock that starts at the fork, and nothing of the
submissions before it. (The same verdicts either way: the corpus and the other grading
tests run through the server; tests/test_sandbox_orphans.py runs both ways.)"""

from __future__ import annotations

import os
import re
from pathlib import Path
from types import SimpleNamespace

import pytest
from notebook_helpers import ROOT

from course_lib.instructor import forkserver
from course_lib.instructor.runtime import Runtime
from course_lib.instructor.sandbox import Limits, run_submission

pytestmark = pytest.mark.skipif(not forkserver.SUPPORTED, reason="the fork server needs Linux")

LOOK = '''
import os, resource, signal, sys, tempfile
here = os.getcwd()
print("folder is HOME and TMPDIR:", here == os.environ["HOME"] == os.environ["TMPDIR"]
      == tempfile.gettempdir(), os.listdir(here))
print("own session and group:", os.getsid(0) == os.getpid() == os.getpgid(0))
print("environment:", sorted(os.environ))
print("HOME inside the runtime:", os.environ["HOME"].startswith(os.environ["MPLCONFIGDIR"].rsplit("/", 1)[0]))
print("open descriptors:", sum(1 for fd in range(256) if not _closed(fd)))
print("limits:", resource.getrlimit(resource.RLIMIT_AS), resource.getrlimit(resource.RLIMIT_FSIZE),
      resource.getrlimit(resource.RLIMIT_CPU))
print("CPU seconds so far under 5:", sum(resource.getrusage(resource.RUSAGE_SELF)[:2]) < 5)
print("stdin empty:", sys.stdin.read() == "")
print("signals:", signal.getsignal(signal.SIGPIPE), signal.getsignal(signal.SIGCHLD),
      signal.getsignal(signal.SIGINT) is signal.default_int_handler)
print("flags:", sys.flags.isolated, sys.flags.no_site, sys.flags.ignore_environment)
print("path starts with the private copy:", sys.path[0].endswith("/lib"))
print("seen before:", "LEFT_BEHIND" in globals(), "leftover" in sys.modules)
LEFT_BEHIND = 1
sys.modules["leftover"] = sys
'''

DEFINE = '''
import os
def _closed(fd):
    try:
        os.fstat(fd)
        return False
    except OSError:
        return True
'''


def _run(runtime: Runtime, notebook: Path) -> list[str]:
    cells = [SimpleNamespace(index=0, source=DEFINE), SimpleNamespace(index=1, source=LOOK)]
    run = run_submission(runtime, notebook, cells, "course_lib.check.nb02", [], Limits(deadline=60))
    assert run.setup_error is None and run.violation is None, run
    assert run.cells[1]["status"] == "ok", run.cells[1]
    return run.cells[1]["output"].splitlines()


def test_a_forked_worker_is_what_a_new_one_was(tmp_path, monkeypatch):
    notebook = tmp_path / "02_forward_euler.ipynb"
    notebook.write_bytes((ROOT / "notebooks" / "02_forward_euler.ipynb").read_bytes())
    forked = Runtime(tmp_path / "forked")
    try:
        assert forked.forks is not None
        first, second = _run(forked, notebook), _run(forked, notebook)
    finally:
        forked.cleanup()
    monkeypatch.setattr(forkserver, "SUPPORTED", False)
    fresh = Runtime(tmp_path / "fresh")
    try:
        assert fresh.forks is None
        new = _run(fresh, notebook)
    finally:
        fresh.cleanup()

    def same(lines):        # the runtimes' folders differ by name only
        return [re.sub(r"/(forked|fresh)/", "/R/", line) for line in lines]

    assert same(first) == same(second) == same(new)
    for expected in ("folder is HOME and TMPDIR: True ['02_forward_euler.ipynb']",
                     "own session and group: True", "HOME inside the runtime: True",
                     "open descriptors: 5",          # 0-2, the channel, stdin's /dev/null
                     "CPU seconds so far under 5: True", "stdin empty: True", "flags: 1 1 1",
                     "path starts with the private copy: True",
                     "seen before: False False"):    # the second submission: nothing left
        assert expected in first, (expected, first)


def test_the_server_ends_with_its_runtime(tmp_path):
    runtime = Runtime(tmp_path / "r")
    server = runtime.forks.proc
    runtime.cleanup()
    assert server.poll() is not None, "the fork server outlived its runtime"
    assert not (tmp_path / "r").exists()


def test_a_runtime_never_cleaned_up_still_ends_its_server_at_exit(tmp_path):
    """A Dask worker's runtime is never cleaned up: at exit the server is still ended and
    waited for (its CPU time then counts in the worker's, for the grading benchmark)."""
    import subprocess
    import sys

    code = ("import sys; from course_lib.instructor.runtime import Runtime; "
            "r = Runtime(); r.ready(60); print(r.forks.proc.pid)")
    env = {**os.environ, "TMPDIR": str(tmp_path)}          # where its folder is left
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                         cwd=tmp_path, env=env, check=True)
    server = int(out.stdout.split()[-1])
    assert not Path(f"/proc/{server}").exists(), "the fork server outlived its grader's exit"

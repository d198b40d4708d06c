"""`make lab` serves the course: JupyterLab on 127.0.0.1, token required.

The server is started on port 0 (the system picks a free one, which the log names), so
that two tests, or two test runs, never race for a port another process grabs meanwhile.
"""

import contextlib
import json
import os
import re
import signal
import subprocess
import time
import urllib.error
import urllib.request

from notebook_helpers import ROOT


def get(url: str):
    try:
        with urllib.request.urlopen(url, timeout=5) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, b""


def test_make_lab_serves_with_token(tmp_path):
    token = "course-test-token"
    args = f"--no-browser --port=0 --IdentityProvider.token={token}"
    log = (tmp_path / "lab.log").open("w+")
    proc = subprocess.Popen(["make", "-s", "lab", f"LAB_ARGS={args}"], cwd=ROOT,
                            stdout=log, stderr=subprocess.STDOUT, start_new_session=True,
                            env={**os.environ, "JUPYTER_PLATFORM_DIRS": "1"})
    try:
        deadline = time.monotonic() + 90
        status, port = None, None
        while time.monotonic() < deadline and proc.poll() is None:
            log.seek(0)
            found = re.search(r"http://127\.0\.0\.1:(\d+)/", log.read())
            if found is None:
                time.sleep(0.5)
                continue
            port = int(found.group(1))
            base = f"http://127.0.0.1:{port}"
            try:
                status, body = get(f"{base}/api/status?token={token}")
                if status == 200:
                    break
            except OSError:
                pass
            time.sleep(0.5)
        log.seek(0)
        output = log.read()
        assert status == 200 and port, f"JupyterLab did not answer:\n{output}"
        assert "started" in json.loads(body)
        assert get(f"{base}/api/status")[0] == 403, "the API must require the token"
        assert get(f"{base}/api/contents/notebooks?token={token}")[0] == 200
        assert f"127.0.0.1:{port}" in output
        # the landing page opens the first notebook
        with urllib.request.urlopen(f"{base}/?token={token}", timeout=10) as r:
            assert r.status == 200
            assert r.geturl().split("?")[0].endswith("/lab/tree/notebooks/01_vector_fields.ipynb")
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
        log.close()

"""`make lab` serves the course: JupyterLab on 127.0.0.1, token required."""

import contextlib
import json
import os
import signal
import socket
import subprocess
import time
import urllib.error
import urllib.request

from notebook_helpers import ROOT


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def get(url: str):
    try:
        with urllib.request.urlopen(url, timeout=5) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, b""


def test_make_lab_serves_with_token(tmp_path):
    port, token = free_port(), "course-test-token"
    args = f"--no-browser --port={port} --IdentityProvider.token={token}"
    log = (tmp_path / "lab.log").open("w+")
    proc = subprocess.Popen(["make", "-s", "lab", f"LAB_ARGS={args}"], cwd=ROOT,
                            stdout=log, stderr=subprocess.STDOUT, start_new_session=True,
                            env={**os.environ, "JUPYTER_PLATFORM_DIRS": "1"})
    try:
        base = f"http://127.0.0.1:{port}"
        deadline = time.monotonic() + 60
        status = None
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                status, body = get(f"{base}/api/status?token={token}")
                if status == 200:
                    break
            except OSError:
                pass
            time.sleep(0.5)
        log.seek(0)
        output = log.read()
        assert status == 200, f"JupyterLab did not answer:\n{output}"
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

"""Debian's Chromium for the browser tests: installed with apt-get when missing, once.

``python3 tools/chromium.py`` installs it (as root, with apt-get) unless ``/usr/bin/chromium``
is already there, and prints why not otherwise. ``make test`` starts it in the background
while pip sets up ``.venv``, so that the download overlaps the setup; the browser tests
(``tests/browser/conftest.py``) call :func:`ensure` too, which waits on the same lock file
for an install in progress. No browser is ever downloaded from anywhere but Debian's
mirrors. Standard library only (it runs before ``.venv`` exists).
"""

from __future__ import annotations

import fcntl
import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = Path("/usr/bin/chromium")
LOCK = ROOT / "build" / "chromium-install.lock"
HOW = "install Debian's Chromium (`sudo apt-get install -y chromium`) and run `make test-browser`"


def ensure() -> str | None:
    """None when Chromium is there (installing it with apt-get if we may), else why not."""
    if CHROMIUM.exists():
        return None
    if os.geteuid() != 0 or shutil.which("apt-get") is None:
        return f"browser tests skipped: /usr/bin/chromium is missing; {HOW}"
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    LOCK.parent.mkdir(exist_ok=True)
    with LOCK.open("w") as held:   # one install at a time (xdist workers, make test's start)
        fcntl.flock(held, fcntl.LOCK_EX)
        if CHROMIUM.exists():
            return None
        subprocess.run(["apt-get", "update", "-qq"], env=env, capture_output=True)
        done = subprocess.run(["apt-get", "install", "-y", "-qq", "chromium"], env=env,
                              capture_output=True, text=True)
    if done.returncode != 0 or not CHROMIUM.exists():
        return f"browser tests skipped: `apt-get install chromium` failed ({done.stderr[-300:]}); {HOW}"
    return None


if __name__ == "__main__":
    why = ensure()
    print(why or f"chromium: {CHROMIUM} is ready")
    sys.exit(0)

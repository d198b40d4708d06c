"""A separate venv holding a pinned nbgrader, made once (standard library only).

nbgrader's dependencies must never enter the course's ``.venv``, so the export's tests
(and an instructor who wants to run nbgrader) use their own venv. Making it is a pip
install of about a minute: ``make test`` starts it in the background while pip sets up
``.venv`` (``python3 course_lib/instructor/nbgrader_venv.py .venv-nbgrader``, run by path,
so that nothing of the package, NumPy included, is imported), and :func:`ensure` waits
for an install in progress on a lock file instead of starting a second one.
"""

from __future__ import annotations

import fcntl
import subprocess
import sys
from pathlib import Path

#: The nbgrader release whose behaviour the export is tested against.
NBGRADER_VERSION = "0.9.6"


def ensure(venv: Path, version: str = NBGRADER_VERSION, python: str = sys.executable) -> Path:
    """The ``nbgrader`` command of ``venv`` holding nbgrader ``version`` (made if needed)."""
    venv = Path(venv)
    exe, stamp = venv / "bin" / "nbgrader", venv / f".nbgrader-{version}"
    if exe.exists() and stamp.exists():
        return exe
    lock = venv.parent / f".{venv.name}.lock"
    with lock.open("w") as held:
        fcntl.flock(held, fcntl.LOCK_EX)       # another process may be making it now
        if exe.exists() and stamp.exists():
            return exe
        subprocess.run([python, "-m", "venv", "--clear", str(venv)], check=True)
        subprocess.run([str(venv / "bin" / "python"), "-m", "pip", "install", "--quiet",
                        "--disable-pip-version-check", f"nbgrader=={version}"], check=True)
        stamp.write_text(f"nbgrader=={version}\n")
    return exe


if __name__ == "__main__":
    print(f"nbgrader: {ensure(Path(sys.argv[1] if len(sys.argv) > 1 else '.venv-nbgrader'))}")

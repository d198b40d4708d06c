"""Time the stages of ``make test`` and print where the time went.

``python3 tools/stage.py run NAME -- CMD ...`` runs CMD, records its wall time and the CPU
time (user + system) of every process it waited for (pytest, its xdist workers, kernels,
servers), and exits with CMD's code; pytest's 5 ("no tests collected") counts as a pass.
``reset`` starts a new record (and notes the time); ``summary`` prints the table: each
stage's own times, their sums, and the time elapsed since ``reset`` (less than the sum of
the walls when a stage ran alongside others). Standard library only, so it also times the
setup that creates ``.venv``. The record is ``build/test-stages.tsv``.

``reset`` also notes what ``git status`` shows, and ``summary`` fails (exit 1) naming every
file that make test left in the checkout: new, changed or deleted, and not ignored. The
tests write only to temporary and ignored folders; a stray file (a lock, a cache, a
notebook rewritten in place) would otherwise show up only in a developer's next commit.
Outside a git checkout (a tarball) the check is skipped.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "build" / "test-stages.tsv"
STATUS = ROOT / "build" / "test-status-before.txt"
NO_TESTS = 5  # pytest: nothing collected (e.g. a folder without notebooks yet)


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run(name: str, cmd: list[str]) -> int:
    cpu0, wall0 = _children_cpu(), time.monotonic()
    code = subprocess.call(cmd)
    wall, cpu = time.monotonic() - wall0, _children_cpu() - cpu0
    if code == NO_TESTS:
        print(f"{name}: pytest collected no tests (exit 5); not a failure of the kit")
        code = 0
    RECORD.parent.mkdir(exist_ok=True)
    with RECORD.open("a") as out:
        out.write(f"{name}\t{wall:.1f}\t{cpu:.1f}\t{code}\n")
    return code


def checkout_status(root: Path = ROOT) -> list[str] | None:
    """``git status --porcelain`` of ``root`` (every untracked file listed), or None when it
    is not a git checkout or git is missing."""
    try:
        out = subprocess.run(["git", "status", "--porcelain=v1", "--untracked-files=all"],
                             cwd=root, capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.SubprocessError):
        return None
    return sorted(out.stdout.splitlines()) if out.returncode == 0 else None


def left_behind(before: list[str] | None, after: list[str] | None) -> list[str]:
    """The status lines of ``after`` that ``before`` did not have: what a run left."""
    if before is None or after is None:
        return []
    return sorted(set(after) - set(before))


def summary() -> str:
    rows = [line.split("\t") for line in RECORD.read_text().splitlines()] \
        if RECORD.exists() else []
    started = [float(r[1]) for r in rows if r[0] == "#started"]
    rows = [r for r in rows if not r[0].startswith("#")]
    lines = [f"make test, per stage ({os.cpu_count()} cores): wall time, CPU time of its "
             "processes, result", f"  {'stage':<18}{'wall':>9}{'CPU':>9}"]
    wall = cpu = 0.0
    for name, w, c, code in rows:
        wall, cpu = wall + float(w), cpu + float(c)
        verdict = "ok" if code == "0" else f"FAILED (exit {code})"
        lines.append(f"  {name:<18}{float(w):>8.1f}s{float(c):>8.1f}s  {verdict}")
    lines.append(f"  {'sum':<18}{wall:>8.1f}s{cpu:>8.1f}s  ({wall / 60:.1f} min)")
    if started:
        elapsed = time.time() - started[0]
        lines.append(f"  {'elapsed':<18}{elapsed:>8.1f}s{'':>9}  ({elapsed / 60:.1f} min)")
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    if argv[:1] == ["reset"]:
        RECORD.parent.mkdir(exist_ok=True)
        RECORD.write_text(f"#started\t{time.time():.1f}\n")
        status = checkout_status()
        STATUS.unlink(missing_ok=True)
        if status is not None:
            STATUS.write_text("".join(line + "\n" for line in status))
        return 0
    if argv[:1] == ["summary"]:
        print(summary())
        before = STATUS.read_text().splitlines() if STATUS.exists() else None
        left = left_behind(before, checkout_status())
        if left:
            print("make test left these in the checkout (not ignored; git status --porcelain):\n"
                  + "\n".join(f"  {line}" for line in left)
                  + "\nwrite them under build/ or a temporary folder, or ignore them in .gitignore")
            return 1
        return 0
    if len(argv) >= 4 and argv[0] == "run" and argv[2] == "--":
        return run(argv[1], argv[3:])
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

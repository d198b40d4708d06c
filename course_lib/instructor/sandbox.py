"""Running one submission in the worker: isolation, limits, deadlines, restarts.

:class:`~.runtime.Runtime` (:mod:`.runtime`) is prepared once per grading run, in a
private temporary folder outside the kit. :func:`run_submission` then gives each submission

- a fresh working folder holding only a copy of the notebook (``HOME`` and ``TMPDIR``
  point there), a scrubbed environment and a fresh ``python -I -S`` process (no user site,
  no ``.pth`` files, no script folder on the path), forked by the runtime's fork server
  (:mod:`.forkserver`) after the libraries were imported once;
- limits: address space, CPU seconds, file size, output kept per cell, a time limit per
  cell and per exercise (an alarm in the worker, then a kill), and a deadline for the
  whole notebook; on Linux with Landlock, reads only below the Python installation, the
  site-packages and the private course_lib, writes only in its folder, no programs, no
  signals outside itself; and with seccomp, no socket of any kind (no network: TCP, UDP,
  DNS, raw or Unix-domain);
- restarts: if the process dies or must be killed in a cell, it is started again without
  that cell; in an exercise, that exercise is recorded as lost and the rest continue.

Messages from the worker are checked (signature, order); anything else is a protocol
violation, which the grader treats as tampering. Imports: the standard library.
"""

from __future__ import annotations

import contextlib
import hashlib
import hmac
import json
import os
import secrets
import selectors
import shutil
import signal
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from .runtime import Runtime, remove_tree

#: A cell's or an exercise's budget is CPU seconds (the worker's profiling timer); the wall
#: clock may run this many times longer before the grader kills the process, which stops
#: code that waits without computing, while a busy machine does not fail a correct answer
#: (and the time the process spent waiting for a CPU, :func:`queued_seconds`, is added).
WAIT_FACTOR = 3.0


@dataclass
class Limits:
    """Resource limits for one submission (seconds, megabytes, characters).

    ``cell_s`` and ``exercise_s`` are CPU seconds (at most :data:`WAIT_FACTOR` times as
    many on the wall clock); ``deadline`` is the whole notebook's wall-clock time.
    """

    deadline: float = 180.0
    cell_s: float = 30.0
    exercise_s: float = 20.0
    memory_mb: int = 2048
    file_mb: int = 16
    output_chars: int = 20_000
    value_bytes: int = 8 << 20
    attempts: int = 4
    grace: float = 3.0


@dataclass
class Run:
    """What the worker reported for one submission, over all its attempts."""

    cells: dict[int, dict] = field(default_factory=dict)
    exercises: dict[str, dict] = field(default_factory=dict)
    changes: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    violation: str | None = None
    setup_error: str | None = None
    out_of_time: bool = False
    landlock: int = 0
    sockets_denied: bool = False
    seconds: float = 0.0
    attempts: int = 0


class _Attempt:
    """One worker process: its messages so far and where it is."""

    def __init__(self, key: str, pid: int | None = None):
        self.key, self.seq, self.buffer = key.encode(), 0, b""
        self.pid = pid
        self.phase: tuple[str, object] | None = ("setup", None)
        self.mark()
        self.ready = self.done = False

    def mark(self) -> None:
        """A new phase starts now: its clock, and the CPU queueing it will not be charged."""
        self.phase_start = time.monotonic()
        self.queued_start = self.credit = queued_seconds(self.pid)

    def lines(self, data: bytes, max_line: int) -> list[dict]:
        self.buffer += data
        *complete, self.buffer = self.buffer.split(b"\n")
        if len(self.buffer) > max_line:
            raise ValueError("a message from the worker is too long")
        out = []
        for line in complete:
            mac, _, payload = line.partition(b" ")
            good = hmac.new(self.key, payload, hashlib.sha256).hexdigest()[:32].encode()
            if not hmac.compare_digest(mac, good):
                raise ValueError("a message on the grader's channel is not signed by the worker")
            msg = json.loads(payload)
            self.seq += 1
            if not isinstance(msg, dict) or msg.get("seq") != self.seq:
                raise ValueError("messages on the grader's channel are out of sequence")
            out.append(msg)
        return out


_SIGNALS = {int(s): s.name for s in signal.Signals}


def _describe(code: int | None) -> str:
    if code is None:
        return "was stopped"
    if code < 0:
        name = _SIGNALS.get(-code, f"signal {-code}")
        why = {"SIGSEGV": "a crash", "SIGKILL": "killed", "SIGXCPU": "its CPU time limit",
               "SIGABRT": "an abort", "SIGBUS": "a crash"}.get(name, "a signal")
        return f"died ({name}: {why})"
    return f"exited with code {code}"


def run_submission(runtime: Runtime, notebook_file: Path, cells: list, check_module: str,
                   exercises: list, limits: Limits) -> Run:
    """Run a submission's code cells and its exercises in workers (see the module docstring)."""
    run = Run(landlock=runtime.landlock)
    start = time.monotonic()
    skip_cells: set[int] = set()
    while run.attempts < limits.attempts:
        left = limits.deadline - (time.monotonic() - start)
        if left <= 0:
            run.out_of_time = True
            break
        run.attempts += 1
        finished = _attempt(runtime, notebook_file, cells, check_module, exercises, limits,
                            skip_cells, left, run)
        if finished or run.violation or run.setup_error or run.out_of_time:
            break
    run.seconds = time.monotonic() - start
    return run


def _attempt(runtime, notebook_file, cells, check_module, exercises, limits, skip_cells, left, run) -> bool:
    workdir = Path(tempfile.mkdtemp(dir=runtime.work))
    shutil.copy(notebook_file, workdir / Path(notebook_file).name)
    key = secrets.token_hex(16)
    job = {
        "key": key, "sys_path": runtime.sys_path, "check_module": check_module,
        "workdir": str(workdir), "landlock": {"read": runtime.read, "write": [str(workdir)]},
        "limits": {"memory_mb": limits.memory_mb, "file_mb": limits.file_mb,
                   "cpu_s": max(int(left) + 2, 3), "cell_s": limits.cell_s,
                   "exercise_s": limits.exercise_s, "output_chars": limits.output_chars,
                   "value_bytes": limits.value_bytes},
        "cells": [{"index": c.index, "source": c.source} for c in cells],
        "skip_cells": sorted(skip_cells),
        "exercises": [{"name": e.name, "check": e.check} for e in exercises],
        "skip_exercises": sorted(run.exercises),
    }
    read_fd, write_fd = os.pipe()
    log = open(workdir.parent / f"{workdir.name}.log", "wb")  # closed below
    try:
        proc, stdin = runtime.start(workdir, check_module, write_fd, log)
    finally:
        os.close(write_fd)
    state = _Attempt(key, proc.pid)
    reason = None
    try:
        try:
            stdin.write(json.dumps(job).encode())
        except BrokenPipeError:
            pass
        finally:
            with contextlib.suppress(BrokenPipeError):
                stdin.close()
        reason = _watch(proc, read_fd, state, run, limits, time.monotonic() + left)
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        code = proc.wait()
        os.close(read_fd)
        log.close()
        tail = (workdir.parent / f"{workdir.name}.log").read_bytes()[-1500:].decode("utf-8", "replace")
        remove_tree(workdir)
        (workdir.parent / f"{workdir.name}.log").unlink(missing_ok=True)
    if state.done:
        return True
    kind, what = state.phase or ("setup", None)
    how = reason or f"the notebook's process {_describe(code)}"
    if not state.ready:
        if not run.violation:
            run.setup_error = f"{how} before running any student code: {tail.strip()[-600:]}"
        return False
    if kind == "cell":
        skip_cells.add(what)
        run.cells[what] = {"status": "killed", "output": "", "dropped": 0,
                           "error": f"{how}; the grader ran the notebook again without this cell"}
    elif kind == "exercise":
        run.exercises[what] = {"name": what, "lost": how, "timeout": "time" in how}
    return False


#: Whether this kernel reports the time a process waited for a CPU (Linux schedstat).
COUNTS_QUEUEING = Path("/proc/self/schedstat").exists()


def queued_seconds(pid: int | None) -> float:
    """Seconds the threads of process ``pid`` have spent runnable but waiting for a CPU
    (``/proc/PID/task/*/schedstat``, Linux); 0.0 where the kernel does not say."""
    if pid is None or not COUNTS_QUEUEING:
        return 0.0
    total = 0
    try:
        tasks = list(os.scandir(f"/proc/{pid}/task"))
    except OSError:
        return 0.0
    for task in tasks:
        try:
            with open(f"{task.path}/schedstat") as f:
                total += int(f.read().split()[1])
        except (OSError, ValueError, IndexError):
            pass
    return total / 1e9


def _watch(proc, fd, state: _Attempt, run: Run, limits: Limits, deadline: float) -> str | None:
    """Read the worker's messages until it ends; return why it was killed, if it was."""
    sel = selectors.DefaultSelector()
    sel.register(fd, selectors.EVENT_READ)
    try:
        while True:
            now = time.monotonic()
            kind = state.phase[0] if state.phase else None
            budget = {"cell": limits.cell_s, "exercise": limits.exercise_s, "setup": 120.0}.get(kind, 30.0)
            waited = WAIT_FACTOR * budget if kind in ("cell", "exercise") else budget
            # the time the worker waited for a CPU is not its own: a busy grading machine
            # must not turn a computing loop's CPU timeout into a wall-clock kill
            phase_end = state.phase_start + waited + limits.grace + (state.credit - state.queued_start)
            if now >= deadline:
                run.out_of_time = True
                return f"the notebook ran out of its {limits.deadline:g} s"
            if now >= phase_end:
                queued = queued_seconds(proc.pid)
                if queued > state.credit + 0.01:
                    state.credit = queued
                    continue
                return f"killed after {waited:g} s (time limit)"
            if not sel.select(timeout=min(deadline, phase_end) - now):
                continue
            data = os.read(fd, 1 << 20)
            if not data:
                return None
            try:
                for msg in state.lines(data, 64 << 20):
                    _apply(msg, state, run)
            except (ValueError, TypeError, KeyError) as exc:
                run.violation = f"the notebook's process broke the grading protocol ({exc})"
                return run.violation
    finally:
        sel.close()


def _apply(msg: dict, state: _Attempt, run: Run) -> None:
    event = msg.get("event")
    expected = {"ready": state.phase == ("setup", None) and not state.ready}
    if state.done or (event in expected and not expected[event]):
        raise ValueError(f"unexpected {event!r} message")
    state.mark()
    if event == "ready":
        state.ready, state.phase = True, None
        run.landlock = int(msg.get("landlock", 0))
        run.sockets_denied = bool(msg.get("sockets_denied", False))
    elif event == "cell_start" and state.ready and state.phase is None:
        state.phase = ("cell", int(msg["cell"]))
    elif event == "cell_end" and state.phase == ("cell", msg.get("cell")):
        run.cells[int(msg["cell"])] = {k: msg.get(k) for k in ("status", "error", "output", "dropped")}
        state.phase = None
    elif event == "changes" and state.phase is None:
        run.changes += [str(c)[:300] for c in msg.get("found", []) if str(c)[:300] not in run.changes]
    elif event == "exercise_start" and state.ready and state.phase is None:
        state.phase = ("exercise", str(msg["name"]))
    elif event == "exercise_end" and state.phase == ("exercise", msg.get("name")):
        run.exercises[str(msg["name"])] = msg
        state.phase = None
    elif event == "done" and state.phase is None and state.ready:
        state.done = True
    else:
        raise ValueError(f"unexpected {event!r} message")

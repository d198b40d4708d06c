"""A fork server for the sandboxed workers: the libraries are imported once per grading run.

Every submission runs in a fresh worker process (:mod:`.worker`). Started with
``python -I -S``, each spent about 1.2 s of CPU importing numpy, matplotlib's pyplot, scipy
and course_lib before running a line of student code, which made the start-up most of the
cost of grading a class. Here one *server* process, started per :class:`.sandbox.Runtime`
from the same private copy of course_lib, in the same scrubbed environment and with the
same ``-I -S``, imports all of that once and then forks a worker for each request.

What the worker gets is what a fresh ``python -I -S worker.py FD`` got: its own session
(process group), the job on its standard input, its output in the grader's log file, the
signed channel on FD, the submission's folder as working folder and the environment the
grader gives; :func:`.worker.main` then sets the limits and closes the sandbox (Landlock,
seccomp) exactly as before. A forked worker starts with no other file descriptor open (it
checks, and refuses to run otherwise) and with a fresh CPU clock.

The server holds nothing of a submission: the job (the key, the student's code) goes from
the grader straight into the worker's standard input. A request carries only the working
folder and the environment, and four descriptors (``SCM_RIGHTS`` on a Unix socket pair):
the job pipe, the channel, the log and a *status* pipe. Between server and worker sits a
small monitor process that writes the worker's pid on the status pipe, waits for the worker
to end, and writes its exit code (as :class:`subprocess.Popen` reports it: minus the signal
number when killed). The monitor kills the worker's process group when the server goes
away, and the server exits when the grader closes its socket (or dies), so no worker
outlives the grader.

The grader side is :class:`ForkServer`; ``python -I -S forkserver.py FD PATH...`` is the
server. Linux only (``fork``, ``socket.send_fds``, Landlock); elsewhere the sandbox starts
each worker with ``subprocess`` as before. Imports (grader side): the standard library.
"""

from __future__ import annotations

import json
import os
import select
import signal
import socket
import subprocess
import sys
import threading
import time

#: Whether workers can be forked here (Linux: ``fork``, ``pidfd``, descriptors over sockets).
SUPPORTED = sys.platform == "linux" and hasattr(socket, "send_fds")

#: The modules every worker needs before it runs student code; a request also names its
#: assignment's check module, which the server imports before the first worker that uses it.
PRELOAD = ("numpy", "matplotlib.pyplot", "course_lib.check", "course_lib.instructor.worker",
           "course_lib.instructor.landlock", "course_lib.instructor.seccomp",
           "course_lib.instructor.recorder", "course_lib.instructor.scan")


class ForkServer:
    """The grader's handle on one server process (thread-safe).

    Parameters
    ----------
    script : path
        This file, in the runtime's private copy of course_lib.
    sys_path : list of str
        The server's import path (the private copy first, then site-packages).
    env : dict
        The server's environment (the runtime's scrubbed one).
    log : path
        Where the server's own output goes (import errors, for the grader's messages).
    """

    def __init__(self, script, sys_path: list[str], env: dict, log) -> None:
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        with open(log, "wb") as out:
            self.proc = subprocess.Popen(
                [sys.executable, "-I", "-S", str(script), str(theirs.fileno()), *sys_path],
                stdin=subprocess.DEVNULL, stdout=out, stderr=out, env=env,
                pass_fds=(theirs.fileno(),), start_new_session=True)
        theirs.close()
        self.sock, self.log, self._lock, self._ready = ours, log, threading.RLock(), False

    def wait_ready(self, timeout: float) -> None:
        """Wait for the server's "ready" (its imports done); OSError if it never comes."""
        with self._lock:
            if self._ready:
                return
            self.sock.settimeout(timeout)
            try:
                ready = self.sock.recv(6)
            except TimeoutError:
                ready = b""
            finally:
                self.sock.settimeout(None)
            if ready != b"ready\n":
                raise OSError("the fork server did not start: " + _tail(self.log))
            self._ready = True

    def spawn(self, cwd: str, env: dict, module: str, stdin_fd: int, channel_fd: int,
              log_fd: int, timeout: float = 120.0) -> Worker:
        """Fork a worker for a job of check module ``module``; the caller then writes the
        job into ``stdin_fd``'s pipe and may close its copies of the three descriptors."""
        status_r, status_w = os.pipe()
        try:
            with self._lock:
                self.wait_ready(timeout)
                request = json.dumps({"cwd": cwd, "env": env, "module": module}).encode() + b"\n"
                socket.send_fds(self.sock, [request], [stdin_fd, channel_fd, log_fd, status_w])
        except BaseException:
            os.close(status_r)
            raise
        finally:
            os.close(status_w)
        return Worker(status_r, timeout)

    def close(self) -> None:
        """End the server (its workers' monitors then kill what is left of them)."""
        self.sock.close()
        try:
            self.proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()


class Worker:
    """A forked worker, as the grader sees it: ``pid`` (its process group too), ``wait()``."""

    def __init__(self, status_fd: int, timeout: float) -> None:
        self._fd, self._buffer, self.returncode = status_fd, b"", None
        line = self._line(timeout)
        if not line:
            os.close(self._fd)
            raise OSError("the fork server could not start a worker")
        self.pid = int(line)

    def _line(self, timeout: float | None) -> bytes:
        end = None if timeout is None else time.monotonic() + timeout
        while b"\n" not in self._buffer:
            left = None if end is None else max(0.0, end - time.monotonic())
            if not select.select([self._fd], [], [], left)[0]:
                return b""
            data = os.read(self._fd, 64)
            if not data:
                return b""
            self._buffer += data
        line, _, self._buffer = self._buffer.partition(b"\n")
        return line

    def wait(self) -> int | None:
        """The worker's exit code once it has ended (``None`` if its monitor died)."""
        if self.returncode is None and self._fd >= 0:
            line = self._line(None)
            os.close(self._fd)
            self._fd = -1
            self.returncode = int(line) if line else None
        return self.returncode


def _tail(path) -> str:
    try:
        with open(path, "rb") as f:
            return f.read()[-600:].decode("utf-8", "replace").strip() or "(no output)"
    except OSError:
        return "(no log)"


# --- the server (runs as a script in the runtime's private copy of course_lib) -----------

def _open_fds() -> set[int]:
    found = set()
    for name in os.listdir("/proc/self/fd"):
        try:
            os.fstat(int(name))       # (the listing's own descriptor is closed by now)
            found.add(int(name))
        except OSError:
            pass
    return found


def _worker(sock: socket.socket, fds: list[int], request: dict) -> None:
    """In the forked worker: become what ``Popen(..., start_new_session=True)`` made."""
    import tempfile

    from course_lib.instructor import worker

    stdin_fd, channel_fd, log_fd, status_fd = fds
    sock.close()
    os.close(status_fd)
    os.setsid()
    os.dup2(stdin_fd, 0)
    os.dup2(log_fd, 1)
    os.dup2(log_fd, 2)
    os.close(stdin_fd)
    os.close(log_fd)
    extra = _open_fds() - {0, 1, 2, channel_fd}
    if extra:
        raise RuntimeError(f"a forked worker holds descriptors it must not: {sorted(extra)}")
    os.chdir(request["cwd"])
    os.environ.clear()
    os.environ.update(request["env"])
    tempfile.tempdir = None            # found again from TMPDIR, the submission's folder
    sys.argv = [worker.__file__, str(channel_fd)]
    worker.main()


def _monitor(sock: socket.socket, fds: list[int], request: dict) -> None:
    """In the monitor: fork the worker, report its pid and later its exit code."""
    server = os.getppid()
    pid = os.fork()
    if pid == 0:
        try:
            _worker(sock, fds, request)
        except BaseException as exc:  # nothing may return into the server
            os.write(2, f"forked worker: {type(exc).__name__}: {exc}\n".encode())
        finally:
            os._exit(70)
    sock.close()
    status_fd = fds[3]
    for fd in fds[:3]:
        os.close(fd)
    os.write(status_fd, f"{pid}\n".encode())
    try:
        ended = os.pidfd_open(pid)
    except (AttributeError, OSError):                  # Linux before 5.3: poll
        ended = None
    while not _ended(pid, ended):
        if os.getppid() != server:                    # the server (so the grader) is gone
            os.killpg(pid, signal.SIGKILL)
    try:
        os.killpg(pid, signal.SIGKILL)                # whatever it forked, while the group lives
    except (ProcessLookupError, PermissionError):
        pass
    _, status = os.waitpid(pid, 0)
    os.write(status_fd, f"{os.waitstatus_to_exitcode(status)}\n".encode())


def _ended(pid: int, pidfd: int | None) -> bool:
    """Whether worker ``pid`` has ended (not reaped: its process group lives on meanwhile),
    after waiting up to half a second."""
    if pidfd is not None:
        select.select([pidfd], [], [], 0.5)
    else:
        time.sleep(0.05)
    return os.waitid(os.P_PID, pid, os.WEXITED | os.WNOWAIT | os.WNOHANG) is not None


def _reap() -> int:
    """Reap the monitors that have ended (their CPU time, and their workers', then counts
    in this server's and so in the grader's); return how many are still running."""
    while True:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return 0
        if pid == 0:
            return 1


def serve(sock_fd: int, sys_path: list[str]) -> None:
    """The server's loop: import, say ready, fork a monitor per request until EOF."""
    import importlib

    sys.path[:0] = sys_path[:1]
    sys.path.extend(sys_path[1:])
    import matplotlib

    matplotlib.use("Agg")
    for name in PRELOAD:
        importlib.import_module(name)
    sock = socket.socket(fileno=sock_fd)
    sock.sendall(b"ready\n")
    while True:
        _reap()
        request, fds, _, _ = socket.recv_fds(sock, 1 << 16, 4)
        if not request:                                # the grader closed its end or died
            end = time.monotonic() + 1.0
            while _reap() and time.monotonic() < end:  # (a monitor whose worker still runs
                time.sleep(0.02)                       # ends once this server has gone)
            return
        if len(fds) != 4:
            for fd in fds:
                os.close(fd)
            continue
        request = json.loads(request)
        if str(request.get("module", "")).startswith("course_lib.check.") and \
                request["module"] not in sys.modules:
            try:
                importlib.import_module(request["module"])
            except Exception:  # the worker imports it again and says why
                pass
        sys.stdout.flush()
        sys.stderr.flush()
        if os.fork() == 0:
            try:
                _monitor(sock, fds, request)
            finally:
                os._exit(0)
        for fd in fds:
            os.close(fd)


if __name__ == "__main__":
    serve(int(sys.argv[1]), sys.argv[2:])

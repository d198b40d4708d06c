"""The sandboxed worker: runs one submission and records what its exercise functions return.

Started by :mod:`.sandbox` as ``python -I -S worker.py FD`` with a job (JSON) on stdin;
never imported by the grader. It sets its import path (a private copy of course_lib and
the environment's site-packages, nothing from the submission's folder), its resource
limits, imports the libraries and the assignment's checks, then gives up file system and
network rights (:mod:`.landlock`, then :mod:`.seccomp` for the sockets Landlock does not
cover) before running a single line of student code, with no other thread alive.

It then executes the student's code cells in order (errors allowed, each cell under a
time limit; the notebook's own ``check.…(…)`` calls do nothing here), and for each
exercise runs the kit's check with a *recorder* (:mod:`.recorder`) in place of the
student's function: it calls the student's function and keeps, per call, a summary of the
arguments, the returned value (:mod:`.codec`), any exception, any change to its
arguments and the calls it made to function arguments. Only these records go back to the
grader (HMAC-signed JSON lines on pipe FD);
the grader replays them into the same check in its own process to decide the verdict.
The worker decides nothing about grades. Imports: stdlib first, then numpy, matplotlib,
course_lib (from the private copy).
"""

import builtins
import hashlib
import hmac
import importlib
import json
import linecache
import os
import resource
import signal
import sys
import threading
import time
import types

_dumps, _write, _hmac_new = json.dumps, os.write, hmac.new  # bound before any student code


class Alarm:
    armed = False

    exception: type = BaseException  # the recorder's Timeout, set once imports are possible

    @staticmethod
    def handler(signum, frame):
        if Alarm.armed:
            Alarm.armed = False
            raise Alarm.exception()

    @staticmethod
    def arm(seconds: float) -> None:
        Alarm.armed = True
        # CPU time of this process, not the wall clock: a correct answer must not time out
        # because the grading machine is busy (a wall-clock limit of 6 s failed one under a
        # load of 11). Code that waits without computing is stopped by the grader's wall
        # watch (sandbox.WAIT_FACTOR times the budget).
        signal.setitimer(signal.ITIMER_PROF, max(seconds, 0.01))

    @staticmethod
    def disarm() -> None:
        Alarm.armed = False
        signal.setitimer(signal.ITIMER_PROF, 0)


class Channel:
    """Signed, numbered JSON lines to the grader."""

    def __init__(self, fd: int, key: str):
        self.fd, self.key, self.seq = fd, key.encode(), 0

    def send(self, body: dict) -> None:
        self.seq += 1
        payload = _dumps({"seq": self.seq, **body}, separators=(",", ":")).encode()
        view = memoryview(_hmac_new(self.key, payload, hashlib.sha256).hexdigest()[:32].encode()
                          + b" " + payload + b"\n")
        while view:
            view = view[_write(self.fd, view):]


def set_limits(limits: dict) -> None:
    mb = 1 << 20
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    resource.setrlimit(resource.RLIMIT_AS, (limits["memory_mb"] * mb, limits["memory_mb"] * mb))
    resource.setrlimit(resource.RLIMIT_FSIZE, (limits["file_mb"] * mb, limits["file_mb"] * mb))
    cpu = int(limits["cpu_s"])
    resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 5))
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails, not the process


def snapshot(check_module: str) -> dict:
    """Identity of course_lib's modules, of everything in the checker's and the grader's
    modules (the library's own globals may legitimately change), Checker and builtins."""
    from course_lib.check import Checker

    watched = ("course_lib.check", "course_lib.instructor")
    state = {name: (id(mod), {k: id(v) for k, v in vars(mod).items()} if name.startswith(watched) else {})
             for name, mod in list(sys.modules.items())
             if name == "course_lib" or name.startswith("course_lib.")}
    state["<Checker>"] = (0, {k: id(v) for k, v in vars(Checker).items()})
    state["<builtins>"] = (0, {k: id(v) for k, v in vars(builtins).items()})
    return state


def compare(before: dict, check_module: str) -> list[str]:
    """What student code changed in course_lib, the checker or builtins since ``before``."""
    now = snapshot(check_module)
    found = []
    for name, (ident, attrs) in before.items():
        if name not in now or (ident and now[name][0] != ident):
            found.append(f"sys.modules[{name!r}] was replaced")
            continue
        for key, value in attrs.items():
            if now[name][1].get(key) != value:
                found.append(f"{name.strip('<>')}.{key} was changed or deleted")
    from course_lib.check import RESULTS

    short = check_module.rsplit(".", 1)[-1] + "."
    found += [f"course_lib.check.RESULTS[{k!r}] was written" for k in list(RESULTS) if k.startswith(short)]
    return found[:20]


def watch_parent(parent: int, period: float = 0.5) -> None:
    """End this process group if the grader that started it (pid ``parent``) dies (the
    worker is then adopted by another process). A killed Dask worker or grader must not
    leave a submission running: its limits stop a busy loop, but not one that sleeps. A
    thread that polls ``getppid`` rather than ``PR_SET_PDEATHSIG``, which fires when the
    parent's *thread* ends, and the grader starts workers from pool threads.

    Started only once the sandbox is closed: Landlock confines the thread that asks and the
    threads it starts afterwards, so a thread started before would run unconfined, and
    student code can make it run its own functions (through ``os.getppid`` or the
    closure's cells)."""
    getppid, killpg, getpgid, sleep = os.getppid, os.killpg, os.getpgid, time.sleep

    def run() -> None:
        while True:
            sleep(period)
            if getppid() != parent:
                killpg(getpgid(0), signal.SIGKILL)

    threading.Thread(target=run, name="parent-watch", daemon=True).start()


def only_thread() -> None:
    """Refuse to close the sandbox with another thread alive (it would stay unconfined)."""
    try:
        tasks = os.listdir("/proc/self/task")
    except OSError:
        tasks = [0] * threading.active_count()
    if len(tasks) != 1:
        raise RuntimeError(f"{len(tasks)} threads before the sandbox closes: they would run unconfined")


def main() -> None:
    parent = os.getppid()
    channel_fd = int(sys.argv[1])
    job = json.loads(sys.stdin.read())
    sys.stdin = open(os.devnull)  # student code that reads stdin gets nothing
    channel = Channel(channel_fd, job.pop("key"))
    sys.path[:0] = job["sys_path"][:1]
    sys.path.extend(job["sys_path"][1:])
    set_limits(job["limits"])
    signal.signal(signal.SIGPROF, Alarm.handler)

    import matplotlib
    import numpy  # noqa: F401 (loaded before the sandbox closes, like matplotlib)

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from course_lib.check import evaluate
    from course_lib.instructor import landlock, seccomp
    from course_lib.instructor.recorder import Capture, Recorder, Timeout, excerpt
    from course_lib.instructor.scan import strip_magics

    Alarm.exception = Timeout

    checks = importlib.import_module(job["check_module"])
    originals = {e["check"]: getattr(checks, e["check"]) for e in job["exercises"]}
    for name in originals:
        setattr(checks, name, lambda *args, **kwargs: None)  # the notebook's own check calls
    before = snapshot(job["check_module"])
    only_thread()
    abi = landlock.restrict(job["landlock"]["read"], job["landlock"]["write"])
    sockets_denied = seccomp.deny_sockets()
    watch_parent(parent)
    os.chdir(job["workdir"])
    capture = Capture(job["limits"]["output_chars"], 40 * job["limits"]["output_chars"])
    sys.stdout = sys.stderr = capture
    main_module = types.ModuleType("__main__")
    main_module.__dict__.update(__builtins__=builtins, display=print,
                                get_ipython=lambda: types.SimpleNamespace(run_line_magic=print,
                                                                          system=print))
    sys.modules["__main__"] = main_module
    ns = main_module.__dict__
    channel.send({"event": "ready", "landlock": abi, "sockets_denied": sockets_denied})

    skip = set(job["skip_cells"])
    for cell in job["cells"]:
        index = cell["index"]
        if index in skip:
            continue
        channel.send({"event": "cell_start", "cell": index})
        status, error = "ok", None
        source = strip_magics(cell["source"])
        filename = f"<cell {index}>"
        linecache.cache[filename] = (len(source), None, source.splitlines(True), filename)
        try:
            try:
                code = compile(source, filename, "exec")
                Alarm.arm(job["limits"]["cell_s"])
                try:
                    exec(code, ns)
                finally:
                    Alarm.disarm()
            except SyntaxError as exc:
                status, error = "syntax", f"SyntaxError: {exc.msg} (line {exc.lineno})"
            except Timeout:
                status, error = "timeout", f"stopped after {job['limits']['cell_s']:g} s of CPU time"
            except BaseException as exc:
                status, error = "error", excerpt(exc)
        except Timeout:
            status, error = "timeout", f"stopped after {job['limits']['cell_s']:g} s of CPU time"
        plt.close("all")
        channel.send({"event": "cell_end", "cell": index, "status": status, "error": error,
                      **capture.take()})
    channel.send({"event": "changes", "found": compare(before, job["check_module"])})

    done = set(job["skip_exercises"])
    for ex in job["exercises"]:
        if ex["name"] in done:
            continue
        channel.send({"event": "exercise_start", "name": ex["name"]})
        fn = ns.get(ex["name"], _MISSING)
        record = {"event": "exercise_end", "name": ex["name"], "found": fn is not _MISSING,
                  "callable": callable(fn), "type": type(fn).__name__,
                  "module": str(getattr(fn, "__module__", "") or "")[:200]}
        if fn is not _MISSING and callable(fn):
            recorder = Recorder(fn, job["limits"]["value_bytes"])
            try:
                try:
                    Alarm.arm(job["limits"]["exercise_s"])
                    try:
                        verdict = evaluate(originals[ex["check"]], recorder)
                        # the run-time watch of library calls (course_lib.check.watch) can
                        # only refuse an answer, so its word from this process is safe to use
                        record["library"] = str(verdict.get("reference") or "")[:600] or None
                    finally:
                        Alarm.disarm()
                except Timeout:
                    record["timeout"] = True
                except BaseException as exc:
                    record["check_error"] = excerpt(exc)
            except Timeout:
                record["timeout"] = True
            record["calls"] = recorder.calls
            plt.close("all")
        channel.send({**record, **capture.take()})
        channel.send({"event": "changes", "found": compare(before, job["check_module"])})
    channel.send({"event": "done"})
    os._exit(0)  # skip atexit handlers and finalizers a submission may have registered


_MISSING = object()

if __name__ == "__main__":
    main()

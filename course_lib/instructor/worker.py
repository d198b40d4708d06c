"""The sandboxed worker: runs one submission and records what its exercise functions return.

Started by :mod:`.sandbox` as ``python -I -S worker.py FD`` with a job (JSON) on stdin;
never imported by the grader. It sets its import path (a private copy of course_lib and
the environment's site-packages, nothing from the submission's folder), its resource
limits, imports the libraries and the assignment's checks, then gives up file system and
network rights (:mod:`.landlock`) before running a single line of student code.

It then executes the student's code cells in order (errors allowed, each cell under a
time limit; the notebook's own ``check.…(…)`` calls do nothing here), and for each
exercise runs the kit's check with a *recorder* in place of the student's function: the
recorder calls the student's function and keeps, per call, a fingerprint of the
arguments, the returned value (:mod:`.codec`), any exception and any change to its array
arguments. Only these records go back to the grader (HMAC-signed JSON lines on pipe FD);
the grader replays them into the same check in its own process to decide the verdict.
The worker decides nothing about grades. Imports: stdlib first, then numpy, matplotlib,
course_lib (from the private copy).
"""

import builtins
import functools
import hashlib
import hmac
import importlib
import io
import json
import linecache
import os
import resource
import signal
import sys
import traceback
import types

_dumps, _write, _hmac_new = json.dumps, os.write, hmac.new  # bound before any student code


class Timeout(BaseException):
    """A cell or an exercise ran out of time (a BaseException: ``except Exception`` in
    student code does not swallow it)."""


class Alarm:
    armed = False

    @staticmethod
    def handler(signum, frame):
        if Alarm.armed:
            Alarm.armed = False
            raise Timeout()

    @staticmethod
    def arm(seconds: float) -> None:
        Alarm.armed = True
        signal.setitimer(signal.ITIMER_REAL, max(seconds, 0.01))

    @staticmethod
    def disarm() -> None:
        Alarm.armed = False
        signal.setitimer(signal.ITIMER_REAL, 0)


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


class Capture(io.TextIOBase):
    """sys.stdout/sys.stderr for student code: keeps the first ``per_part`` characters of
    each cell or exercise (and ``total`` overall), counts and drops the rest."""

    def __init__(self, per_part: int, total: int):
        self.per_part, self.left = per_part, total
        self.begin()

    def begin(self) -> None:
        self.parts, self.size, self.dropped = [], 0, 0

    def writable(self) -> bool:
        return True

    def write(self, s) -> int:
        s = str(s)
        room = max(min(self.per_part - self.size, self.left), 0)
        self.parts.append(s[:room])
        self.size += min(len(s), room)
        self.left -= min(len(s), room)
        self.dropped += max(len(s) - room, 0)
        return len(s)

    def take(self) -> dict:
        out = {"output": "".join(self.parts), "dropped": self.dropped}
        self.begin()
        return out


def excerpt(exc: BaseException, limit: int = 2000) -> str:
    """The student's part of a traceback (frames in cells) and the exception line."""
    try:
        tb = traceback.TracebackException.from_exception(exc, capture_locals=False)
        frames = traceback.StackSummary.from_list([f for f in tb.stack if f.filename.startswith("<cell")])
        text = "".join(frames.format()[-6:]) + "".join(tb.format_exception_only())
    except Exception:
        text = f"{type(exc).__name__}\n"
    return text[-limit:]


def set_limits(limits: dict) -> None:
    mb = 1 << 20
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    resource.setrlimit(resource.RLIMIT_AS, (limits["memory_mb"] * mb, limits["memory_mb"] * mb))
    resource.setrlimit(resource.RLIMIT_FSIZE, (limits["file_mb"] * mb, limits["file_mb"] * mb))
    cpu = int(limits["cpu_s"])
    resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 5))
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails, not the process


def snapshot(check_module: str) -> dict:
    """Identity of everything in course_lib's modules, Checker and builtins."""
    from course_lib.check import Checker

    state = {name: (id(mod), {k: id(v) for k, v in vars(mod).items()})
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


MAX_CALLBACKS = 5000


class Recorder:
    """Stands in for the student's function in the worker's run of a check.

    Function arguments (callbacks such as ``f(t, y)`` or a check's ``run(dt)``) reach the
    student wrapped: each call is logged (arguments, a summary of the result), so the
    grader can make the same calls on its own objects and reproduce their side effects.
    """

    def __init__(self, fn, codec, np, max_bytes: int):
        self.fn, self.codec, self.np, self.max_bytes = fn, codec, np, max_bytes
        self.calls: list[dict] = []

    def _spy(self, value, key: str, log: list):
        if not isinstance(value, types.FunctionType):
            return value
        codec = self.codec

        def spy(*args, **kwargs):
            entry = {"arg": key}
            if len(log) < MAX_CALLBACKS:
                try:  # arguments the codec cannot carry (a function of the student's) are not replayed
                    encoded = codec.encode([list(args), kwargs], 1 << 20)
                    entry["args"] = None if codec.has_opaque(encoded) else encoded
                except Exception:
                    entry["args"] = None
                log.append(entry)
            try:
                out = value(*args, **kwargs)
            except BaseException as exc:
                entry["raised"] = type(exc).__name__
                raise
            entry["sig"] = codec.summary(out)
            return out

        return functools.update_wrapper(spy, value)

    def __call__(self, *args, **kwargs):
        codec = self.codec
        items = list(enumerate(args)) + list(kwargs.items())
        before = {str(k): codec.fingerprint(v) for k, v in items}
        log: list = []
        call = {"sig": codec.summary([list(args), kwargs]), "callbacks": log}
        self.calls.append(call)
        spied = [self._spy(a, str(i), log) for i, a in enumerate(args)]
        spied_kw = {k: self._spy(v, k, log) for k, v in kwargs.items()}
        try:
            value = self.fn(*spied, **spied_kw)
        except Timeout:
            call["timeout"] = True
            raise
        except BaseException as exc:
            call["raised"] = codec.exception_record(exc)
            call["traceback"] = excerpt(exc)
            self._mutations(call, items, before)
            raise codec.rebuild_exception(call["raised"]) from None
        self._mutations(call, items, before)
        try:
            call["result"] = codec.encode(value, self.max_bytes)
        except codec.EncodingLimit as exc:
            call["result"] = {"opaque": str(exc)}
        except Timeout:
            raise
        except BaseException as exc:
            call["result"] = {"opaque": f"{type(value).__name__} (unreadable: {type(exc).__name__})"}
        return codec.decode(call["result"])  # the worker's check sees what the grader's will

    def _mutations(self, call: dict, items: list, before: dict) -> None:
        changed = {str(k): v for k, v in items if self.codec.fingerprint(v) != before[str(k)]}
        if changed:
            try:
                call["mutated"] = {k: self.codec.encode(v, self.max_bytes) for k, v in changed.items()}
            except Exception:
                call["mutated"] = {k: {"opaque": "changed argument"} for k in changed}


def main() -> None:
    channel_fd = int(sys.argv[1])
    job = json.loads(sys.stdin.read())
    sys.stdin = open(os.devnull)  # student code that reads stdin gets nothing
    channel = Channel(channel_fd, job.pop("key"))
    sys.path[:0] = job["sys_path"][:1]
    sys.path.extend(job["sys_path"][1:])
    set_limits(job["limits"])
    signal.signal(signal.SIGALRM, Alarm.handler)

    import matplotlib
    import numpy as np

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from course_lib.check import evaluate
    from course_lib.instructor import codec, landlock
    from course_lib.instructor.scan import strip_magics

    checks = importlib.import_module(job["check_module"])
    originals = {e["check"]: getattr(checks, e["check"]) for e in job["exercises"]}
    for name in originals:
        setattr(checks, name, lambda *args, **kwargs: None)  # the notebook's own check calls
    before = snapshot(job["check_module"])
    abi = landlock.restrict(job["landlock"]["read"], job["landlock"]["write"])
    os.chdir(job["workdir"])
    capture = Capture(job["limits"]["output_chars"], 40 * job["limits"]["output_chars"])
    sys.stdout = sys.stderr = capture
    main_module = types.ModuleType("__main__")
    main_module.__dict__.update(__builtins__=builtins, display=print,
                                get_ipython=lambda: types.SimpleNamespace(run_line_magic=print,
                                                                          system=print))
    sys.modules["__main__"] = main_module
    ns = main_module.__dict__
    channel.send({"event": "ready", "landlock": abi})

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
                status, error = "timeout", f"stopped after {job['limits']['cell_s']:g} s"
            except BaseException as exc:
                status, error = "error", excerpt(exc)
        except Timeout:
            status, error = "timeout", f"stopped after {job['limits']['cell_s']:g} s"
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
            recorder = Recorder(fn, codec, np, job["limits"]["value_bytes"])
            try:
                try:
                    Alarm.arm(job["limits"]["exercise_s"])
                    try:
                        evaluate(originals[ex["check"]], recorder)
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

"""What the worker keeps while student code runs: output, tracebacks, calls to exercises.

:class:`Recorder` stands in for a student's function in the worker's run of a check (see
:mod:`.worker`); :class:`Capture` replaces ``sys.stdout``/``sys.stderr``; :func:`excerpt`
keeps the student's part of a traceback. Runs inside the sandboxed worker, so it imports
only the standard library and :mod:`.codec`.
"""

import contextlib
import functools
import io
import sys
import traceback
import types

from . import codec

_getprofile, _setprofile = sys.getprofile, sys.setprofile  # bound before any student code


@contextlib.contextmanager
def _profile(hook):
    """``hook`` as the profile function for the block (the previous one after it). The
    recorder's own bookkeeping runs with none: a check's library watch
    (:mod:`course_lib.check.watch`) is a profile hook that has nothing to say about the
    recorder and cost it most of its time (a Python call per call and return); the
    student's function and the check's callbacks still run under the watch."""
    previous = _getprofile()
    _setprofile(hook)
    try:
        yield
    finally:
        _setprofile(previous)


class Timeout(BaseException):
    """A cell or an exercise ran out of time (a BaseException: ``except Exception`` in
    student code does not swallow it)."""


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


MAX_CALLBACKS = 5000


class Recorder:
    """Stands in for the student's function in the worker's run of a check.

    Function arguments (callbacks such as ``f(t, y)`` or a check's ``run(dt)``) reach the
    student wrapped: each call is logged (arguments, a summary of the result), so the
    grader can make the same calls on its own objects and reproduce their side effects.
    """

    def __init__(self, fn, max_bytes: int):
        self.fn, self.codec, self.max_bytes = fn, codec, max_bytes
        self.calls: list[dict] = []

    def _spy(self, value, key: str, log: list):
        # A check may hand over a callable object of its own (a probe that notes the runs a
        # search made); it is spied like a function. Other objects (a library model the
        # answer reads attributes of) reach the student as they are.
        probe = callable(value) and not isinstance(value, type) \
            and str(getattr(type(value), "__module__", "")).startswith("course_lib.check")
        if not (isinstance(value, types.FunctionType) or probe):
            return value
        codec = self.codec

        def spy(*args, **kwargs):
            if len(log) >= MAX_CALLBACKS:  # past the cap a call is made, not kept
                return value(*args, **kwargs)
            watch = _getprofile()
            with _profile(None):
                entry = {"arg": key}
                try:  # arguments the codec cannot carry (a function of the student's) are not replayed
                    encoded, opaque = codec.encode_flagged([list(args), kwargs], 1 << 20)
                    entry["args"] = None if opaque else encoded
                except Exception:
                    entry["args"] = None
                log.append(entry)
                try:
                    with _profile(watch):
                        out = value(*args, **kwargs)
                except Timeout:
                    # the time limit struck inside the check's own function: not something the
                    # function raised, and the replay stops at this call anyway
                    entry["interrupted"] = True
                    raise
                except BaseException as exc:
                    entry["raised"] = type(exc).__name__
                    raise
                entry["sig"] = codec.summary(out)
            return out

        return functools.update_wrapper(spy, value)

    def __call__(self, *args, **kwargs):
        # The time limit can strike anywhere, in this bookkeeping too (between the answer's
        # return and its encoding, say): the call is then marked as timed out, so the grader's
        # replay stops there as well, instead of finding an incomplete call and calling it
        # tampering.
        made: list[dict] = []
        try:
            return self._record(made, args, kwargs)
        except Timeout:
            if made:
                made[0]["timeout"] = True
            raise

    def _record(self, made: list, args: tuple, kwargs: dict):
        watch = _getprofile()
        with _profile(None):
            codec = self.codec
            items = list(enumerate(args)) + list(kwargs.items())
            before = {str(k): codec.fingerprint(v) for k, v in items}
            log: list = []
            call = {"sig": codec.summary([list(args), kwargs]), "callbacks": log}
            self.calls.append(call)
            made.append(call)
            spied = [self._spy(a, str(i), log) for i, a in enumerate(args)]
            spied_kw = {k: self._spy(v, k, log) for k, v in kwargs.items()}
            try:
                with _profile(watch):
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

"""Verdicts: the kit's checks, run in the grader's process on values the worker recorded.

For each exercise the grader calls :func:`course_lib.check.evaluate` with a
:class:`Replay` in place of the student's function. The replay answers the k-th call with
the k-th value the student's function returned in the worker (or raises what it raised,
or repeats the change it made to its array arguments), after checking that the grader's
arguments have the same fingerprint as the worker's. So the check, its inputs, its
reference values and its verdict all live in the grader; the student's process supplied
return values and nothing else. A fingerprint mismatch means the check ran differently in
the student's process (the checker or its data was changed there): that is tampering.

Statuses (closed set): correct, incorrect, pending, error, timeout, missing, tampered,
wrong-assignment, unreadable. Imports: numpy, :mod:`course_lib.check`, :mod:`.codec`.
"""

from __future__ import annotations

import re
import threading
from dataclasses import dataclass, field

import numpy as np

from course_lib.check import evaluate

from . import codec

STATUSES = ("correct", "incorrect", "pending", "error", "timeout", "missing", "tampered",
            "wrong-assignment", "unreadable")
FIELDS = ["student", "assignment", "exercise", "status", "points", "possible", "passed", "total",
          "message", "file"]
_LOCK = threading.Lock()  # replays may change arguments the check shares between students


@dataclass
class Row:
    """One gradebook line, plus the details a student's feedback shows."""

    student: str
    assignment: str
    exercise: str
    status: str
    possible: int
    message: str
    file: str = ""
    passed: int = 0
    total: int = 0
    details: dict = field(default_factory=dict)

    @property
    def points(self) -> int:
        return self.possible if self.status == "correct" else 0

    def csv(self) -> dict:
        return {k: getattr(self, k) for k in FIELDS}


class ReplayStop(BaseException):
    """The replay cannot answer: the worker recorded fewer calls, or different arguments."""


class Replay:
    """Answers a check's calls with what the student's function did in the worker."""

    def __init__(self, calls: list[dict]):
        self.calls, self.k, self.undo = calls, 0, []

    def __call__(self, *args, **kwargs):
        if self.k >= len(self.calls):
            raise ReplayStop("exhausted")
        call = self.calls[self.k]
        self.k += 1
        if not codec.same(call.get("sig"), codec.summary([list(args), kwargs])):
            raise ReplayStop("diverged")
        self._callbacks(call.get("callbacks") or [], args, kwargs)
        for key, value in (call.get("mutated") or {}).items():
            target = args[int(key)] if key.isdigit() and int(key) < len(args) else kwargs.get(key)
            self._restore(target, codec.decode(value))
        if "raised" in call:
            raise codec.rebuild_exception(call["raised"])
        if "result" not in call:
            raise ReplayStop("timeout" if call.get("timeout") else "exhausted")
        return codec.decode(call["result"])

    def _callbacks(self, log: list, args: tuple, kwargs: dict) -> None:
        """Make the calls the student's function made to function arguments, on the grader's
        own functions, so their side effects (a check recording what was asked) happen here."""
        for entry in log:
            key = str(entry.get("arg"))
            target = args[int(key)] if key.isdigit() and int(key) < len(args) else kwargs.get(key)
            if entry.get("interrupted"):  # the time limit struck during this callback
                raise ReplayStop("timeout")
            if not callable(target) or entry.get("args") is None:
                continue
            cb_args, cb_kwargs = codec.decode(entry["args"])
            try:
                out = target(*cb_args, **cb_kwargs)
            except Exception:
                if "raised" not in entry:
                    raise ReplayStop("diverged") from None
                continue
            if "raised" in entry or ("sig" in entry and not codec.same(entry["sig"], codec.summary(out))):
                raise ReplayStop("diverged")

    def _restore(self, target, value) -> None:
        """Repeat an in-place change on the grader's argument (undone after the check)."""
        if isinstance(target, np.ndarray) and isinstance(value, np.ndarray) and value.shape == target.shape:
            self.undo.append((target, target.copy()))
            target[...] = value
        elif isinstance(target, list) and isinstance(value, list):
            self.undo.append((target, list(target)))
            target[:] = value
        elif isinstance(target, dict) and isinstance(value, dict):
            self.undo.append((target, dict(target)))
            for k, v in value.items():
                if isinstance(target.get(k), np.ndarray) and isinstance(v, np.ndarray):
                    self._restore(target[k], v)
                else:
                    target[k] = v

    def rollback(self) -> None:
        for target, old in reversed(self.undo):
            if isinstance(target, np.ndarray):
                target[...] = old
            elif isinstance(target, list):
                target[:] = old
            else:
                target.clear()
                target.update(old)
        self.undo.clear()


def _first_line(text: str) -> str:
    return text.strip().splitlines()[0] if text and text.strip() else ""


def hint_of(case: str) -> str:
    """The hint part of a failed case message ("...\n      hint: ...")."""
    m = re.search(r"hint:\s*(.+)", case)
    return m.group(1).strip() if m else ""


def judge(check, record: dict, limits_exercise_s: float) -> tuple[str, str, dict]:
    """Status, message and details for one exercise the worker recorded."""
    replay = Replay(record.get("calls") or [])
    details: dict = {"output": record.get("output", ""), "dropped": record.get("dropped", 0)}
    with _LOCK:
        try:
            verdict = evaluate(check, replay)
            stop = None
            if replay.k < len(replay.calls):
                stop = "diverged"
        except ReplayStop as exc:
            verdict, stop = None, str(exc)
        except ValueError as exc:  # an undecodable record
            verdict, stop = None, f"malformed: {exc}"
        finally:
            replay.rollback()
    call = replay.calls[replay.k - 1] if 0 < replay.k <= len(replay.calls) else {}
    if call.get("traceback"):
        details["traceback"] = call["traceback"]
    if stop == "exhausted" and not record.get("timeout") and not record.get("check_error"):
        stop = "diverged"  # the worker's check finished with fewer calls than the grader's
    if stop == "diverged":
        return ("tampered", "tampering: the check's inputs in the notebook's process differ from "
                "the grader's: something in the notebook changed the checker or its data", details)
    if stop == "timeout" or (stop == "exhausted" and record.get("timeout")):
        return ("timeout", f"your function did not finish within {limits_exercise_s:g} s "
                f"of CPU time (call {replay.k} of the check)", details)
    if stop:
        if record.get("check_error"):
            details["traceback"] = record["check_error"]
        return "error", f"the check could not finish ({stop})", details
    details.update(passed_cases=verdict["passed_cases"], failed_cases=verdict["failed_cases"])
    details["counts"] = (verdict["passed"], verdict["total"])
    # What the function raised, seen in the replay itself (whether or not the check caught it).
    raised = [c["raised"] for c in replay.calls[:replay.k] if isinstance(c.get("raised"), dict)]
    returned = any("result" in c for c in replay.calls[:replay.k])
    if verdict["status"] == "pending" or (verdict["status"] != "correct" and raised and not returned
                                          and all(r.get("pending") for r in raised)):
        return "pending", "not attempted yet: the function still raises NotImplementedError", details
    errors = [r for r in raised if not r.get("pending")]
    if verdict["status"] != "correct" and (verdict["error"] or errors):
        what = verdict["error"] or f"{errors[0].get('type')}: {errors[0].get('message')}"
        if not details.get("traceback"):
            details["traceback"] = next((c["traceback"] for c in replay.calls[:replay.k]
                                         if c.get("traceback")), "")
        return "error", f"your function raised {what}"[:300], details
    if verdict["status"] == "correct":
        return "correct", f"{verdict['passed']} of {verdict['total']} cases passed", details
    failed = verdict["failed_cases"]
    first = _first_line(failed[0]) if failed else ""
    hint = hint_of(failed[0]) if failed else ""
    msg = f"{len(failed)} of {verdict['total']} cases failed: {first}"
    return "incorrect", (msg + (f" (hint: {hint})" if hint else ""))[:400], details

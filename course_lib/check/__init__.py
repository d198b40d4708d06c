"""Automatic feedback for the notebook exercises.

Each notebook imports its own checks, e.g. ``from course_lib.check import nb01 as check``,
and calls one right after an exercise: ``check.advect_step(advect_step)``. A check runs
the student's function on a few cases, compares with the reference answer and prints
one verdict:

- ``✓ correct`` with what was verified;
- ``✗`` with each failed case: what was expected, what came back, and a hint aimed at the
  usual mistake when the answer matches one (e.g. the slope taken at the end of the step);
- ``○ pending`` while the function still raises ``NotImplementedError`` (so a blank
  student notebook runs top to bottom).

Every verdict is also recorded in :data:`RESULTS`, which the grader reads
(``python -m course_lib.instructor grade``).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

#: Latest verdict of every exercise run in this kernel, by "module.exercise" name.
RESULTS: dict[str, dict] = {}
#: Every exercise any imported check module defines, with its points.
REGISTRY: dict[str, int] = {}
#: Wrong verdicts per exercise in this kernel, so that hints can escalate (see Checker.pick).
FAILURES: dict[str, int] = {}
#: A hint: one string, or a tuple that escalates from a nudge to a fuller explanation.
Hint = str | tuple[str, ...] | None


@dataclass
class Checker:
    """Collects the outcome of the cases of one exercise check."""

    name: str
    passed: list[str] = field(default_factory=list)
    failed: list[str] = field(default_factory=list)
    #: How many times this exercise was already judged wrong in this kernel (0 in the grader).
    attempt: int = 0

    def pick(self, hint: Hint) -> str | None:
        """The hint to show now: a tuple ``(nudge, more, ...)`` escalates one step per earlier
        wrong attempt (a nudge first; the fuller explanation only after another failure)."""
        if isinstance(hint, tuple):
            return hint[min(self.attempt, len(hint) - 1)] if hint else None
        return hint

    def expect(self, ok: bool, what: str, detail: str = "", hint: Hint = None) -> bool:
        """Record a case: ``what`` describes it, ``detail`` and ``hint`` explain a failure.

        ``hint`` is a string, or a tuple of strings that escalates (see :meth:`pick`).
        """
        if ok:
            self.passed.append(what)
        else:
            msg = f"{what}: {detail}" if detail else what
            if hint := self.pick(hint):
                msg += f"\n      hint: {hint}"
            self.failed.append(msg)
        return bool(ok)

    def close(
        self,
        actual,
        expected,
        what: str,
        *,
        rtol: float = 1e-9,
        atol: float = 1e-12,
        hint: Hint = None,
        mistakes: dict[Hint, object] | None = None,
    ) -> bool:
        """Record whether ``actual`` matches ``expected`` numerically.

        ``mistakes`` maps a hint to the value a typical wrong solution produces; if the
        student's answer matches one, that hint is shown instead of the generic one.
        """
        try:
            a = np.asarray(actual, dtype=float)
        except (TypeError, ValueError):
            return self.expect(False, what, f"expected a number/array, got {type(actual).__name__}", hint)
        e = np.asarray(expected, dtype=float)
        ok = a.shape == e.shape and bool(np.allclose(a, e, rtol=rtol, atol=atol))
        if not ok and mistakes:
            # A known mistake may have a different shape (a transposed or truncated answer).
            for mistake_hint, wrong in mistakes.items():
                w = np.asarray(wrong, dtype=float)
                if w.shape == a.shape and np.allclose(a, w, rtol=rtol, atol=atol):
                    hint = mistake_hint
                    break
        if a.shape != e.shape:
            return self.expect(False, what, f"expected shape {e.shape}, got shape {a.shape}", hint)
        shown_e, shown_a = apart(e, a)
        return self.expect(ok, what, f"expected {shown_e}, got {shown_a}", hint)


def apart(expected, got, digits: int = 6) -> tuple[str, str]:
    """``expected`` and ``got`` as text with ``digits`` digits, or with more (up to 17) when
    they differ but would print alike, so that no check says "expected 4.2429, got 4.2429".

    A Python or NumPy scalar prints with ``digits`` significant digits (``:.6g``), an
    ndarray (0-d too) with ``digits`` decimals (NumPy's layout, small entries suppressed).

    >>> apart(4.242900001, 4.2429)
    ('4.242900001', '4.2429')
    >>> apart([1.0, 2.0], [1.0, 2.5])
    ('[1., 2.]', '[1. , 2.5]')
    """
    def text(x, p: int) -> str:
        if isinstance(x, (int, float, complex, np.number)) and not isinstance(x, bool):
            return f"{x:.{p}g}"
        x = np.asarray(x)
        if np.issubdtype(x.dtype, np.inexact):
            x = x + 0.0     # -0.0 prints as "-0."; + 0.0 makes it 0.0
        return np.array2string(x, precision=p, suppress_small=True, separator=", ")

    p = digits
    shown = text(expected, p), text(got, p)
    try:
        same = bool(np.array_equal(np.asarray(expected), np.asarray(got), equal_nan=True))
    except TypeError:   # not numbers: as NumPy prints them
        same = True
    while shown[0] == shown[1] and not same and p < 17:
        p += 1
        shown = text(expected, p), text(got, p)
    return shown


def exercise(func: Callable | None = None, *, points: int = 1, allow: tuple = (),
             forbid: tuple = (), reference: tuple = ()):
    """Turn ``func(checker, answer, ...)`` into a check called as ``check(answer, ...)``.

    The decorated check prints one verdict and records it in :data:`RESULTS`.
    ``NotImplementedError`` from the student's code means "pending"; any other exception
    from it is reported as a failure with the exception's message.

    An answer may call no ``course_lib`` callable except those in ``allow`` (objects or
    dotted names: the building blocks the prompt hands over) and what the check passes to
    it; any other library call, found in its bytecode or watched while it runs, fails as
    "uses the reference" (:mod:`course_lib.check.policy`, :mod:`course_lib.check.watch`).
    ``forbid`` adds dotted prefixes outside the library (``"scipy.integrate"``) or objects;
    ``reference`` is its older name.
    """
    if func is None:
        return functools.partial(exercise, points=points, allow=allow, forbid=forbid,
                                 reference=reference)
    key = f"{func.__module__.rsplit('.', 1)[-1]}.{func.__name__}"
    REGISTRY[key] = points

    @functools.wraps(func)
    def run(*args, **kwargs) -> None:
        verdict = evaluate(run, *args, **kwargs)
        status, passed, failed = verdict["status"], verdict["passed_cases"], verdict["failed_cases"]
        if status == "incorrect":
            FAILURES[key] = FAILURES.get(key, 0) + 1
        RESULTS[key] = {k: verdict[k] for k in ("status", "passed", "total", "points")}
        if status == "pending":
            print(f"○ {func.__name__}: pending — replace `raise NotImplementedError()` with your code, "
                  "then run this cell again.")
        elif status == "correct":
            print(f"✓ {func.__name__}: correct ({len(passed)} of {verdict['total']} checks passed)")
            for what in passed:
                print(f"   ✓ {what}")
        else:
            print(f"✗ {func.__name__}: {len(failed)} of {verdict['total']} checks failed")
            for msg in failed:
                print(f"   ✗ {msg}")

    run.key, run.points, run.references = key, points, tuple(reference)
    run.allow, run.forbid = tuple(allow), tuple(forbid)
    return run


def evaluate(check: Callable, *args, **kwargs) -> dict:
    """Run the ``@exercise`` check ``check`` on an answer without printing or recording.

    Returns the verdict: ``status`` (correct, incorrect, pending), ``passed``/``total``
    case counts, ``points``, the ``passed_cases`` and ``failed_cases`` messages, ``error``
    (the exception the answer raised, if any) and ``reference`` (why the answer counts
    as using the reference, if it does). The grader and nbgrader tests call this.
    """
    ck = Checker(check.__name__, attempt=FAILURES.get(getattr(check, "key", ""), 0))
    verdict = {"status": "incorrect", "points": check.points, "error": None, "reference": None}
    watch = None
    try:  # the policy must never break a check: on any failure, assume no reference use
        from .policy import exercise_rules, message, reference_use, refused_names
        from .watch import LibraryWatch, watched_answer

        verdict["reference"] = reference_use(check, args[0]) if args else None
        if args and not verdict["reference"] and watched_answer(args[0]):
            rules = exercise_rules(check)
            watch = LibraryWatch(rules["allow"], rules["prefixes"])
            args = (watch.wrap(args[0]), *args[1:])
    except Exception:
        watch = None
    if verdict["reference"]:
        ck.failed.append(verdict["reference"])
    else:
        try:
            check.__wrapped__(ck, *args, **kwargs)
        except NotImplementedError:
            verdict["status"] = "pending"
        except Exception as exc:  # the student's code failed: say how, do not crash the notebook
            verdict["error"] = f"{type(exc).__name__}: {exc}"
            ck.failed.append(f"your code raised {verdict['error']}")
        if watch is not None and watch.found and verdict["status"] != "pending":
            verdict["reference"] = message(watch.found, refused=refused_names(check))
            ck.failed.insert(0, verdict["reference"])
    if verdict["status"] == "pending":
        ck.passed, ck.failed = [], []
    elif not ck.failed:
        verdict["status"] = "correct"
    verdict.update(passed=len(ck.passed), total=len(ck.passed) + len(ck.failed),
                   passed_cases=list(ck.passed), failed_cases=list(ck.failed))
    return verdict


def summary() -> dict[str, dict]:
    """Verdict of every registered exercise (``"not run"`` if its check never ran)."""
    out = {}
    for key, points in REGISTRY.items():
        out[key] = RESULTS.get(key, {"status": "not run", "passed": 0, "total": 0, "points": points})
    return out

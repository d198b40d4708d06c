"""Planted answers for the exercise checks of notebooks 05-08: each is written as a student
would write it in a notebook cell (module ``__main__``), judged by the check exactly as the
grader judges it (:func:`course_lib.check.evaluate`, first attempt: the nudge), and must get
the verdict and the hint expected.

Every exercise has at least three plants (``kind``): one ``delegating`` call into the library,
one ``shortcut`` that the check's data breaks, and one usual ``misconception``; more kinds
(``other``) where the checks found more. A test module lists its plants as :class:`Plant`
rows and runs :func:`judge` on each.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import course_lib as cl
from course_lib.check import FAILURES, evaluate


@dataclass(frozen=True)
class Plant:
    exercise: str     #: the check's name in its module
    kind: str         #: delegating, shortcut, misconception or other
    label: str        #: what the answer does, in a few words
    source: str       #: the answer, as a notebook cell defines it
    status: str       #: the verdict expected: correct, incorrect or pending
    says: str         #: a piece of text the first failed case must hold (its hint), or ""
    avoid: str = ""   #: a piece of text no failed case may hold (a hint that misfires), or ""
    attempt: int = 0  #: earlier wrong attempts in the kernel (1: the escalated hint)


def define(source: str, name: str, **extra):
    """The function ``name`` that ``source`` defines, as a notebook cell defines it."""
    from course_lib.lessons import nb05_newton, nb06_forces, nb07_springs, nb08_hair_chains

    namespace = {"__name__": "__main__", "np": np, "cl": cl,
                 "lesson05": nb05_newton, "lesson06": nb06_forces, "lesson07": nb07_springs,
                 "lesson08": nb08_hair_chains, **extra}
    exec(compile(source, "<cell>", "exec"), namespace)
    return namespace[name]


def judge(check_module, plant: Plant) -> dict:
    """Judge a plant as the grader does (a fresh kernel: the nudge, never the fuller hint;
    or, with ``plant.attempt``, after that many wrong attempts) and assert its verdict and
    hint. Returns the verdict."""
    check = getattr(check_module, plant.exercise)
    FAILURES.pop(check.key, None)
    if plant.attempt:
        FAILURES[check.key] = plant.attempt
    try:
        verdict = evaluate(check, define(plant.source, plant.exercise))
    finally:
        FAILURES.pop(check.key, None)
    failed = "\n".join(verdict["failed_cases"])
    assert verdict["status"] == plant.status, (plant.label, verdict["status"], failed)
    if plant.says:
        assert plant.says in failed, (plant.label, failed)
    if plant.avoid:
        assert plant.avoid not in failed, (plant.label, failed)
    if plant.kind == "delegating":
        assert verdict["reference"] and "uses the reference" in verdict["reference"], plant.label
    return verdict


def table(check_module, plants) -> str:
    """A markdown table of the plants and what the check says to each (for reports)."""
    rows = ["| exercise | kind | answer | verdict | first message |", "|---|---|---|---|---|"]
    for p in plants:
        check = getattr(check_module, p.exercise)
        FAILURES.pop(check.key, None)
        v = evaluate(check, define(p.source, p.exercise))
        first = (v["failed_cases"] or [""])[0].replace("\n      ", " ").replace("|", "\\|")
        rows.append(f"| {p.exercise} | {p.kind} | {p.label} | {v['status']} | {first[:160]} |")
    return "\n".join(rows)

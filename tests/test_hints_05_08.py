"""Check messages and hints of notebooks 05-08 after the fourth read.

A long wrong array is summarised by one row: the row that is off the most (07's
``network_forces`` printed "e.g. row 0", the first row that differed, where other checks
print the worst).
"""

from __future__ import annotations

import numpy as np
from planted import define
from test_nb07_springs import NETWORK_RIGHT

from course_lib.check import Checker, evaluate
from course_lib.check import nb07 as check07
from course_lib.check._answers import close


def _summary(answer, expected) -> str:
    ck = Checker("demo")
    assert not close(ck, answer, expected, "a table", rtol=1e-9)
    return ck.failed[-1]


def test_a_long_wrong_array_names_the_row_that_is_off_the_most():
    expected = np.arange(60.0).reshape(20, 3) + 1.0
    answer = expected.copy()
    answer[2] += 1e-3                       # first to differ, barely
    answer[17, 1] -= 4.0                    # off the most
    answer[9] *= 1 + 1e-6
    text = _summary(answer, expected)
    assert "7 of 60 values differ; the worst, row 17" in text, text
    assert "(off by 4)" in text, text
    answer[11, 0] = np.nan                  # a NaN is the worst there is
    assert "the worst, row 11" in _summary(answer, expected)
    flat = np.linspace(1.0, 2.0, 30)        # 1-D answers: the row is the entry
    wrong = flat.copy()
    wrong[[0, 21]] += (1e-4, 0.5)
    assert "the worst, row 21" in _summary(wrong, flat)


def test_network_forces_shows_the_worst_particle():
    source = NETWORK_RIGHT.replace(
        "    return F", "    F[0] += 1e-3 * np.abs(F).max()\n    F[-1] += 1.0\n    return F")
    verdict = evaluate(check07.network_forces, define(source, "network_forces"))
    text = "\n".join(verdict["failed_cases"])
    assert verdict["status"] == "incorrect"
    assert "e.g. row" not in text
    assert "6 of 18 values differ; the worst, row 5:" in text, text
    assert "7 particles, 24 springs in 2D: 4 of 14 values differ; the worst, row 6:" in text, text

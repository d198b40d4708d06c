"""Check messages and hints of notebooks 05-08 after the fourth read.

A long wrong array is summarised by one row: the row that is off the most (07's
``network_forces`` printed "e.g. row 0", the first row that differed, where other checks
print the worst).
"""

from __future__ import annotations

import numpy as np
from notebook_helpers import markdown as _markdown
from planted import define
from test_nb07_springs import NETWORK_RIGHT

from course_lib.check import Checker, evaluate
from course_lib.check import nb06 as check06
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


def test_terminal_speed_prompt_says_a_root_finder_is_accepted_and_it_is():
    """06 Exercise 2 asks for 'a formula'; brentq on the balance passes, so the prompt says so."""
    text = _markdown("06_forces.ipynb")
    assert "a root\nfinder such as `scipy.optimize.brentq` on the balance is accepted too" in text
    source = ("def terminal_speed(m, g, b, c):\n"
              "    from scipy.optimize import brentq\n"
              "    return brentq(lambda v: b * v + c * v**2 - m * g, 0.0, m * g / b if b > 0 "
              "else np.sqrt(m * g / c), xtol=1e-300, rtol=4 * np.finfo(float).eps)")
    verdict = evaluate(check06.terminal_speed, define(source, "terminal_speed"))
    assert verdict["status"] == "correct", verdict["failed_cases"]


def test_notebook_06_names_its_errors_with_the_right_sign_and_unit():
    """06 cell 25: the 5.5 mm excess is friction after the drift (mu g dt T) plus symplectic
    Euler's half-step LEAD (+1/2 a dt T); it said 'F dt T less the half step SE leads by'.
    Cell 8 and the summary: (omega dt)^2/3 is a fraction of the period, not radians."""
    text = _markdown("06_forces.ipynb")
    assert "less the half step" not in text
    assert "Friction acts only\nafter the drift" in text and "lead by half a step" in text
    assert "a lag of $(\\omega\\Delta t)^2/3$ per" not in text
    assert "lags it by $(\\omega\\Delta t)^2/3$ per period" not in text
    assert text.count("longer by a fraction $(\\omega\\Delta t)^2/3$") == 3


def test_notebook_08_quotes_no_machine_dependent_speed_range():
    """08 cell 2 said 'we measured 2.7 to 3.4 on three'; a reviewer's machine printed 3.6.
    Only the tested claim stays: more than twice as fast."""
    text = _markdown("08_hair_chains.ipynb")
    assert "2.7 to 3.4" not in text and "more than twice as fast" in text


def test_notebook_05_goal_claims_exact_samples_not_an_exact_landing():
    """Verlet's samples of the apple are exact; its landing time is exact only with the
    ballistic rule (cell 9 prints 1.4272 s with the linear rule)."""
    text = _markdown("05_newtons_second_law.ipynb")
    assert "lands the falling apple exactly" not in text
    assert "Verlet's samples of the falling apple are exact" in text

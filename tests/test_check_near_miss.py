"""Near misses never print as "expected 4.2429, got 4.2429" (sixth read, notebook 11 Ex 1).

An answer a few parts in a billion off fails a check that wants round-off; its message must
show the two numbers apart (:func:`course_lib.check.apart` adds digits until they differ).
Planted near misses in the checks of notebooks 11 (a block, a strain), 10 (a radius) and 03
(R(z), complex), and in the shared :meth:`Checker.close`; every "expected X, got Y" in a
failure must have X and Y different.
"""

import re

import numpy as np
import pytest

from course_lib.check import Checker, apart, evaluate, nb03, nb10, nb11
from course_lib.lessons import nb10_flocking

PAIR = re.compile(r"expected (.+?)(?: m)?, got (.+?)(?: m)?(?:,|:|$| \()")


def pairs(messages):
    """Every (expected, got) text pair in the failure messages."""
    return [m.groups() for line in messages for m in PAIR.finditer(line.split("\n")[0])]


def exact_block(xi, xj, k, rest):
    d = xi - xj
    length = np.linalg.norm(d)
    u = d / length
    uu = np.outer(u, u)
    return -k * (uu + (1 - rest / length) * (np.eye(3) - uu))


def central_difference_block(xi, xj, k, rest):
    """The reviewer's near miss: the block by central differences of the force (7.7e-9 off)."""
    def force(x):
        d = x - xj
        length = np.linalg.norm(d)
        return -k * (length - rest) * d / length
    h = 1e-6
    return np.stack([(force(xi + h * e) - force(xi - h * e)) / (2 * h) for e in np.eye(3)], axis=1)


def off_by_a_billionth(xi, xj, k, rest):
    return exact_block(xi, xj, k, rest) * (1 + 3e-9)


def strain_near_miss(x, i, j, rest):
    length = np.linalg.norm(x[:, j] - x[:, i], axis=-1)
    return float(((length - rest) / rest).max()) * (1 + 1e-8)


def ring_near_miss(n, w_s, w_c):
    return np.sqrt(w_s * (n - 1) ** 2 / (2 * n * w_c)) * (1 + 2e-9)


def stability_near_miss(step, z):
    z = np.asarray(z, dtype=complex)
    return step(lambda t, y: z * y, 0.0, np.ones_like(z), 1.0) * (1 + 1e-9)


PLANTED = {
    "11 Ex 1, central differences": (nb11.spring_jacobian, central_difference_block),
    "11 Ex 1, 3e-9 off": (nb11.spring_jacobian, off_by_a_billionth),
    "11 Ex 4, 1e-8 off": (nb11.peak_strain, strain_near_miss),
    "10 Ex 2, 2e-9 off": (nb10.ring_radius, ring_near_miss),
    "03 Ex 1, 1e-9 off": (nb03.stability_function, stability_near_miss),
}


@pytest.mark.parametrize("planted", sorted(PLANTED))
def test_a_near_miss_fails_and_shows_the_two_numbers_apart(planted):
    check, answer = PLANTED[planted]
    verdict = evaluate(check, answer)
    assert verdict["status"] == "incorrect", verdict
    shown = pairs(verdict["failed_cases"])
    assert shown, verdict["failed_cases"]
    for expected, got in shown:
        assert expected != got, (planted, verdict["failed_cases"])


def test_the_shared_close_shows_near_misses_apart():
    ck = Checker("x")
    ck.close(4.2429001, 4.2429, "a number")
    ck.close([1.0, 4.2429001], [1.0, 4.2429], "an array")
    ck.close(np.float32(4.2429), 4.2429 + 1e-12, "float32 against float64", rtol=1e-14, atol=0)
    assert len(ck.failed) == 3
    for expected, got in pairs(ck.failed):
        assert expected != got, ck.failed


def test_apart_adds_digits_only_when_needed():
    assert apart(4.2429, 4.2431) == ("4.2429", "4.2431")              # six digits suffice
    assert apart(4.242900001, 4.2429) == ("4.242900001", "4.2429")
    assert apart(2.0, 2.0) == ("2", "2")                              # equal stays equal
    assert apart(np.array([np.nan]), np.array([np.nan])) == ("[nan]", "[nan]")
    e, g = apart(np.array([0.5, 1 + 1e-12]), np.array([0.5, 1.0]))
    assert e != g and "1.000000000001" in e
    # as many digits as float64 holds, no more: two neighbours print apart at 17
    e, g = apart(1.0, np.nextafter(1.0, 2.0))
    assert e != g and len(e.replace("0", "")) <= 18


def test_ring_radius_near_miss_reports_both_numbers_in_metres():
    r = nb10_flocking.ring_radius(2, 0.3, 1.0)
    verdict = evaluate(nb10.ring_radius, ring_near_miss)
    first = next(c for c in verdict["failed_cases"] if c.startswith("2 boids"))
    assert f"expected {r:.10g}" in first or f"expected {r:.11g}" in first, first

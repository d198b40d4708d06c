"""The exercise checks of notebook 14 against planted answers.

For each exercise: the right answer passes; an answer that delegates to the library fails
as using the reference; a shortcut that the check's data break fails (a non-unit or turned
quaternion, sides in another order, a contact moving away); and the usual misconception
fails with the hint that names it. Verdicts come from ``evaluate`` (what the grader runs:
the first, nudging, hint).
"""

import numpy as np
import pytest

from course_lib import rigid
from course_lib.check import FAILURES, evaluate
from course_lib.check import nb14 as check


@pytest.fixture(autouse=True)
def fresh_attempts():
    for name in ("quaternion_step", "box_inertia", "collision_impulse"):
        FAILURES.pop(f"nb14.{name}", None)


def _failed(check_fn, answer, hint):
    verdict = evaluate(check_fn, answer)
    assert verdict["status"] == "incorrect", verdict
    text = " ".join(verdict["failed_cases"])
    assert hint in text, text
    return verdict


# --- quaternion step ---------------------------------------------------------------------

def quaternion_step(q, omega, dt):
    w, u = q[0], q[1:]
    q1 = q + 0.5 * dt * np.concatenate(([-omega @ u], w * omega + np.cross(omega, u)))
    return q1 / np.linalg.norm(q1)


def test_quaternion_step_right_and_pending():
    assert evaluate(check.quaternion_step, quaternion_step)["status"] == "correct"

    def stub(q, omega, dt):
        raise NotImplementedError()

    assert evaluate(check.quaternion_step, stub)["status"] == "pending"


def test_quaternion_step_delegating():
    verdict = evaluate(check.quaternion_step, lambda q, w, dt: rigid.quaternion.step(q, w, dt))
    assert verdict["status"] == "incorrect" and "uses the reference" in verdict["reference"]


def test_quaternion_step_shortcut_assuming_a_unit_quaternion():
    """An exact rotation that trusts |q| = 1 breaks on the check's drifted quaternion."""
    def rotate_only(q, omega, dt):
        angle = np.linalg.norm(omega) * dt
        axis = omega / np.linalg.norm(omega)
        r = np.r_[np.cos(angle / 2), np.sin(angle / 2) * axis]
        w, u = r[0], r[1:]
        return np.r_[w * q[0] - u @ q[1:], w * q[1:] + q[0] * u + np.cross(u, q[1:])]

    _failed(check.quaternion_step, rotate_only, "length 1.03")


@pytest.mark.parametrize("answer,hint", [
    (lambda q, w, dt: q + 0.5 * dt * np.r_[-w @ q[1:], q[0] * w + np.cross(w, q[1:])],
     "not of length 1"),                                                   # no renormalisation
    (lambda q, w, dt: quaternion_step(q, w, dt) if not q[1:].any() else
     (lambda p: p / np.linalg.norm(p))(q + 0.5 * dt * np.r_[-w @ q[1:], q[0] * w + np.cross(q[1:], w)]),
     "order of the product"),                                              # q ⊗ ω
    (lambda q, w, dt: quaternion_step(q, w, 2 * dt), "left out the ½"),
])
def test_quaternion_step_misconceptions(answer, hint):
    _failed(check.quaternion_step, answer, hint)


# --- box inertia -------------------------------------------------------------------------

def box_inertia(mass, sides, R):
    a, b, c = sides
    return R @ (mass / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])) @ R.T


def test_box_inertia_right_and_delegating():
    assert evaluate(check.box_inertia, box_inertia)["status"] == "correct"
    verdict = evaluate(check.box_inertia, lambda m, s, R: rigid.inertia.world_tensor(
        R, rigid.inertia.box_moments(m, s)))
    assert verdict["status"] == "incorrect" and "uses the reference" in verdict["reference"]


def test_box_inertia_shortcut_sorted_sides():
    """Sorting the sides works for the check's first box only: its sides come in order."""
    _failed(check.box_inertia, lambda m, s, R: box_inertia(m, np.sort(s)[::-1], R), "own body axis")


@pytest.mark.parametrize("answer,hint", [
    (lambda m, s, R: box_inertia(m, s, np.eye(3)), "body-frame tensor"),          # body vs world
    (lambda m, s, R: box_inertia(m, s, R.T), "not Rᵀ I R"),
    (lambda m, s, R: 4 * box_inertia(m, s, R), "m/3 is for half-sides"),
    (lambda m, s, R: R @ (m / 12 * np.diag([s[0]**2 + s[1]**2, s[1]**2 + s[2]**2, s[0]**2 + s[2]**2])) @ R.T,
     "*across* the x axis"),
])
def test_box_inertia_misconceptions(answer, hint):
    _failed(check.box_inertia, answer, hint)


# --- collision impulse -------------------------------------------------------------------

def collision_impulse(mass, inv_inertia, r, normal, v, omega, restitution):
    u_n = (v + np.cross(omega, r)) @ normal
    if u_n >= 0:
        return 0.0
    return -(1 + restitution) * u_n / (1 / mass + np.cross(inv_inertia @ np.cross(r, normal), r) @ normal)


def test_collision_impulse_right_and_delegating():
    assert evaluate(check.collision_impulse, collision_impulse)["status"] == "correct"
    verdict = evaluate(check.collision_impulse,
                       lambda m, inv, r, n, v, w, e: rigid.contact.normal_impulse(m, inv, r, n, v, w, e))
    assert verdict["status"] == "incorrect" and "uses the reference" in verdict["reference"]


def test_collision_impulse_shortcut_without_the_approach_test():
    """The formula alone, without 'only while approaching', fails the separating contact."""
    def always(mass, inv_inertia, r, normal, v, omega, restitution):
        u_n = (v + np.cross(omega, r)) @ normal
        return -(1 + restitution) * u_n / (1 / mass + np.cross(inv_inertia @ np.cross(r, normal), r) @ normal)

    verdict = _failed(check.collision_impulse, always, "already moves away")
    assert verdict["passed"] == 4                                          # the four approaching cases pass


@pytest.mark.parametrize("answer,hint", [
    (lambda m, inv, r, n, v, w, e: max(-(1 + e) * ((v + np.cross(w, r)) @ n) * m, 0.0), "starts to spin"),
    (lambda m, inv, r, n, v, w, e: collision_impulse(m, inv, r, n, v, np.zeros(3), e), "v + ω × r"),
    (lambda m, inv, r, n, v, w, e: collision_impulse(m, np.linalg.inv(inv), r, n, v, w, e), "do not invert"),
    (lambda m, inv, r, n, v, w, e: collision_impulse(m, inv, r, n, v, w, e) * e / (1 + e), "(1 + e) times"),
])
def test_collision_impulse_misconceptions(answer, hint):
    _failed(check.collision_impulse, answer, hint)

"""The exercise checks of notebook 14 against planted answers.

For each of the five exercises: the right answer passes and a stub is pending; an answer
that delegates to the library fails as using the reference; a shortcut that the check's
data break fails (a non-unit or turned quaternion, sides in another order, a step long
enough that a fixed-point iteration or two Newton iterations fall short, a contact moving
away, a point that does not slide); and the usual misconceptions fail with the hint that
names them. Verdicts come from ``evaluate`` as the grader runs it (a fresh kernel: the
nudge, never the fuller hint); a second wrong attempt in one kernel shows the fuller hint.
"""

import contextlib
import io

import pytest
from planted import Plant, judge

from course_lib.check import FAILURES
from course_lib.check import nb14 as check

QUATERNION = '''
def quaternion_step(q, omega, dt):
    w, u = q[0], q[1:]
    q1 = q + 0.5 * dt * np.concatenate(([-omega @ u], w * omega + np.cross(omega, u)))
    return q1 / np.linalg.norm(q1)
'''
BOX = '''
def box_inertia(mass, sides, R):
    a, b, c = sides
    return R @ (mass / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])) @ R.T
'''
MIDPOINT = '''
def cross_matrix(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])

def midpoint_step(L, moments, dt, iterations=50, theta=0.5, sign=1.0):
    L1 = L.copy()
    for _ in range(iterations):
        X = (1 - theta) * L + theta * L1
        residual = L1 - L - sign * dt * np.cross(X, X / moments)
        jacobian = np.eye(3) - sign * theta * dt * (cross_matrix(X) / moments - cross_matrix(X / moments))
        update = np.linalg.solve(jacobian, residual)
        L1 = L1 - update
        if np.linalg.norm(update) < 1e-12 * np.linalg.norm(L):
            break
    return L1
'''
IMPULSE = '''
def collision_impulse(mass, inv_inertia, r, normal, v, omega, restitution):
    u_n = (v + np.cross(omega, r)) @ normal
    if u_n >= 0:
        return 0.0
    return -(1 + restitution) * u_n / (1 / mass + np.cross(inv_inertia @ np.cross(r, normal), r) @ normal)
'''
FRICTION = '''
def friction_impulse(mass, inv_inertia, r, normal, v, omega, j_n, mu):
    u = v + np.cross(omega, r)
    u_t = u - (u @ normal) * normal
    slip = np.linalg.norm(u_t)
    if slip == 0.0:
        return np.zeros(3)
    t = u_t / slip
    k_t = 1 / mass + np.cross(inv_inertia @ np.cross(r, t), r) @ t
    return -min(slip / k_t, mu * j_n) * t
'''


def _wrap(name, args, body):
    return f"def {name}({args}):\n" + "".join(f"    {line}\n" for line in body.strip().splitlines())


def _q(body):
    return _wrap("quaternion_step", "q, omega, dt", body)


def _box(body):
    return _wrap("box_inertia", "mass, sides, R", body)


def _mid(body):
    newton = MIDPOINT.replace("def midpoint_step(", "def _newton(")
    return newton + _wrap("midpoint_step", "L, moments, dt", body)


def _imp(body):
    return _wrap("collision_impulse", "mass, inv_inertia, r, normal, v, omega, restitution", body)


def _fr(body):
    return FRICTION.replace("def friction_impulse(", "def _right(") + _wrap(
        "friction_impulse", "mass, inv_inertia, r, normal, v, omega, j_n, mu", body)


STUB = "raise NotImplementedError()"

PLANTS = [
    # --- Exercise 1: the quaternion step --------------------------------------------------
    Plant("quaternion_step", "other", "right", QUATERNION, "correct", ""),
    Plant("quaternion_step", "other", "stub", _q(STUB), "pending", ""),
    Plant("quaternion_step", "delegating", "rigid.quaternion.step",
          "from course_lib import rigid\n" + _q("return rigid.quaternion.step(q, omega, dt)"),
          "incorrect", ""),
    Plant("quaternion_step", "delegating", "the product from the library",
          "from course_lib.rigid import quaternion as qu\n" + _q(
              "q1 = q + 0.5 * dt * qu.multiply(np.r_[0.0, omega], q)\nreturn q1 / np.linalg.norm(q1)"),
          "incorrect", ""),
    Plant("quaternion_step", "shortcut", "an exact rotation that trusts |q| = 1", _q('''
angle = np.linalg.norm(omega) * dt
axis = omega / np.linalg.norm(omega)
w, u = np.cos(angle / 2), np.sin(angle / 2) * axis
return np.r_[w * q[0] - u @ q[1:], w * q[1:] + q[0] * u + np.cross(u, q[1:])]'''),
"incorrect", "length 1.03"),
    Plant("quaternion_step", "misconception", "no renormalisation", _q(
        "return q + 0.5 * dt * np.r_[-omega @ q[1:], q[0] * omega + np.cross(omega, q[1:])]"),
        "incorrect", "not of length 1"),
    Plant("quaternion_step", "misconception", "q ⊗ (0, ω)", _q(
        "p = q + 0.5 * dt * np.r_[-omega @ q[1:], q[0] * omega + np.cross(q[1:], omega)]\n"
        "return p / np.linalg.norm(p)"), "incorrect", "order of the product"),
    Plant("quaternion_step", "misconception", "no ½", _q(
        "p = q + dt * np.r_[-omega @ q[1:], q[0] * omega + np.cross(omega, q[1:])]\n"
        "return p / np.linalg.norm(p)"), "incorrect", "left out the ½"),
    Plant("quaternion_step", "other", "minus the step", _q(
        "p = q - 0.5 * dt * np.r_[-omega @ q[1:], q[0] * omega + np.cross(omega, q[1:])]\n"
        "return p / np.linalg.norm(p)"), "incorrect", "check its sign"),
    Plant("quaternion_step", "other", "(x, y, z, w) storage", _q(
        "w, u = q[3], q[:3]\n"
        "p = np.r_[u + 0.5 * dt * (w * omega + np.cross(omega, u)), w - 0.5 * dt * omega @ u]\n"
        "return p / np.linalg.norm(p)"), "incorrect", "scalar part comes first"),
    # --- Exercise 2: the inertia of a box -------------------------------------------------
    Plant("box_inertia", "other", "right", BOX, "correct", ""),
    Plant("box_inertia", "delegating", "world_tensor of box_moments",
          "from course_lib import rigid\n" + _box(
              "return rigid.inertia.world_tensor(R, rigid.inertia.box_moments(mass, sides))"),
              "incorrect", ""),
    Plant("box_inertia", "shortcut", "sides sorted (the first box comes sorted)",
          BOX.replace("a, b, c = sides", "a, b, c = np.sort(sides)[::-1]"), "incorrect", "own body axis"),
    Plant("box_inertia", "misconception", "the body tensor",
          BOX.replace("return R @ (", "return (").replace(") @ R.T", ")"),
          "incorrect", "body-frame tensor"),
    Plant("box_inertia", "misconception", "Rᵀ I R",
          BOX.replace("return R @ (", "return R.T @ (").replace(") @ R.T", ") @ R"),
          "incorrect", "not Rᵀ I R"),
    Plant("box_inertia", "misconception", "element-wise R * D * R.T",
          BOX.replace("return R @ (", "return R * (").replace(") @ R.T", ") * R.T"), "incorrect", "use @"),
    Plant("box_inertia", "misconception", "the inverse tensor",
          BOX.replace("return R @ (", "return np.linalg.inv(R @ (").replace(") @ R.T", ") @ R.T)"),
          "incorrect", "inverse tensor I⁻¹"),
    Plant("box_inertia", "misconception", "each side's own square", _box(
        "return R @ (mass / 12 * np.diag(np.asarray(sides) ** 2)) @ R.T"),
        "incorrect", "not the x side's own"),
    Plant("box_inertia", "misconception", "m/3", BOX.replace("mass / 12", "mass / 3"),
          "incorrect", "half-sides"),
    Plant("box_inertia", "misconception", "squares along the axis",
          BOX.replace("[b * b + c * c, a * a + c * c, a * a + b * b]",
                      "[a * a + b * b, b * b + c * c, a * a + c * c]"),
          "incorrect", "*across* the x axis"),
    # --- Exercise 3: the implicit midpoint step ------------------------------------------
    Plant("midpoint_step", "other", "right", MIDPOINT, "correct", ""),
    Plant("midpoint_step", "other", "stub", _wrap("midpoint_step", "L, moments, dt", STUB), "pending", ""),
    Plant("midpoint_step", "delegating", "rigid.free.implicit_solve",
          "from course_lib.rigid import free\n" + _wrap("midpoint_step", "L, moments, dt",
                                                         "return free.implicit_solve(L, moments, dt, 0.5)"),
          "incorrect", ""),
    Plant("midpoint_step", "delegating", "one step of rigid.free_body",
          "from course_lib import rigid\n" + _wrap("midpoint_step", "L, moments, dt",
                                                    "return rigid.free_body(moments, L / moments, dt, 1)"
                                                    "[1][-1] * moments"),
          "incorrect", ""),
    Plant("midpoint_step", "shortcut", "two Newton iterations (enough at short steps)",
          _mid("return _newton(L, moments, dt, iterations=2)"), "incorrect", "not solved to round-off"),
    Plant("midpoint_step", "shortcut", "a fixed-point iteration", _wrap("midpoint_step", "L, moments, dt", '''
L1 = L.copy()
for _ in range(50):
    Lm = 0.5 * (L + L1)
    new = L + dt * np.cross(Lm, Lm / moments)
    if np.linalg.norm(new - L1) < 1e-12 * np.linalg.norm(L):
        return new
    L1 = new
return L1'''), "incorrect", "fixed-point iteration"),
    Plant("midpoint_step", "misconception", "explicit Euler", _wrap(
        "midpoint_step", "L, moments, dt", "return L + dt * np.cross(L, L / moments)"),
        "incorrect", "explicit Euler step"),
    Plant("midpoint_step", "misconception", "backward Euler",
          _mid("return _newton(L, moments, dt, theta=1.0)"),
          "incorrect", "that is backward Euler"),
    Plant("midpoint_step", "misconception", "the explicit midpoint rule (also of order 2)", _wrap(
        "midpoint_step", "L, moments, dt",
        "Lm = L + 0.5 * dt * np.cross(L, L / moments)\nreturn L + dt * np.cross(Lm, Lm / moments)"),
          "incorrect", "explicit midpoint rule"),
    Plant("midpoint_step", "other", "Ω × L", _mid("return _newton(L, moments, dt, sign=-1.0)"),
          "incorrect", "not Ω × L"),
    Plant("midpoint_step", "other", "Ω = L · I", _mid("return _newton(L, 1.0 / moments, dt)"),
          "incorrect", "not L · I"),
    # --- Exercise 4: the collision impulse ------------------------------------------------
    Plant("collision_impulse", "other", "right", IMPULSE, "correct", ""),
    Plant("collision_impulse", "delegating", "rigid.contact.normal_impulse",
          "from course_lib import rigid\n" + _imp(
              "return rigid.contact.normal_impulse(mass, inv_inertia, r, normal, v, omega, restitution)"),
          "incorrect", ""),
    Plant("collision_impulse", "shortcut", "no approach test", IMPULSE.replace(
        "    if u_n >= 0:\n        return 0.0\n", ""), "incorrect", "already moves away"),
    Plant("collision_impulse", "shortcut", "|u_n| without the approach test", _imp('''
u_n = abs((v + np.cross(omega, r)) @ normal)
return (1 + restitution) * u_n / (1 / mass + np.cross(inv_inertia @ np.cross(r, normal), r) @ normal)'''),
          "incorrect", "abs(u_n) hides the direction"),
    Plant("collision_impulse", "misconception", "K_n = 1/m", _imp('''
u_n = (v + np.cross(omega, r)) @ normal
return max(-(1 + restitution) * u_n * mass, 0.0)'''), "incorrect", "starts to spin"),
    Plant("collision_impulse", "misconception", "u = v",
          IMPULSE.replace("(v + np.cross(omega, r)) @ normal", "v @ normal"),
          "incorrect", "v + ω × r, not with v alone"),
    Plant("collision_impulse", "misconception", "r × ω",
          IMPULSE.replace("np.cross(omega, r)", "np.cross(r, omega)"),
          "incorrect", "not v + r × ω"),
    Plant("collision_impulse", "misconception", "K_n with a sign slip", IMPULSE.replace(
        "np.cross(inv_inertia @ np.cross(r, normal), r) @ normal",
        "normal @ np.cross(r, inv_inertia @ np.cross(r, normal))"),
          "incorrect", "K_n > 0 always"),
    Plant("collision_impulse", "misconception", "e u_n",
          IMPULSE.replace("-(1 + restitution)", "-restitution"),
          "incorrect", "(1 + e) times"),
    Plant("collision_impulse", "misconception", "inverts inv_inertia", IMPULSE.replace(
        "inv_inertia @", "np.linalg.inv(inv_inertia) @"), "incorrect", "do not invert"),
    # --- Exercise 5: the friction impulse -------------------------------------------------
    Plant("friction_impulse", "other", "right", FRICTION, "correct", ""),
    Plant("friction_impulse", "delegating", "rigid.contact.friction_impulse",
          "from course_lib.rigid import contact\n" + _wrap(
              "friction_impulse", "mass, inv_inertia, r, normal, v, omega, j_n, mu",
              "return contact.friction_impulse(mass, inv_inertia, r, normal, v, omega, j_n, mu)"),
          "incorrect", ""),
    Plant("friction_impulse", "shortcut", "always μ j_n (kinetic friction only)",
          FRICTION.replace("min(slip / k_t, mu * j_n)", "mu * j_n"),
          "incorrect", "only while the point keeps sliding"),
    Plant("friction_impulse", "shortcut", "no guard for a point that does not slide",
          FRICTION.replace("    if slip == 0.0:\n        return np.zeros(3)\n", ""), "incorrect",
          "when the point does not slide"),
    Plant("friction_impulse", "misconception", "K_t = 1/m", FRICTION.replace(
        "1 / mass + np.cross(inv_inertia @ np.cross(r, t), r) @ t", "1 / mass"),
        "incorrect", "the point also turns"),
    Plant("friction_impulse", "misconception", "K_n instead of K_t", FRICTION.replace(
        "np.cross(inv_inertia @ np.cross(r, t), r) @ t",
        "np.cross(inv_inertia @ np.cross(r, normal), r) @ normal"),
          "incorrect", "along the slip direction t"),
    Plant("friction_impulse", "misconception", "u = v",
          FRICTION.replace("u = v + np.cross(omega, r)", "u = v"),
          "incorrect", "not with v alone"),
    Plant("friction_impulse", "misconception", "no cap",
          FRICTION.replace("min(slip / k_t, mu * j_n)", "slip / k_t"),
          "incorrect", "caps the impulse"),
    Plant("friction_impulse", "misconception", "along +t", FRICTION.replace("return -min(", "return min("),
          "incorrect", "opposes the sliding"),
    Plant("friction_impulse", "other", "the cap on each component", _fr('''
J = _right(mass, inv_inertia, r, normal, v, omega, 1e300, np.inf)
return np.clip(J, -mu * j_n, mu * j_n)'''), "incorrect", "not on each component"),
    Plant("friction_impulse", "other", "the normal part of u left in", FRICTION.replace(
        "u_t = u - (u @ normal) * normal", "u_t = u"), "incorrect", "remove the normal part"),
]


@pytest.mark.parametrize("plant", PLANTS, ids=lambda p: f"{p.exercise}-{p.label}")
def test_planted_answer(plant):
    judge(check, plant)


def test_every_exercise_has_the_three_kinds():
    for name in ("quaternion_step", "box_inertia", "midpoint_step", "collision_impulse", "friction_impulse"):
        kinds = {p.kind for p in PLANTS if p.exercise == name}
        assert {"delegating", "shortcut", "misconception"} <= kinds, name


def test_the_simulation_checks_report_what_they_measured():
    """The right midpoint step gets the period errors at N = 50, 100, 200 and the order 2.0;
    the right friction gets the ball rolling at 5/7 v₀ from the step after 2v₀/(7μg)."""
    mid = judge(check, next(p for p in PLANTS if p.exercise == "midpoint_step" and p.label == "right"))
    text = "\n".join(mid["passed_cases"])
    assert "-9.0e-03, -2.2e-03, -5.4e-04" in text and "observed order of the period error 2.0" in text
    fr = judge(check, next(p for p in PLANTS if p.exercise == "friction_impulse" and p.label == "right"))
    assert "rolls from t = 0.195 s" in "\n".join(fr["passed_cases"])
    assert "0.714285714286 (5/7)" in "\n".join(fr["passed_cases"])


@pytest.mark.parametrize("exercise,answer,nudge,more", [
    ("box_inertia", _box("return R @ (mass / 12 * np.diag(np.asarray(sides) ** 2)) @ R.T"),
     "not the x side's own", "I_xx = m (b² + c²)/12"),
    ("midpoint_step", _wrap("midpoint_step", "L, moments, dt", "return L + dt * np.cross(L, L / moments)"),
     "explicit Euler step", "by Newton's method, L_m"),
    ("friction_impulse",
     FRICTION.replace("1 / mass + np.cross(inv_inertia @ np.cross(r, t), r) @ t", "1 / mass"),
     "the point also turns", "K_t = 1/m + t·((I⁻¹(r × t)) × r)"),
])
def test_hints_escalate(exercise, answer, nudge, more):
    """In one kernel: the nudge first, the fuller hint (with the formula) only after
    another wrong attempt."""
    from planted import define

    fn = define(answer, exercise)
    check_fn = getattr(check, exercise)
    FAILURES.pop(check_fn.key, None)
    said = []
    for _ in range(2):
        with contextlib.redirect_stdout(io.StringIO()) as out:
            check_fn(fn)
        said.append(out.getvalue())
    FAILURES.pop(check_fn.key, None)
    assert nudge in said[0] and more not in said[0]
    assert more in said[1]

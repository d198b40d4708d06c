"""Checks, hints and sentences of notebooks 05-08 after the fifth blind read.

- 06 Exercise 4 said "no Python loop over bodies: the check notices one"; a loop that first
  wrote ``x = np.asarray(x, float)`` (or ``np.array(x)``) passed, because the check watched
  only the argument array. The check now also counts the Python lines the answer runs on a
  case of many bodies (as ``drag_force`` and ``located_bounce`` do).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from notebook_helpers import markdown as _markdown
from planted import Plant, define, judge
from test_nb06_forces import NBODY_RIGHT

from course_lib.check import evaluate
from course_lib.check import nb06 as check06

# --- 06 Exercise 4: a loop over bodies is caught however the input is converted ----------

_LOOP_AFTER_ASARRAY = """def nbody_force(x, mass, G, softening):
    x = np.asarray(x, float)
    F = np.zeros_like(x)
    for i in range(len(x)):
        r = x[i] - x
        d2 = np.sum(r * r, axis=1) + softening**2
        d2[i] = np.inf
        F[i] = -G * mass[i] * np.sum((mass / d2**1.5)[:, None] * r, axis=0)
    return F"""
_PAIRS_AFTER_ARRAY = """def nbody_force(x, mass, G, softening):
    x = np.array(x)
    n = len(x)
    F = np.zeros(x.shape)
    for i in range(n):
        for j in range(i + 1, n):
            r = x[i] - x[j]
            f = G * mass[i] * mass[j] * r / (r @ r + softening**2) ** 1.5
            F[i] -= f
            F[j] += f
    return F"""
_COMPREHENSION_AFTER_COPY = """def nbody_force(x, mass, G, softening):
    pos = np.asarray(x, dtype=np.float64).copy()
    def one(i):
        r = pos[i] - pos
        d2 = np.einsum("jk,jk->j", r, r) + softening**2
        d2[i] = np.inf
        return -G * mass[i] * ((mass / d2**1.5) @ r)
    return np.array([one(i) for i in range(pos.shape[0])])"""
_TOLIST_LOOP = """def nbody_force(x, mass, G, softening):
    pts = np.asarray(x).tolist()
    F = []
    for i, a in enumerate(pts):
        f = np.zeros(len(a))
        for j, b in enumerate(pts):
            if i != j:
                r = np.subtract(a, b)
                f -= G * mass[i] * mass[j] * r / (r @ r + softening**2) ** 1.5
        F.append(f)
    return np.array(F)"""

NBODY_PLANTS = [
    Plant("nbody_force", "shortcut", "a loop over bodies after np.asarray(x, float)",
          _LOOP_AFTER_ASARRAY, "incorrect", "loops over the bodies"),
    Plant("nbody_force", "shortcut", "a double loop over pairs after np.array(x)",
          _PAIRS_AFTER_ARRAY, "incorrect", "loops over the bodies"),
    Plant("nbody_force", "shortcut", "a comprehension over bodies on a converted copy",
          _COMPREHENSION_AFTER_COPY, "incorrect", "loops over the bodies"),
    Plant("nbody_force", "shortcut", "nested loops over x.tolist()",
          _TOLIST_LOOP, "incorrect", "loops over the bodies"),
    Plant("nbody_force", "other", "right", NBODY_RIGHT, "correct", ""),
    Plant("nbody_force", "other", "right, after np.asarray(x, float)",
          NBODY_RIGHT.replace("    r = x[:, None, :]",
                              "    x = np.asarray(x, float)\n    mass = np.array(mass)\n"
                              "    r = x[:, None, :]"), "correct", ""),
    Plant("nbody_force", "other", "right, with a loop over the d coordinates",
          """def nbody_force(x, mass, G, softening):
    x = np.array(x, dtype=float)
    n, d = x.shape
    r = np.empty((n, n, d))
    for k in range(d):
        r[:, :, k] = x[:, k, None] - x[None, :, k]
    d2 = (r**2).sum(-1) + softening**2
    np.fill_diagonal(d2, np.inf)
    w = mass[:, None] * mass[None, :] / d2**1.5
    return -G * (w[:, :, None] * r).sum(axis=1)""", "correct", ""),
]


@pytest.mark.parametrize("plant", NBODY_PLANTS, ids=lambda p: p.label)
def test_nbody_loop_is_caught_however_the_positions_are_converted(plant):
    verdict = judge(check06, plant)
    if plant.status == "incorrect":
        assert verdict["passed"] < verdict["total"]


# --- 06 Exercise 2: a short fixed-point iteration is named where it has not converged -----

_ITERATE_FROM_ONE = """def terminal_speed(m, g, b, c):
    v = 1.0
    for _ in range(40):
        v = m * g / (b + c * v)
    return v"""
_ITERATE_UNTIL_STILL = """def terminal_speed(m, g, b, c):
    v = m * g / (b + c + 1e-3)
    for _ in range(30):
        new = m * g / (b + c * v)
        if abs(new - v) < 1e-12 * v:
            break
        v = new
    return v"""


@pytest.mark.parametrize("source", [_ITERATE_FROM_ONE, _ITERATE_UNTIL_STILL],
                         ids=["40 steps from v = 1", "at most 30 steps, stop when still"])
def test_a_short_fixed_point_iteration_gets_a_hint_where_it_has_not_converged(source):
    plant = Plant("terminal_speed", "other", "short iteration", source, "incorrect",
                  "if you iterate v = m g / (b + c v)")
    verdict = judge(check06, plant)
    failed = verdict["failed_cases"]
    assert any("b = 0.0 kg/s" in case for case in failed)
    assert all("converges slowly" in case and "solve the balance once" in case for case in failed)
    escalated = judge(check06, Plant("terminal_speed", "other", "again", source, "incorrect",
                                     "its positive root, written 2 m g", attempt=1))
    assert escalated["passed"] == verdict["passed"]


def test_the_iteration_hint_does_not_land_on_a_case_where_iteration_converges_fast():
    """b large next to c v: a wrong answer there is not blamed on an iteration."""
    source = ("def terminal_speed(m, g, b, c):\n"
              "    return 1.001 * 2 * m * g / (b + np.sqrt(b * b + 4 * c * m * g))")
    verdict = judge(check06, Plant("terminal_speed", "other", "0.1 % off", source,
                                   "incorrect", ""))
    fast = [case for case in verdict["failed_cases"] if "b = 0.5 kg/s, c = 0.05" in case]
    assert fast and "iterate" not in fast[0]


# --- 06 Exercise 5: a loop over particles is caught (a case of 300 particles) -------------

_BOUNCE_LOOP = """def bounce(y, restitution, friction):
    out = np.array(y, dtype=float)
    for p in range(out.shape[1]):
        x, v = out[0, p], out[1, p]
        if x[1] < 0:
            x[1] = 0.0
            if v[1] < 0:
                vn = v[1]
                vt = v.copy()
                vt[1] = 0.0
                s = np.linalg.norm(vt)
                scale = max(0.0, 1 - friction * (1 + restitution) * abs(vn) / s) if s else 0.0
                v[:] = scale * vt
                v[1] = -restitution * vn
    return out"""


def test_a_loop_over_particles_in_the_bounce_is_caught():
    from test_nb06_forces import BOUNCE_RIGHT

    judge(check06, Plant("bounce", "other", "right", BOUNCE_RIGHT, "correct", ""))
    verdict = judge(check06, Plant("bounce", "shortcut", "a loop over particles", _BOUNCE_LOOP,
                                   "incorrect", "loops over the particles"))
    assert any("300 particles" in case and "no Python loop" in case
               for case in verdict["failed_cases"])


def test_notebook_06_prompts_say_what_the_checks_count():
    """Exercise 4 promised that 'the check notices' a loop (it did not after np.asarray);
    Exercise 5 asked for 'all particles at once' with no check. Both now count lines, on the
    number of bodies and particles the prompt names."""
    from course_lib.check._nb06_cases import ground_states, nbody_cases

    text = _markdown("06_forces.ipynb")
    assert "the check notices" not in text
    bodies = max(x.shape[0] for _, x, *_ in nbody_cases())
    particles = max(y.shape[1] for _, y, *_ in ground_states())
    assert f"counts the lines of Python your function runs, and tries {bodies} bodies" in text
    assert (f"counts the lines of Python your function runs, and tries {particles} particles"
            in text)
    assert check06.ARRAY_LINES < min(bodies, particles)


def test_notebook_06_summary_lets_a_damped_glider_coast_a_distance():
    """'damping stops a glider after v0 m/c' read as a time and as a stop; it is a distance,
    approached for ever: the library's glider creeps towards v0 m/c and never passes it."""
    import course_lib as cl

    text = _markdown("06_forces.ipynb")
    assert "damping stops a glider" not in text
    assert "coast a total $v_0 m/c$, approached but never reached" in text
    m, c, v0 = 1.0, 0.5, 2.0
    glider = cl.newtonian(cl.forces.viscous_damping(c), m)
    glide = cl.integrate(glider, cl.stack_state([[0.0, 0.0]], [[v0, 0.0]]), (0.0, 40.0), 0.01,
                         "rk4")
    x = glide.y[:, 0, 0, 0]
    assert np.all(np.diff(x) > 0) and np.all(x < v0 * m / c)    # still moving, never there
    assert v0 * m / c - x[-1] == pytest.approx(v0 * m / c * np.exp(-c * 40.0 / m), rel=1e-6)


# --- 07 Exercise 2: the mass misplaced, and a factor 2 lost in the quadratic formula ------

_DT_RIGHT = "    g, w2 = c / m, k / m\n    return (-g + np.sqrt(g * g + 4 * w2)) / w2"


@pytest.mark.parametrize("body, says", [
    ("    zeta = c / (2 * np.sqrt(k))\n    w = np.sqrt(k / m)\n"
     "    return 2 / w * (np.sqrt(1 + zeta**2) - zeta)", "not 2√k"),
    ("    g, w2 = c / m, k\n    return (-g + np.sqrt(g * g + 4 * w2)) / w2",
     "left the mass out of it"),
    ("    return 4.0 / (c + np.sqrt(c * c + 4.0 * k))", "missing from both terms"),
    ("    g, w2 = c, k / m\n    return (-g + np.sqrt(g * g + 4 * w2)) / w2",
     "damping rate γ = c/m"),
    ("    g, w2 = c / m, k / m\n    return (-2 * g + np.sqrt(4 * g**2 + 16 * w2)) / w2",
     "off by exactly a factor of 2: redo the quadratic formula"),
    ("    g, w2 = c / m, k / m\n    return (-2 * g + np.sqrt(4 * g**2 + 16 * w2)) / (4 * w2)",
     "off by exactly a factor of 2 (half the limit)"),
], ids=["c_crit = 2√k", "ω² = k", "no m anywhere", "γ = c", "root doubled", "root halved"])
def test_damped_dt_max_names_a_misplaced_mass_or_a_lost_factor_of_two(body, says):
    from course_lib.check import nb07 as check07

    source = "def damped_dt_max(k, m, c):\n" + body
    verdict = judge(check07, Plant("damped_dt_max", "other", says, source, "incorrect", says))
    assert all(says in case for case in verdict["failed_cases"]), verdict["failed_cases"]
    judge(check07, Plant("damped_dt_max", "other", "right",
                         "def damped_dt_max(k, m, c):\n" + _DT_RIGHT, "correct", ""))


# --- 07 cell 12-13: the table shows every window the formulas give -----------------------

def test_notebook_07_table_prints_every_window_of_the_formulas():
    """Cell 13 says "the scan finds every edge the formulas give"; the scan stopped at
    2.6 x 2/ω and the table showed ζ = 0.25 with one Verlet window where the formulas give
    two (the second 3.749 to 4 x 2/ω). Every row of the stored table must now print all the
    windows of :func:`stable_windows`, both methods, every ζ."""
    import nbformat

    from course_lib.lessons import nb07_springs as nb07

    path = Path(__file__).resolve().parents[1] / "solutions" / "07_springs.ipynb"
    cell = next(c for c in nbformat.read(path, 4).cells
                if c.cell_type == "code" and "scan_windows" in c.source)
    out = "".join(o.get("text", "") for o in cell.outputs)
    k, m = 10.0, 1.0
    unit = 2 / np.sqrt(k / m)
    c_crit = 2 * np.sqrt(k * m)
    rows = [line for line in out.splitlines() if line[:6].strip().replace(".", "").isdigit()]
    assert len(rows) == 5
    for line in rows:
        zeta = float(line.split()[0])
        for name in ("symplectic_euler", "velocity_verlet"):
            windows = nb07.stable_windows(name, k, m, zeta * c_crit)
            text = " and ".join(f"< {hi / unit:.5f}" if lo == 0 else
                                f"{lo / unit:.5f} to {hi / unit:.5f}" for lo, hi in windows)
            assert text in line, (zeta, name, text, line)
    assert "0.25" in out and "< 0.91598 and 3.74888 to 4.00000" in out
    text = _markdown("07_springs.ipynb")
    assert "Below $\\zeta^*$ velocity Verlet" not in text and "below $\\zeta^* \\approx" not in text
    assert text.count("$0 < \\zeta < \\zeta^*") == 2


# --- 05: Exercise 1's time hint names the time called, and the summary's RK4 sentence -----

_SE = """def symplectic_euler_step(f, t, y, dt):
    v = y[1] + dt * f(TIME, y)[1]
    return np.stack((y[0] + dt * v, v))"""


@pytest.mark.parametrize("time, says", [
    ("0.0", "your function evaluated f at time 0; the step starts at t = 0.7 s"),
    ("0", "your function evaluated f at time 0; the step starts at t = 0.7 s"),
    ("dt", "your function evaluated f at time 0.1 s; the step starts at t = 0.7 s"),
    ("t + dt / 2", "your function evaluated f at t + dt/2; the step starts at t = 0.7 s"),
    ("t + dt", "the acceleration belongs to the start of the step: f(t, y), not f(t + dt, y)"),
    ("t - dt", "your function evaluated f at t - dt; the step starts at t = 0.7 s"),
], ids=["f(0.0, y)", "f(0, y)", "f(dt, y)", "f(t + dt/2, y)", "f(t + dt, y)",
                        "f(t - dt, y)"])
def test_a_step_at_the_wrong_time_is_told_which_time_it_used(time, says):
    from course_lib.check import nb05 as check05

    verdict = judge(check05, Plant("symplectic_euler_step", "other", time,
                                   _SE.replace("TIME", time), "incorrect", says))
    assert "t - 0.7" not in "\n".join(verdict["failed_cases"])


def test_notebook_05_summary_says_rk4_energy_falls_every_step():
    """'RK4's energy drifts slowly and without bound' reads as unbounded energy; it decays
    towards 0. The library's RK4 oscillator loses a little energy on every step."""
    import course_lib as cl

    text = _markdown("05_newtons_second_law.ipynb")
    assert "drifts slowly and without bound" not in text
    assert "RK4's\n  energy falls a little every step, for as long as the run lasts" in text \
        or "RK4's energy falls a little every step, for as long as the run lasts" in text
    spring = cl.newtonian(lambda t, x, v: -x, 1.0)
    run = cl.integrate(spring, cl.stack_state([[1.0]], [[0.0]]), (0.0, 200.0), 0.5, "rk4")
    energy = 0.5 * (run.y[:, 0, 0, 0] ** 2 + run.y[:, 1, 0, 0] ** 2)
    assert np.all(np.diff(energy) < 0) and energy[-1] > 0


# --- 08 (and every notebook): the library message says "uses" when a name is not called ---

_NAMES_ONLY = """def strand_springs(x0):
    builder = cl.springs.hair_chain              # named, never called
    net = cl.springs.SpringNetwork(np.zeros((2, 3)), [0], [1], [1.0], 1.0)
    return net.i, net.j, net.rest"""
_CALLS_ONLY = """def strand_springs(x0):
    net = cl.strands.strand_network(x0, 1.0, 1.0, 1.0)
    return net.i, net.j, net.rest"""


@pytest.mark.parametrize("source, verb, names", [
    (_NAMES_ONLY, "uses", ("hair_chain", "SpringNetwork")),
    ("def strand_springs(x0, chain=cl.springs.hair_chain):\n    return 0, 0, 0",
     "uses", ("hair_chain",)),
    ("def strand_springs(x0):\n    return pick(cl.springs.hair_chain)",
     "uses", ("hair_chain",)),
    (_CALLS_ONLY, "calls", ("course_lib.strands.strand_network",)),
    ("def strand_springs(x0):\n    return hair_chain(len(x0))", "calls",
     ("hair_chain",)),
], ids=["assigned and a class called", "a default", "passed on", "called", "called bare"])
def test_library_message_says_uses_when_a_name_is_only_named(source, verb, names):
    from course_lib.check import nb08 as check08
    from course_lib.springs import hair_chain

    check = check08.strand_springs
    verdict = evaluate(check, define(source, "strand_springs", pick=lambda f: f,
                                     hair_chain=hair_chain))
    line = verdict["failed_cases"][0]
    assert verdict["status"] == "incorrect"
    assert line.startswith(f"uses the reference: your function {verb} "), line
    assert all(name in line for name in names), line

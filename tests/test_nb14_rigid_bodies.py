"""Every number quoted in solutions/14_rigid_bodies.ipynb, against course_lib and theory.

The spin runs are plain float arithmetic (course_lib.rigid._spin), identical on every
machine; where the notebook quotes a round-off level, the test bounds it by a few units of
round-off per step. The dropped box and the magnets are contact runs: the notebook's seed
is checked against what theory says of its end state, and the tests of
test_rigid_contact.py and test_rigid_magnets.py judge ensembles of seeds.
"""

import numpy as np
import pytest

from course_lib import rigid
from course_lib.lessons import nb14_rigid_bodies as nb14
from course_lib.rigid import exact, magnets
from course_lib.rigid import quaternion as quat

EPS = np.finfo(float).eps


def test_section1_quaternion_growth_and_lag():
    q0 = quat.from_axis_angle([1.0, 1.0, 0.0], 0.7)
    omega, dt, steps = np.array([0.0, 10.0, 0.0]), 0.01, 800
    q_raw, q_unit = q0.copy(), q0.copy()
    for _ in range(steps):
        q_raw = quat.step(q_raw, omega, dt, renormalise=False)
        q_unit = quat.step(q_unit, omega, dt)
    predicted = (1 + (10 * dt) ** 2 / 4) ** (steps / 2)
    assert np.linalg.norm(q_raw) == pytest.approx(predicted, rel=steps * 8 * EPS)
    assert f"{predicted:.2f}" == "2.71" and f"{predicted**2:.2f}" == "7.37"    # "2.71 times", "7.37"
    v = quat.multiply(quat.multiply(q_raw, [0.0, 1.0, 0.0, 0.0]), quat.conjugate(q_raw))[1:]
    assert np.linalg.norm(v) == pytest.approx(predicted**2, rel=steps * 16 * EPS)   # stretched by |q|²
    # the unit-quaternion matrix formula on q_raw is |q|² R + (1 − |q|²) 1: not a stretched rotation
    w, x, y, z = q_raw
    M = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    s = np.linalg.svd(M, compute_uv=False)
    assert s.max() / s.min() > 1.5                                           # unequal stretches
    R = quat.to_matrix(q_raw)                                            # divides by |q| first
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-14)
    assert np.linalg.norm(q_unit) == pytest.approx(1.0, abs=4 * EPS)
    lag_per_step = 0.1 - 2 * np.arctan(0.05)
    assert lag_per_step == pytest.approx(0.1**3 / 12, rel=0.01)                # |ω|³Δt³/12
    gap = quat.multiply(q_unit, quat.conjugate(quat.multiply(quat.from_rotvec(omega * 8.0), q0)))
    lag = 2 * np.arcsin(np.linalg.norm(gap[1:]))
    assert lag == pytest.approx(steps * lag_per_step, rel=1e-9)
    assert f"{np.degrees(lag):.1f}" == "3.8"


def test_section2_inertia_numbers():
    assert np.allclose(rigid.inertia.box_moments(0.3, (0.2, 0.1, 0.05)), [3.125e-4, 1.0625e-3, 1.25e-3])
    assert np.allclose(rigid.inertia.sphere_moments(1.0, 0.1), 0.004)
    assert np.allclose(rigid.inertia.cylinder_moments(2.0, 0.1, 0.4), [2 * 0.19 / 12, 2 * 0.19 / 12, 0.01])


@pytest.fixture(scope="module")
def rows():
    return nb14.drift_table()


def test_section3_drift_table(rows):
    """Forward Euler +32 % |L|, +73 % E; Baraff's explicit step |L| exact, E × 3.4;
    RK4 ~1e-7; backward Euler −19 %, −35 %; midpoint both to round-off; splitting |L| to
    round-off and E at worst 8e-5, coming back (3e-7 at the end)."""
    steps = len(rows["rk4"]["t"]) - 1
    roundoff = 16 * EPS * steps
    fe, be, ba = rows["forward_euler"], rows["backward_euler"], rows["baraff_euler"]
    assert (f"{fe['L_end']:+.1e}", f"{fe['E_end']:+.1e}") == ("+3.2e-01", "+7.3e-01")
    assert (f"{be['L_end']:+.1e}", f"{be['E_end']:+.1e}") == ("-1.9e-01", "-3.5e-01")
    assert abs(ba["L_end"]) < roundoff and f"{1 + ba['E_end']:.1f}" == "3.4"
    assert f"{rows['rk4']['E_end']:+.1e}" == "-1.0e-07" and rows["rk4"]["L_max"] < 1e-7
    mid, spl = rows["implicit_midpoint"], rows["splitting"]
    assert mid["L_max"] < roundoff and mid["E_max"] < roundoff
    assert spl["L_max"] < roundoff
    assert f"{spl['E_max']:.1e}" == "8.2e-05" and abs(spl["E_end"]) < 1e-6
    for row in (fe, ba):                                     # explicit methods gain energy
        assert np.all(np.diff(row["dE"]) > 0)
    assert np.all(np.diff(be["dE"]) < 0)


def test_section3_midpoint_keeps_L_world(rows):
    """'L_world changes by round-off': the Cayley rotation of L_body and the renormalised
    quaternion step with Ω_m cancel; a few units of round-off per step."""
    mid = rows["implicit_midpoint"]
    L = mid["omega"] * nb14.spin_moments()
    world = quat.rotate(mid["q"], L)
    steps = len(mid["t"]) - 1
    assert np.abs(world - world[0]).max() / np.linalg.norm(L[0]) < min(16 * EPS * steps, 1e-12)


def test_section4_flip_period(rows):
    moments = nb14.spin_moments()
    p = exact.parameters(moments, nb14.SPIN["omega0"])
    assert (f"{p['m']:.5f}", f"{p['lam']:.4f}", f"{p['period']:.4f}") == ("0.99985", "6.0004", "3.8656")
    assert f"{p['period'] / 2:.3f}" == "1.933"
    assert f"{p['D']:.3e}" == "-2.344e-09" and p["functions"] == ("dn", "sn", "cn")
    assert [f"{a:.4f}" for a in p["amplitudes"]] == ["8.2468", "10.0000", "8.2462"]
    assert f"{p['tau0']:.4f}" == "5.7989"
    A1 = p["amplitudes"][0]                                  # Ω_x swings between 0.1 and 8.25 rad/s
    assert A1 * np.sqrt(1 - p["m"]) == pytest.approx(0.1, rel=1e-9) and f"{A1:.2f}" == "8.25"
    assert np.all(rows["implicit_midpoint"]["omega"][:, 0] > 0)              # dn: no sign change
    mid = rows["implicit_midpoint"]
    measured = exact.measured_period(mid["t"], mid["omega"], 1)
    assert f"{measured:.4f}" == "3.8651" and f"{measured / p['period'] - 1:+.1e}" == "-1.4e-04"
    # the run follows the exact curves: the error of a second-order method at ω dt = 0.1
    assert np.abs(mid["omega"] - exact.omega(moments, nb14.SPIN["omega0"], mid["t"])).max() < 0.2
    assert p["order"][1] == 1                                # y is the intermediate axis


def test_section4_period_orders():
    study = nb14.period_errors()
    assert study["implicit_midpoint_order"] == pytest.approx(2.0, abs=0.1)
    assert study["splitting_order"] == pytest.approx(2.0, abs=0.15)
    assert study["rk4_order"] == pytest.approx(4.0, abs=0.2)
    n100 = list(study["steps"]).index(100)
    assert abs(study["implicit_midpoint"][n100]) < 0.002 * 1.15          # "within 0.2 %"
    assert abs(study["splitting"][n100]) < 0.011 * 1.05                  # "1.1 %"
    assert abs(study["rk4"][n100]) < 3e-5                                # "3e-5"
    quoted = ["-3.8e-02", "-9.0e-03", "-2.2e-03", "-5.4e-04"]
    assert [f"{e:+.1e}" for e in study["implicit_midpoint"]] == quoted
    mid, spl = study["implicit_midpoint"], study["splitting"]
    assert mid[0] / mid[1] == pytest.approx(4.0, rel=0.1)                   # on its line from N = 25
    assert f"{spl[0]:.0%}" == "-69%"
    # N = 25: the box turns by |Ω|Δt = 1.5 rad (89°) per step, |Ω| = 10 rad/s at the start
    turn = np.linalg.norm(nb14.SPIN["omega0"]) * study["T"] / 25
    assert f"{turn:.1f}" == "1.5" and f"{np.degrees(turn):.0f}" == "89"
    energy = study["splitting_energy"]
    assert [f"{e:.1e}" for e in energy] == ["1.4e-01", "5.0e-03", "1.2e-03", "3.1e-04"]
    assert np.allclose(energy[1:-1] / energy[2:], 4.0, rtol=0.05)          # 4 per halving from 50 on
    assert f"{energy[0] / energy[1]:.0f}" == "27" and f"{energy[0]:.0%}" == "14%"


def test_section5_rolling_numbers():
    r = nb14.rolling_sphere()
    assert f"{r['t'][r['k_roll']]:.3f}" == "0.195" and f"{r['t_roll']:.4f}" == "0.1942"
    assert f"{r['v'][-1]:.6f}" == "1.428571"
    # "|v − 5/7 v0| = round-off": below 1e-12 relative, and below the round-off bound of
    # a few eps per step
    miss = abs(r["v"][-1] / r["v_roll"] - 1)
    assert miss < min(1e-12, 16 * EPS * (len(r["v"]) - 1))


def test_section5_the_notebooks_drop():
    """The notebook's box ends at rest on its largest face (centre at 5 cm): the energy it
    lost is its initial energy less m g times that height."""
    run = nb14.bouncing_box(every=1)
    rest, kinetic, gap = nb14.at_rest_on_a_face(run)
    assert rest and kinetic < 1e-6
    R = quat.to_matrix(run.q[-1, 0])
    assert int(np.argmax(np.abs(R[1]))) == 2                           # the 10 cm side stands up
    e = nb14.energies(run)["total"]
    lost = e[0] - e[-1]
    assert lost == pytest.approx(e[0] - 9.81 * (0.05 + gap), rel=1e-9)
    assert f"{lost:.2f}" == "4.47" and f"{e[0]:.2f}" == "4.96"
    # in flight symplectic Euler loses ½ m g² Δt² a step (the spin's energy is kept exactly):
    # "0.000835 J"; one step of the contacts raises it, by 1e-5 of m g h, less than a tenth
    # of that loss
    flight_loss = 0.5 * 9.81**2 * nb14.DROP["dt"] ** 2
    assert np.allclose(np.diff(e[:20]), -flight_loss, rtol=1e-9) and f"{flight_loss:.6f}" == "0.000835"
    rise = np.diff(e)
    assert np.sum(rise > 0) == 1 and rise.max() < 0.1 * flight_loss
    assert f"{rise.max() / (9.81 * nb14.DROP['height']):.0e}" == "1e-05"


def test_section6_magnet_numbers():
    R = nb14.MAGNET["radius"]
    m = magnets.sphere_moment(R, nb14.MAGNET["remanence"])
    mass = nb14.MAGNET["density"] * 4 / 3 * np.pi * R**3
    assert f"{m:.4f}" == "0.0677" and f"{mass * 1e3:.3f}" == "0.491"
    force = magnets.coaxial_force(m, m, 2 * R)
    assert f"{force:.4f}" == "4.4010" and f"{force / (mass * 9.81):.0f}" == "914"
    assert 850 < force / (mass * 9.81) < 950                             # "about 900 times"


def test_section6_the_notebooks_pair():
    """Seed 14: in contact after about 11 ms (frames 0.25 ms apart), rocking with a period of
    3.7 ms (73 steps of 50 μs), aligned within a degree at 60 ms. Other seeds: the ensemble
    tests of test_rigid_magnets.py."""
    run = nb14.magnet_scene(every=5)
    align = nb14.alignment(run)
    touch = run.t[np.argmax(align["distance"] < 1.001)]
    assert 0.010 <= touch <= 0.012
    assert np.all(align["angles"][-1] < 1.0)
    rocking = nb14.rocking_period(run)
    assert abs(rocking - 3.7e-3) < 0.05e-3 and 70 <= rocking / nb14.MAGNET["dt"] <= 75


def test_showcase_is_an_animation():
    """The showcase's drawing: a 16:9 ``Animation`` that the kernel-free player renders
    (a short run here; the full clip is 201 frames, 6.7 s at 30 fps)."""
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.animation import Animation

    from course_lib.lessons import nb14_drawings
    from course_lib.plotting import animation_html
    run = nb14.magnet_scene(n=6, seed=3, t_end=0.002, every=10, spread=0.024)
    anim = nb14_drawings.animate_magnets(run, nb14.MAGNET["radius"], figsize=(8.0, 4.5), fps=30.0)
    assert isinstance(anim, Animation) and anim._fig.get_size_inches().tolist() == [8.0, 4.5]
    player = animation_html(anim)
    assert len(player.labels) == len(run.t) == 5
    assert round(0.1 / nb14.MAGNET["dt"]) // 10 + 1 == 201 and 201 / 30 <= 10.0

"""course_lib.cloth: the sheet, its energies, the time loop and the measured step limit."""

import numpy as np
import pytest

import course_lib as cl
from course_lib import cloth as C
from course_lib import collisions, springs
from course_lib.baraff_witkin import BaraffWitkin
from course_lib.systems import NewtonianSystem, stack_state, sum_forces


def test_sheet_layout():
    c = C.sheet(n=5, size=0.4, total_mass=0.05, k_struct=100.0, height=0.3)
    assert c.n == 25 and c.shape == (5, 5) and c.pinned.tolist() == [0, 4]
    assert c.mass.sum() == pytest.approx(0.05, rel=1e-14)
    assert np.allclose(c.x0[:, 1], 0.3) and np.allclose(c.x0[:, [0, 2]].mean(axis=0), 0.0)
    counts = {k: c.network.select(k).n_springs for k in ("struct", "shear", "bend")}
    assert counts == {"struct": 40, "shear": 32, "bend": 30}
    assert c.network.select("shear").k[0] == pytest.approx(10.0)
    assert c.network.select("bend").k[0] == pytest.approx(2.0)
    assert np.allclose(c.network.lengths(c.x0), c.network.rest)          # at rest
    assert C.sheet(n=3, pinned="none").pinned.size == 0
    with pytest.raises(ValueError, match="pinned"):
        C.sheet(pinned="edge")


def test_energies():
    c = C.sheet(n=4)
    e = C.energies(c, c.x0, np.zeros_like(c.x0))
    assert e["kinetic"] == 0.0 and e["elastic"] == pytest.approx(0.0, abs=1e-25)
    lifted = c.x0 + np.array([0.0, 0.5, 0.0])
    v = np.full_like(c.x0, 2.0)
    e2 = C.energies(c, lifted, v)
    assert e2["gravity"] - e["gravity"] == pytest.approx(0.1 * 9.81 * 0.5, rel=1e-12)
    assert e2["kinetic"] == pytest.approx(0.5 * 0.1 * 12.0, rel=1e-12)
    assert e2["total"] == pytest.approx(e2["kinetic"] + e2["elastic"] + e2["gravity"])


def test_explicit_loop_is_symplectic_euler_and_keeps_pins():
    c = C.sheet(n=5, c=0.02)
    run = C.simulate(c, "symplectic_euler", frames=2, substeps=10)
    system = NewtonianSystem(sum_forces(c.network.force,
                                        cl.forces.constant_gravity(c.mass)), c.mass, c.pinned)
    traj = cl.integrate(system, stack_state(c.x0, np.zeros_like(c.x0)), (0.0, 2 / 30), run.dt,
                        method="symplectic_euler")
    assert np.allclose(run.x[-1], traj.y[-1][0], rtol=0, atol=1e-13)
    assert np.array_equal(run.x[:, c.pinned], np.broadcast_to(c.x0[c.pinned], (3, 2, 3)))
    assert run.t.tolist() == pytest.approx([0.0, 1 / 30, 2 / 30])


def test_implicit_loop_is_baraff_witkin():
    c = C.sheet(n=5)
    run = C.simulate(c, "baraff_witkin", frames=3, rtol=1e-10)
    xs, _, infos = BaraffWitkin(c.network, c.mass, pinned=c.pinned, gravity=cl.forces.G_EARTH,
                                rtol=1e-10).run(c.x0, np.zeros_like(c.x0), 1 / 30, 3)
    assert np.allclose(run.x, xs, rtol=0, atol=1e-9)
    assert run.iterations.tolist() == [info.iterations for info in infos]


def test_collisions_and_blow_up():
    c = C.sheet(n=6, size=0.5, height=0.1, pinned="none")
    floor = collisions.plane((0.0, 1.0, 0.0), 0.0, restitution=0.0)
    run = C.simulate(c, "baraff_witkin", frames=10, substeps=2, post_step=floor, rtol=1e-3)
    assert run.stable and run.x[1:, :, 1].min() >= -1e-15
    bad = C.simulate(C.sheet(n=6), "symplectic_euler", frames=5, substeps=1)
    assert not bad.stable and bad.message.startswith("unstable at frame")
    assert np.isnan(bad.x[-1]).all()
    with pytest.raises(ValueError, match="unknown method"):
        C.simulate(c, "rk4")
    with pytest.raises(ValueError, match="substeps"):
        C.simulate(c, substeps=0)


def test_a_state_that_turns_nan_stops_the_run_before_the_next_implicit_step(monkeypatch):
    import scipy.sparse.linalg as spla

    c = C.sheet(n=5)
    calls = []
    real = spla.cg
    monkeypatch.setattr(spla, "cg", lambda *a, **k: calls.append(1) or real(*a, **k))

    def poison(t, y):
        return y * np.nan if t > 1.2 / 30 else y     # from the first step of frame 2

    for method in C.METHODS[1:]:
        calls.clear()
        run = C.simulate(c, method, frames=6, substeps=2, post_step=poison)
        assert not run.stable and run.message.startswith("unstable at frame 2")
        assert np.isnan(run.x[2:]).all() and np.isfinite(run.x[:2]).all()
        assert len(run.iterations) == 3                  # no step started from NaN
        assert len(calls) == (3 if method == "baraff_witkin" else 0)


@pytest.mark.parametrize("kwargs, name", [
    ({"x0": np.zeros((25, 2))}, "x0"), ({"v0": np.zeros((24, 3))}, "v0"),
    ({"x0": np.full((25, 3), np.nan)}, "x0"), ({"v0": np.full((25, 3), np.inf)}, "v0"),
    ({"gravity": [0.0, -9.81]}, "gravity"), ({"gravity": [0.0, np.nan, 0.0]}, "gravity"),
    ({"frames": 0}, "frames"), ({"fps": -30.0}, "fps"), ({"rtol": 0.0}, "rtol"),
    ({"blowup_bound": np.nan}, "blowup_bound"), ({"post_step": 3}, "post_step"),
    ({"iterations": 0, "method": "fast_mass_spring"}, "iterations"),
    ({"iterations": 3}, "iterations"), ({"strain_limit": -0.1}, "strain_limit"),
    ({"method": "xpbd", "options": {"substeps": 0}}, "substeps"),
    ({"options": {"memory": 2}}, "options"), ({"method": "verlet"}, "method"),
])
def test_simulate_rejects_bad_input_by_name(kwargs, name):
    c = C.sheet(n=5)
    with pytest.raises((ValueError, TypeError), match=name):
        C.simulate(c, **{"method": "symplectic_euler", "frames": 2, **kwargs})


@pytest.mark.parametrize("kwargs, name", [
    ({"n": 1}, "n"), ({"n": 4.0}, "n"), ({"size": 0.0}, "size"), ({"height": np.nan}, "height"),
    ({"total_mass": -1.0}, "total_mass"), ({"k_struct": 0.0}, "k_struct"),
])
def test_sheet_rejects_bad_input_by_name(kwargs, name):
    with pytest.raises((ValueError, TypeError), match=name):
        C.sheet(**kwargs)


def test_energies_reject_misshapen_states():
    c = C.sheet(n=4)
    with pytest.raises(ValueError, match="shape"):
        C.energies(c, c.x0[:5], c.x0[:5])
    with pytest.raises(ValueError, match="x"):
        C.energies(c, np.full_like(c.x0, np.nan), c.x0)


def test_measured_limit_is_two_over_omega_max():
    c = C.sheet(n=6, size=0.25, total_mass=0.02, k_struct=500.0)
    omega = springs.max_frequency(c.network, c.x0, c.mass, c.pinned)
    measured = C.explicit_dt_max(c)
    assert measured == pytest.approx(2 / omega, rel=2e-3)
    assert measured <= 2 / omega * (1 + 1e-9)                  # the stable end of the bracket


# --- the large-step methods in the frame loop -------------------------------------------

def test_methods_list_and_every_method_keeps_pins_and_respects_the_floor():
    assert C.METHODS == ("symplectic_euler", "baraff_witkin", "fast_mass_spring", "xpbd")
    c = C.sheet(n=6, size=0.5, height=0.05, damping_ratio=0.1)
    floor = collisions.plane((0.0, 1.0, 0.0), 0.0, restitution=0.0)
    for method in C.METHODS[1:]:
        run = C.simulate(c, method, frames=12, fps=60, post_step=floor)
        assert run.stable, (method, run.message)
        assert np.array_equal(run.x[:, c.pinned], np.broadcast_to(c.x0[c.pinned], (13, 2, 3)))
        assert run.x[1:, :, 1].min() >= -1e-15
        assert run.x[-1, :, 1].mean() < 0.04                   # it fell onto the floor


def test_fast_mass_spring_and_xpbd_in_the_loop_are_their_solvers():
    from course_lib.largestep import XPBD, FastMassSpring

    c = C.sheet(n=5, damping_ratio=0.05)
    g = cl.forces.G_EARTH
    run = C.simulate(c, "fast_mass_spring", frames=3, fps=60, iterations=7)
    solver = FastMassSpring(c.network, c.mass, pinned=c.pinned, gravity=g, iterations=7)
    x, v = c.x0.copy(), np.zeros_like(c.x0)
    for f in range(3):
        x, v = solver.step(x, v, 1 / 60, t=f / 60)
    assert np.array_equal(run.x[-1], x) and run.iterations.tolist() == [7, 7, 7]
    run = C.simulate(c, "xpbd", frames=2, fps=60)
    solver = XPBD(c.network, c.mass, pinned=c.pinned, gravity=g, substeps=C.XPBD_SUBSTEPS_PER_SECOND // 60)
    x, v = solver.step(*solver.step(c.x0, np.zeros_like(c.x0), 1 / 60), 1 / 60)
    assert np.array_equal(run.x[-1], x)
    assert run.iterations.tolist() == [C.XPBD_SUBSTEPS_PER_SECOND // 60] * 2


def test_strain_limit_bounds_every_method():
    c = C.sheet(n=8, k_struct=300.0)
    for method in C.METHODS:
        kw = {"substeps": 20} if method == "symplectic_euler" else {}
        if method == "xpbd":
            kw["options"] = {"substeps": 30}             # soft cloth: few small steps suffice
        free = C.simulate(c, method, frames=12, fps=60, **kw)
        limited = C.simulate(c, method, frames=12, fps=60, strain_limit=0.01, **kw)
        peak_free = c.network.strain(free.x[1:]).max()
        peak = c.network.strain(limited.x[1:]).max()
        # The limiter sweeps until no spring is strained beyond tau (1 + 1 %) (hundreds of
        # sweeps on some steps here): its guarantee holds at every frame, for every method,
        # where the free cloth stretches more than four times tau (5.1-5.5 % in these 0.2 s,
        # measured; 6-7 % by 0.33 s).
        assert peak_free > 0.04 and peak <= 0.01 * (1 + 0.01) + 1e-12, (method, peak_free, peak)


def test_damping_ratio_sets_c():
    c = C.sheet(n=4, total_mass=0.16, k_struct=100.0, damping_ratio=0.5)
    assert np.allclose(c.network.c, 0.5 * 2 * np.sqrt(100.0 * 0.01))
    with pytest.raises(ValueError, match="damping_ratio"):
        C.sheet(c=0.1, damping_ratio=0.1)
    with pytest.raises(ValueError, match="damping_ratio"):
        C.sheet(damping_ratio=-1.0)


def peak_struct_strain(c, run):
    return float(c.network.select("struct").strain(run.x[1:]).max())


@pytest.fixture(scope="module")
def fidelity_scenes():
    """The bench's scene (issue 19) at ×100 and ×1000, and the reference peak at ×100:
    converged symplectic Euler, 1 s, 32². Issue 19 (and make bench) run it at half its
    measured (damped) limit; here it runs at 0.9 times the limit, 0.56 times the cost: the
    peak there is 0.2444 % against 0.2451 % at half of it (measured), a first-order error of
    at most 0.002 pp, a hundred times less than the smallest margin below (0.2 pp, XPBD)."""
    scenes = {f: C.sheet(n=32, k_struct=300.0 * f, damping_ratio=0.1) for f in (100, 1000)}
    c = scenes[100]
    substeps = int(np.ceil(1 / (60 * 0.9 * C.explicit_dt_max(c))))
    reference = C.simulate(c, "symplectic_euler", frames=60, fps=60, substeps=substeps)
    assert reference.stable
    return scenes, peak_struct_strain(c, reference)


# XPBD's peak comes from the free edge whipping round at the end of the second: runs started
# 1e-12 m and 1e-9 m apart differ by 0.02 pp there. At ×1000 the room is 0.1 pp (0.40 %
# against 0.5 %), five times that spread: that case runs again under the second rounding.
# At ×100 the room is 0.2 pp (0.54 % against 0.745 %), ten times the spread, and the
# second rounding would need the 10 s reference too, so it runs once.
@pytest.mark.parametrize("method", ["fast_mass_spring", "xpbd"])
def test_defaults_meet_the_fidelity_target_x100(fidelity_scenes, method):
    """Issue 19: with one call per 1/60 s frame and the defaults, peak structural strain over
    1 s within 0.5 percentage points of converged symplectic Euler (see the fixture), 32²,
    stiffness ×100 (springs damped at 10 % of critical, the bench's scene)."""
    scenes, ref_100 = fidelity_scenes
    cf = scenes[100]
    peak = peak_struct_strain(cf, C.simulate(cf, method, frames=60, fps=60))
    # (Converged: at 0.9 and 0.45 times the limit the reference peaks at 0.2444 % and
    # 0.2450 %, against 0.2451 % at half of it: 0.001 pp apart, measured.)
    assert abs(peak - ref_100) <= 0.005


@pytest.mark.parametrize("method", ["fast_mass_spring",
                                    pytest.param("xpbd", marks=pytest.mark.roundoff)])
def test_defaults_meet_the_fidelity_target_x1000(method):
    """Issue 19 at stiffness ×1000: the same scene and target as the ×100 test."""
    cf = C.sheet(n=32, k_struct=300.0 * 1000, damping_ratio=0.1)
    peak = peak_struct_strain(cf, C.simulate(cf, method, frames=60, fps=60))
    # At ×1000 the reference costs 170,000 explicit steps (make bench runs it: 0.070 %;
    # 0.075 % at 0.9 times the limit). A stiffer cloth stretches less, so 0 <=
    # reference(×1000) <= reference(×100) < 0.25 % (asserted in the test below); a peak p
    # within 0.5 pp of every value in that interval meets the target whatever it is:
    # p <= 0.5 % and p >= 0.25 % - 0.5 % < 0, which a maximum of strains in a sheet
    # hanging under gravity (its top row pinned, its springs pulled) meets when p >= 0.
    assert 0.0 <= peak <= 0.005


def test_xpbd_with_few_small_steps_stretches_forty_times_more(fidelity_scenes):
    """Notebook 12: with 30 small steps per frame the sheet stretches more than 10 %, where
    the true motion stretches less than a quarter of a percent (not a round-off question:
    peaks 13.1 % at ×100 and 11.4 % at ×1000, measured, against 0.02 pp of spread)."""
    scenes, ref_100 = fidelity_scenes
    assert ref_100 < 0.0025
    for cf in scenes.values():
        few = C.simulate(cf, "xpbd", frames=60, fps=60, options={"substeps": 30})
        assert peak_struct_strain(cf, few) > 0.10


def test_self_contact_pushes_close_pairs_to_the_thickness_and_keeps_momentum():
    # Two particles 1 cm apart, closing at 2 m/s, masses 1 and 3: pushed apart to 4 cm in
    # inverse proportion to their masses; the closing velocity is removed, momentum kept.
    x = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [1.0, 1.0, 1.0]])
    v = np.array([[1.0, 0.5, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 0.3]])
    mass = np.array([1.0, 3.0, 2.0])
    out = collisions.self_contact(0.04, mass=mass, iterations=1)(0.0, np.stack((x, v)))
    assert np.linalg.norm(out[0, 1] - out[0, 0]) == pytest.approx(0.04, rel=1e-12)
    assert (x[0, 0] - out[0, 0, 0]) == pytest.approx(3 * (out[0, 1, 0] - x[1, 0]), rel=1e-12)
    assert out[1, 1, 0] - out[1, 0, 0] == pytest.approx(0.0, abs=1e-14)    # no longer closing
    assert np.allclose(mass @ out[1], mass @ v, rtol=0, atol=1e-14)
    assert np.array_equal(out[:, 2], np.stack((x, v))[:, 2])             # far away: untouched
    assert np.allclose(out[1, :, 1:], v[:, 1:])                           # sideways motion kept
    # separating pairs keep their velocities; only positions are corrected
    apart = collisions.self_contact(0.04)(0.0, np.stack((x, -v)))
    assert np.array_equal(apart[1], -v)
    with pytest.raises(ValueError, match="thickness"):
        collisions.self_contact(0.0)
    with pytest.raises(ValueError, match="y must"):
        collisions.self_contact(0.1)(0.0, x)

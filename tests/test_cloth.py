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


def test_measured_limit_is_two_over_omega_max():
    c = C.sheet(n=6, size=0.25, total_mass=0.02, k_struct=500.0)
    omega = springs.max_frequency(c.network, c.x0, c.mass, c.pinned)
    measured = C.explicit_dt_max(c)
    assert measured == pytest.approx(2 / omega, rel=2e-3)
    assert measured <= 2 / omega * (1 + 1e-9)                  # the stable end of the bracket

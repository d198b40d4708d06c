"""course_lib.rigid.magnets: the exact dipole force, torque and energy, with μ₀.

Central differences with step h = 1e-6 |r| have a truncation error of order (h/r)² and a
round-off error of order eps/(h/r) = 2e-10 (relative): they are asserted to 1e-8. Two
magnets snapping together are judged as an ensemble over seeds.
"""

import numpy as np
import pytest
from scipy.constants import mu_0

from course_lib.lessons import nb14_rigid_bodies as nb14
from course_lib.rigid import magnets
from course_lib.rigid import quaternion as quat

EPS = np.finfo(float).eps
FD_TOL = 1e-8


def _pairs(n=6, seed=7):
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, 3)) * 0.05, rng.normal(size=(n, 3)) * 0.05, rng.normal(size=(n, 3)) * 0.02


def test_mu0_and_the_coaxial_force():
    assert magnets.MU0 == mu_0 == pytest.approx(4e-7 * np.pi, rel=1e-9)
    m1, m2, r = 0.07, 0.05, 0.013
    F = magnets.force([0, 0, m1], [0, 0, m2], [0, 0, r])
    assert np.allclose(F, [0, 0, -3 * mu_0 * m1 * m2 / (2 * np.pi * r**4)], rtol=4 * EPS, atol=0)
    assert magnets.coaxial_force(m1, m2, r) == pytest.approx(-F[2], rel=4 * EPS)
    # anti-parallel on one axis: the same force, repulsive
    assert np.allclose(magnets.force([0, 0, m1], [0, 0, -m2], [0, 0, r]), -F, rtol=4 * EPS)
    # side by side, parallel: repel with 3 μ0 m1 m2 / (4π r⁴), no torque
    side = magnets.force([0, 0, m1], [0, 0, m2], [r, 0, 0])
    assert np.allclose(side, [3 * mu_0 * m1 * m2 / (4 * np.pi * r**4), 0, 0], rtol=4 * EPS, atol=0)
    assert np.allclose(magnets.torque([0, 0, m1], [0, 0, m2], [r, 0, 0]), 0.0, atol=1e-30)


def test_perpendicular_torque():
    """m2 across the field of a coaxial m1: τ = m2 × B, |B| = μ0 2 m1 / (4π r³)."""
    m1, m2, r = 0.07, 0.05, 0.013
    tau = magnets.torque([0, 0, m1], [m2, 0, 0], [0, 0, r])
    # x̂ × ẑ = −ŷ: the torque turns m2 towards the field
    assert np.allclose(tau, [0, -mu_0 * 2 * m1 * m2 / (4 * np.pi * r**3), 0], rtol=4 * EPS, atol=0)


def test_force_is_minus_the_gradient_of_the_energy():
    m1, m2, r = _pairs()
    F = magnets.force(m1, m2, r)
    for k in range(len(r)):
        h = 1e-6 * np.linalg.norm(r[k])
        U = [[magnets.energy(m1[k], m2[k], r[k] + s * h * e) for s in (1, -1)] for e in np.eye(3)]
        grad = np.array([(up - down) / (2 * h) for up, down in U])
        assert np.linalg.norm(F[k] + grad) < FD_TOL * np.linalg.norm(F[k])


def test_torque_is_minus_the_derivative_of_the_energy_under_rotation():
    """τ·a = −dU/dθ when m2 turns by θ about the unit axis a."""
    m1, m2, r = _pairs(seed=8)
    tau = magnets.torque(m1, m2, r)
    rng = np.random.default_rng(9)
    for k in range(len(r)):
        a = rng.normal(size=3)
        a /= np.linalg.norm(a)
        h = 1e-6
        turn = [quat.rotate(quat.from_axis_angle(a, s * h), m2[k]) for s in (1, -1)]
        dU = (magnets.energy(m1[k], turn[0], r[k]) - magnets.energy(m1[k], turn[1], r[k])) / (2 * h)
        assert abs(tau[k] @ a + dU) < FD_TOL * np.linalg.norm(tau[k])


def test_third_law_and_angular_momentum_for_many_dipoles():
    rng = np.random.default_rng(10)
    x, m = rng.normal(size=(7, 3)) * 0.03, rng.normal(size=(7, 3)) * 0.05
    F, tau, U = magnets.interactions(x, m)
    scale = np.abs(F).max()
    assert np.linalg.norm(F.sum(axis=0)) < 64 * EPS * scale * len(x)             # Newton's third law
    balance = np.sum(np.cross(x, F) + tau, axis=0)                                 # Σ x × F + τ = 0
    assert np.linalg.norm(balance) < 64 * EPS * len(x) * (np.abs(tau).max() + scale * np.abs(x).max())
    i, j = np.triu_indices(7, 1)
    assert U == pytest.approx(np.sum(magnets.energy(m[i], m[j], x[j] - x[i])), rel=1e-13)
    # one pair, both orders
    f12 = magnets.force(m[0], m[1], x[1] - x[0])
    assert np.allclose(magnets.force(m[1], m[0], x[0] - x[1]), -f12, rtol=1e-13, atol=0)
    F1, tau1, _ = magnets.interactions(x[:1], m[:1])
    assert not F1.any() and not tau1.any()


def test_sphere_moment_and_bad_input():
    assert magnets.sphere_moment(0.0025, 1.3) == pytest.approx(1.3 * 4 / 3 * np.pi * 0.0025**3 / mu_0)
    with pytest.raises(ValueError, match="one point"):
        magnets.force([0, 0, 1.0], [0, 0, 1.0], [0, 0, 0])


@pytest.fixture(scope="module")
def pairs():
    return [nb14.magnet_scene(seed=seed, every=5) for seed in (14, 1, 2, 3)]


def test_two_magnets_snap_and_align(pairs):
    """4 seeds of 4 (the notebook's seed 14 among them): after 60 ms the two balls touch
    and both dipoles lie within 5° of the line of centres, pointing the same way."""
    for run in pairs:
        align = nb14.alignment(run)
        assert abs(align["distance"][-1] - 1.0) < 1e-3
        assert np.all(align["angles"][-1] < 5.0)
        assert align["parallel"][-1] > np.cos(np.radians(10.0))
        assert np.linalg.norm(run.P[-1].sum(axis=0)) < 1e-12 * np.abs(run.P).max()   # no net push


def test_the_pair_rocks_slower_than_one_ball_in_a_fixed_field(pairs):
    """4 seeds of 4: in contact the pair rocks with a period of 3.7 ± 0.3 ms (70 ± 6 steps of
    50 μs), longer than the 2π√(I/(mB)) = 2.6 ms of one ball in the field B = μ₀m/(2π(2R)³)
    = 0.108 T of a neighbour held fixed; the spread over seeds is below 10 %."""
    R = nb14.MAGNET["radius"]
    m = magnets.sphere_moment(R, nb14.MAGNET["remanence"])
    B = magnets.MU0 * m / (2 * np.pi * (2 * R) ** 3)
    assert f"{B:.3f}" == "0.108"
    assert magnets.field([0, 0, m], [0, 0, 2 * R])[2] == pytest.approx(B, rel=1e-12)   # on the axis
    single = nb14.single_ball_rocking()
    assert f"{single * 1e3:.1f}" == "2.6"
    periods = np.array([nb14.rocking_period(run) for run in pairs])
    assert np.all(np.abs(periods - 3.7e-3) < 0.3e-3), periods
    assert periods.std() < 0.1 * periods.mean() and np.all(periods > single)

"""course_lib.sph, the core of notebook 13: kernels, pairs, density, forces, walls, solvers.

Against references written here: kernels by quadrature and by finite differences, the
density and forces by a plain loop over all pairs, the sparse pressure operator against
the pair sums, IISPH's diagonal against the operator probed with unit pressures.
"""

import numpy as np
import pytest
from scipy.integrate import quad

from course_lib import neighbors, sph
from course_lib.sph import boundary, density, forces, iisph, kernels, scenes, wcsph
from course_lib.sph.operators import PressureOperator

SHELL = {1: lambda r: 2.0, 2: lambda r: 2 * np.pi * r, 3: lambda r: 4 * np.pi * r * r}


@pytest.mark.parametrize("name", sorted(kernels.KERNELS))
@pytest.mark.parametrize("dim", [1, 2, 3])
def test_kernels_are_normalised(name, dim):
    """∫ W dV = 1 by adaptive quadrature (relative tolerance 1e-13), for two h."""
    for h in (0.37, 2.0):
        value, err = quad(lambda r, h=h: kernels.KERNELS[name](r, h, dim) * SHELL[dim](r), 0.0,
                          kernels.SUPPORT[name] * h, points=[h] if name == "cubic" else None,
                          epsabs=0.0, epsrel=1e-13, limit=200)
        assert abs(value - 1.0) <= 1e-13 + err


@pytest.mark.parametrize("name", sorted(kernels.KERNELS))
def test_gradients_are_the_derivatives(name):
    """dW/dr against central differences (step 1e-6 h: error ~ h² W''' + ε W / step)."""
    h = 0.5
    r = np.linspace(0.01, 1.05 * kernels.SUPPORT[name] * h, 57)
    r = r[np.abs(r - h) > 1e-3]                     # the cubic spline's knot
    step = 1e-6 * h
    for dim in (2, 3):
        W = kernels.KERNELS[name]
        fd = (W(r + step, h, dim) - W(r - step, h, dim)) / (2 * step)
        scale = W(0.0, h, dim) / h
        np.testing.assert_allclose(kernels.GRADIENTS[name](r, h, dim), fd, atol=1e-6 * scale)


def test_kernel_values_shapes_and_support():
    r = np.array([[0.0, 0.5], [1.0, 3.0]])
    for name, W in kernels.KERNELS.items():
        w = W(r, 1.0, 2)
        assert w.shape == (2, 2) and np.all(w >= 0)
        assert W(kernels.SUPPORT[name] * 1.0 + 1e-12, 1.0, 3) == 0.0
    assert kernels.poly6(0.0, 1.0, 2) == pytest.approx(4 / np.pi)
    assert kernels.spiky(0.0, 1.0, 2) == pytest.approx(10 / np.pi)
    assert kernels.cubic(0.0, 1.0, 2) == pytest.approx(10 / (7 * np.pi))
    assert kernels.spiky_dr(0.0, 1.0, 2) == pytest.approx(-30 / np.pi)   # spiky still pushes at r = 0
    assert kernels.poly6_dr(0.0, 1.0, 2) == 0.0


@pytest.mark.parametrize("bad,match", [({"dim": 4}, "dim"), ({"h": 0.0}, "h must"),
                                        ({"h": np.nan}, "h must")])
def test_kernel_bad_input(bad, match):
    args = {"r": 0.5, "h": 1.0, "dim": 2, **bad}
    with pytest.raises(ValueError, match=match):
        kernels.cubic(**args)
    with pytest.raises(ValueError, match="valid choices are: cubic, poly6, spiky"):
        kernels.gradient("gauss", np.zeros((1, 2)), np.zeros(1), 1.0)


def blob(n=150, seed=7, dim=2):
    rng = np.random.default_rng(seed)
    return rng.uniform(0.0, 0.2, (n, dim)), rng.uniform(0.5, 1.5, n)


def test_pairs_and_density_against_all_pairs():
    x, m = blob()
    h = 0.02
    nb = density.neighbourhood(x, h)
    ref = neighbors.all_pairs(x, 2 * h)
    assert nb.n_pairs == len(ref)
    assert set(zip(nb.i.tolist(), nb.j.tolist(), strict=True)) == set(
        zip(ref.i.tolist(), ref.j.tolist(), strict=True))
    r = np.linalg.norm(x[:, None] - x[None], axis=-1)
    np.testing.assert_allclose(density.summation_density(nb, m), kernels.cubic(r, h) @ m,
                               rtol=1e-13)


def test_scatter_adds_both_ends():
    i, j = np.array([0, 0, 2]), np.array([1, 2, 1])
    f = np.array([[1.0, 0.0], [2.0, 1.0], [4.0, -1.0]])
    np.testing.assert_array_equal(density.scatter(i, j, f, 3),
                                  [[3.0, 1.0], [-5.0, 1.0], [2.0, -2.0]])
    np.testing.assert_array_equal(density.scatter(i, j, f[:, 0], 3, sign=1.0), [3.0, 5.0, 6.0])


def pair_sum_pressure(x, m, rho, p, h):
    """-Σ_j m_j (p_i/ρ_i² + p_j/ρ_j²) ∇_i W_ij, by a dense all-pairs sum."""
    d = x[:, None] - x[None]
    r = np.linalg.norm(d, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        grad = np.where(r[..., None] > 0, d * (kernels.cubic_dr(r, h) / r)[..., None], 0.0)
    q = p / rho**2
    return -np.einsum("ij,ijk->ik", m[None, :] * (q[:, None] + q[None, :]), grad)


def test_pressure_force_against_all_pairs_and_third_law():
    x, m = blob()
    h = 0.02
    nb = density.neighbourhood(x, h)
    rho = density.summation_density(nb, m)
    p = forces.tait_pressure(rho, rho.mean() * 0.98, 20.0)
    a = forces.pressure_acceleration(nb, m, rho, p)
    ref = pair_sum_pressure(x, m, rho, p, h)
    np.testing.assert_allclose(a, ref, atol=1e-11 * np.abs(ref).max())
    total = np.abs((m[:, None] * a).sum(axis=0)).max()
    assert total <= 64 * np.finfo(float).eps * np.sum(m[:, None] * np.abs(a))


@pytest.mark.roundoff
def test_momentum_is_conserved_to_roundoff_over_a_run():
    """A squeezed blob expanding for 60 WCSPH steps (no walls, no gravity): the total momentum
    moves by no more than Σ_steps dt Σ m|a| · 64 ε, while the naive force moves it ~1e10 times more."""
    from course_lib.lessons import nb13_sph_liquids as nb13

    out = nb13.momentum_study(side=12, steps=60)
    P, _, bound = out["symmetric"]
    assert P.max() <= bound
    P_naive, _, bound_naive = out["naive"]
    assert P_naive.max() > 1e6 * bound_naive


def test_viscosity_is_symmetric_and_dissipates():
    x, m = blob()
    rng = np.random.default_rng(3)
    v = rng.normal(size=x.shape)
    h = 0.02
    nb = density.neighbourhood(x, h)
    rho = density.summation_density(nb, m)
    a = forces.viscosity_acceleration(nb, m, rho, v, 1e-3)
    assert np.abs((m[:, None] * a).sum(axis=0)).max() <= 64 * np.finfo(float).eps * np.sum(
        m[:, None] * np.abs(a))
    assert np.sum(m[:, None] * a * v) < 0                        # kinetic energy decreases


def test_tait_pressure():
    assert forces.tait_pressure(1000.0, 1000.0, 30.0) == 0.0
    assert forces.tait_pressure(990.0, 1000.0, 30.0) == 0.0       # no tension at a surface
    B = 1000.0 * 30.0**2 / 7
    assert forces.tait_pressure(1010.0, 1000.0, 30.0) == pytest.approx(B * (1.01**7 - 1))


@pytest.fixture(scope="module")
def dam_state():
    sim = scenes.dam_break_simulation(450)
    sim.run(0.12)
    nb = density.neighbourhood(sim.x, sim.params.h, sim.params.kernel, sim.wall)
    rho = density.summation_density(nb, sim.params.mass, sim.wall.psi)
    return sim, nb, rho


def test_pressure_operator_matches_the_pair_sums(dam_state):
    sim, nb, rho = dam_state
    rng = np.random.default_rng(5)
    p = rng.uniform(0.0, 2e4, sim.n)
    op = PressureOperator(nb, sim.params.mass, rho, sim.wall.psi)
    p_wall = forces.wall_pressure(nb, p, rho, sim.params.gravity, sim.wall.n)
    ref = forces.pressure_acceleration(nb, sim.params.mass, rho, p, sim.wall.psi, p_wall)
    np.testing.assert_allclose(op.accel(p), ref, atol=1e-13 * np.abs(ref).max())
    u = rng.normal(size=sim.x.shape)
    s = np.einsum("pk,pk->p", u[nb.i] - u[nb.j], nb.gw)
    div = density.scatter(nb.i, nb.j, sim.params.mass * s, nb.n, sim.params.mass * s) \
        + density.wall_sum(nb, sim.wall.psi[nb.bk] * np.einsum("pk,pk->p", u[nb.bi], nb.bgw))
    np.testing.assert_allclose(op.divergence(u), div, atol=1e-13 * np.abs(div).max())
    mirrored = PressureOperator(nb, sim.params.mass, rho, sim.wall.psi, wall_pressure="mirrored")
    np.testing.assert_allclose(mirrored.accel(p), forces.pressure_acceleration(
        nb, sim.params.mass, rho, p, sim.wall.psi), atol=1e-13 * np.abs(ref).max())


def test_iisph_diagonal_is_the_operators_own_coefficient(dam_state):
    """a_ii equals (A e_i)_i exactly for particles away from the walls, and within a
    fraction of it next to them (the wall pressures' effect on the neighbours is left out)."""
    sim, nb, rho = dam_state
    m, dt = sim.params.mass, 2e-3
    op = PressureOperator(nb, m, rho, sim.wall.psi)
    g2 = np.einsum("pk,pk->p", nb.gw, nb.gw)
    diag = op.diagonal(dt, m * density.scatter(nb.i, nb.j, m * g2, nb.n, m * g2))
    A = lambda p: dt * dt * op.divergence(op.accel(p))                        # noqa: E731
    offset = A(np.zeros(sim.n))
    near_wall = np.isin(np.arange(sim.n), nb.bi)
    for k in np.linspace(0, sim.n - 1, 25).astype(int):
        e = np.zeros(sim.n)
        e[k] = 1.0
        probe = A(e)[k] - offset[k]
        assert diag[k] < 0
        if near_wall[k]:
            assert probe == pytest.approx(diag[k], rel=0.5)
        else:
            assert probe == pytest.approx(diag[k], rel=1e-9)


def test_walls_keep_the_density_at_rest():
    x = scenes.lattice(0.5, 0.3, 0.025)
    params = sph.Params(spacing=0.025)
    wall = boundary.box(0.5, 0.5, 0.025, params.rho0, params.h)
    nb = density.neighbourhood(x, params.h, params.kernel, wall)
    rho = density.summation_density(nb, params.mass, wall.psi)
    bottom_and_sides = x[:, 1] < 0.3 - params.support          # below the free surface's reach
    np.testing.assert_allclose(rho[bottom_and_sides], params.rho0, rtol=1e-12)
    assert boundary.layers_needed(0.025, params.h) == 2
    assert boundary.lattice_volume(1.0, 1.2) == pytest.approx(1 / 0.9997573067322311, rel=1e-12)


def test_akinci_weights_of_a_line():
    """One straight layer: ψ = ρ₀ / Σ_l W(|k - l|), the same for every inner particle."""
    xs = np.arange(-20, 21) * 0.1
    psi = boundary.akinci_psi(np.stack([xs, np.zeros_like(xs)], axis=1), 1000.0, 0.12)
    line = kernels.cubic(np.abs(np.arange(-3, 4)) * 0.1, 0.12).sum()
    assert psi[20] == pytest.approx(1000.0 / line, rel=1e-13)
    assert psi[0] > psi[20]                                      # the ends see fewer neighbours


@pytest.mark.parametrize("bad,match", [
    ({"spacing": 0.0}, "spacing"), ({"kernel": "gauss"}, "valid choices"),
    ({"omega": 1.5}, "omega"), ({"viscosity": -1.0}, "viscosity"),
    ({"wall_pressure": "zero"}, "valid choices are: extrapolated, mirrored"),
    ({"max_iterations": 0}, "max_iterations"), ({"gravity": (0.0, np.inf)}, "gravity"),
    ({"cfl": np.nan}, "cfl")])
def test_params_bad_input(bad, match):
    with pytest.raises(ValueError, match=match):
        sph.Params(**{"spacing": 0.02, **bad})


def test_simulation_bad_input():
    params = sph.Params(spacing=0.02, sound_speed=10.0)
    x = scenes.lattice(0.1, 0.1, 0.02)
    with pytest.raises(ValueError, match="valid choices are: iisph, wcsph"):
        sph.Simulation(x, params, method="sph")
    with pytest.raises(ValueError, match=r"shape \(N, 2\)"):
        sph.Simulation(x[:, :1], params)
    with pytest.raises(ValueError, match="finite"):
        sph.Simulation(np.full((3, 2), np.nan), params)
    sim = sph.Simulation(x, params, method="wcsph")
    with pytest.raises(ValueError, match="dt must be a positive"):
        sim.step(dt=-1.0)
    with pytest.raises(ValueError, match="t_end"):
        sim.run(0.0)
    with pytest.raises(ValueError, match="WCSPH needs"):
        wcsph.cfl_step(sph.Params(spacing=0.02), 1.0, 1.0)
    with pytest.raises(ValueError, match="unbounded"):
        iisph.cfl_step(sph.Params(spacing=0.02), 0.0, 0.0)
    with pytest.raises(ValueError, match="n_particles"):
        scenes.dam_break(n_particles=3)


def test_a_blow_up_stops_and_says_so():
    """WCSPH at five times its Courant number: the run stops at the speed limit, no warnings."""
    sim = scenes.dam_break_simulation(200, "wcsph", cfl=2.0 * 2.5)
    sim.run(0.2)
    assert not sim.stable and "past the speed limit" in sim.message
    steps = sim.steps
    assert sim.step() == {} and sim.steps == steps


def test_cfl_steps():
    params = scenes.liquid(0.05, 2.0)
    c = params.sound_speed
    assert c == pytest.approx(10 * np.sqrt(2 * 9.81 * 2.0))
    assert wcsph.cfl_step(params, 5.0, 1.0) == pytest.approx(0.4 * params.h / (c + 5.0))
    assert iisph.cfl_step(params, 5.0, 9.81) == pytest.approx(0.4 * 0.05 / 5.0)
    assert iisph.cfl_step(params, 0.0, 9.81) == pytest.approx(0.4 * 0.05 / np.sqrt(9.81 * 2.0))
    ratio = iisph.cfl_step(params, 6.0, 9.81) / wcsph.cfl_step(params, 6.0, 9.81)
    assert ratio == pytest.approx((c + 6.0) / (6.0 * 2.4 / 2.0))           # Δx/v against h/(c+v)


def test_mirrored_wall_pressure_lets_water_slide_down_the_walls():
    """Notebook 13, Section 4: with mirrored wall pressures a column at rest circulates,
    fastest along the side walls; extrapolated pressures (Adami et al. 2012) keep it still."""
    speeds = {}
    for choice in ("extrapolated", "mirrored"):
        sim = scenes.water_column(wall_pressure=choice)
        sim.run(0.6)
        v = np.linalg.norm(sim.v, axis=1)
        side = (sim.x[:, 0] < 0.04) | (sim.x[:, 0] > 0.46)
        speeds[choice] = (v.mean(), v[side].mean(), v[~side].mean())
    assert speeds["mirrored"][0] > 5 * speeds["extrapolated"][0]
    assert speeds["mirrored"][1] > 2 * speeds["mirrored"][2]       # along the walls
    assert speeds["extrapolated"][0] < 0.01                          # m/s: at rest, to noise

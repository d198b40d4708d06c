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
    diag = op.diagonal(dt)
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
    ({"wall_velocity": "slip"}, "valid choices are: own, no-slip"),
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
    assert wcsph.cfl_step(params, 5.0, 1.0) == pytest.approx(0.4 * 0.05 / (c + 5.0))
    assert wcsph.cfl_step(params, 5.0, 1e6) == pytest.approx(0.4 * np.sqrt(0.05 / 1e6))
    assert iisph.cfl_step(params, 5.0, 9.81) == pytest.approx(0.4 * 0.05 / 5.0)
    assert iisph.cfl_step(params, 0.0, 9.81) == pytest.approx(0.4 * 0.05 / np.sqrt(9.81 * 2.0))
    ratio = iisph.cfl_step(params, 6.0, 9.81) / wcsph.cfl_step(params, 6.0, 9.81)
    assert ratio == pytest.approx((c + 6.0) / 6.0)            # both count spacings: Δx/v against Δx/(c+v)


def periodic_acceleration(x, params, box):
    """WCSPH pressure accelerations of a periodic lattice block (a 3 × 3 tiling of images,
    the block first): every particle sees a full neighbourhood."""
    shifts = [np.zeros(2)] + [np.array([i, j]) * box for i in (-1, 0, 1) for j in (-1, 0, 1)
                               if (i, j) != (0, 0)]
    ext = np.concatenate([x + s for s in shifts])
    nb = density.neighbourhood(ext, params.h)
    rho = density.summation_density(nb, params.mass)
    p = forces.tait_pressure(rho, params.rho0, params.sound_speed)
    return forces.pressure_acceleration(nb, params.mass, rho, p)[:len(x)]


def test_acoustic_limit_is_the_lattices_fastest_mode():
    """The largest eigenvalue ω² of -∂a/∂x of a periodic 10 × 10 lattice, compressed by 0.1 %
    so that no pressure is clamped, against c² max|g(k)|² over that lattice's wave vectors
    (central differences, step 1e-6 Δx: error ~ 1e-6 relative). The pressure of the 0.1 %
    compression stiffens sound by (ρ/ρ₀)^6 (dp/dρ = c² (ρ/ρ₀)^6): ~0.7 %, the tolerance."""
    n, dx, c = 10, 1.0, 10.0
    params = sph.Params(spacing=dx, gravity=(0.0, 0.0), sound_speed=c)
    squeeze = 0.9995
    x0 = scenes.lattice(n * dx, n * dx, dx) * squeeze
    box = n * dx * squeeze
    jac = np.zeros((2 * n * n, 2 * n * n))
    step = 1e-6 * dx
    for k in range(2 * n * n):
        e = np.zeros(2 * n * n)
        e[k] = step
        jac[:, k] = (periodic_acceleration(x0 + e.reshape(-1, 2), params, box)
                     - periodic_acceleration(x0 - e.reshape(-1, 2), params, box)).ravel() / (2 * step)
    omega_max = np.sqrt(np.linalg.eigvals(-jac).real.max())
    k = 2 * np.pi * np.arange(n) / (n * dx)
    grid = np.stack(np.meshgrid(k, k, indexing="ij"), axis=-1).reshape(-1, 2)
    predicted = c * np.linalg.norm(wcsph.lattice_gradient(params, grid), axis=1).max()
    assert omega_max == pytest.approx(predicted, rel=0.01)
    lam, k_fast = wcsph.acoustic_limit(params)
    assert lam == pytest.approx(2.0 * c / (dx * predicted), rel=0.02)    # the grid misses the peak a little
    assert 2.0 * c / (dx * predicted) >= lam                              # the true maximum is larger
    assert k_fast[0] == pytest.approx(k_fast[1], rel=1e-6)                # along a diagonal
    small = np.array([1e-4, 0.0])
    assert np.linalg.norm(wcsph.lattice_gradient(params, small)) / 1e-4 == pytest.approx(1.0, abs=0.01)
    with pytest.raises(ValueError, match="2D"):
        wcsph.acoustic_limit(sph.Params(spacing=1.0, gravity=(0.0, 0.0, -9.81)))


def test_jacobi_solves_the_system_and_clamps():
    """Without active clamps Jacobi converges to A⁻¹ source (within the tolerance it is given);
    a positive source entry (a particle that would need tension) ends at p = 0; a particle
    with a_ii = 0 keeps p = 0; the sweep count is capped."""
    rng = np.random.default_rng(11)
    n = 30
    M = rng.uniform(0.0, 1.0, (n, n))
    A = -(M + M.T) / n - np.diag(np.full(n, 3.0))
    A[5, :] = A[:, 5] = 0.0
    x_true = rng.uniform(1.0, 2.0, n)
    x_true[5] = 0.0
    source = A @ x_true
    p, sweeps = iisph.jacobi(lambda q: A @ q, np.diag(A).copy(), source, np.zeros(n), 1.0,
                             omega=0.5, tolerance=1e-13, max_sweeps=2000)
    assert sweeps < 2000 and p[5] == 0.0
    np.testing.assert_allclose(p, x_true, atol=1e-10)
    source[7] = 5.0                                      # wants a negative pressure
    p, _ = iisph.jacobi(lambda q: A @ q, np.diag(A).copy(), source, np.zeros(n), 1.0,
                        tolerance=1e-13, max_sweeps=2000)
    assert p[7] == 0.0 and np.all(p >= 0)
    _, sweeps = iisph.jacobi(lambda q: A @ q, np.diag(A).copy(), source, np.zeros(n), 1.0,
                             tolerance=0.0, max_sweeps=3)
    assert sweeps == 3


def test_front_errors_against_a_straight_front():
    """A front moving at Ritter's speed has Z = 1 + 2T exactly (linear: interpolation exact);
    a delay ΔT turns it into 1 + 2(T - ΔT)."""
    a = 0.3
    t = np.linspace(0.0, 1.0, 7) ** 1.5                      # uneven steps
    z = a * sph.ritter_front(t * np.sqrt(2 * 9.81 / a))
    table = np.array([[0.5, 2.0], [1.5, 4.0], [1.0, 2.5]])
    np.testing.assert_allclose(scenes.front_errors(t, z, a, table), [0.0, 0.0, 0.2], atol=1e-13)
    np.testing.assert_allclose(scenes.front_errors(t, z, a, table, delay=0.25),
                               [-0.25, -0.125, 0.0], atol=1e-13)
    assert scenes.front_errors(t, z, a).shape == (len(sph.MARTIN_MOYCE),)


def test_on_step_is_not_called_after_a_blow_up():
    sim = scenes.dam_break_simulation(200, "wcsph", cfl=5.0)
    calls = []
    sim.run(0.2, on_step=lambda s: calls.append(s.steps))
    assert not sim.stable and calls == list(range(1, sim.steps + 1))


# Moving walls (a lifted gate), and Adami et al.'s no-slip wall velocity.

@pytest.fixture(scope="module")
def block():
    """A 20 × 12 lattice block in a box (walls at rest), its pairs and densities."""
    params = sph.Params(spacing=0.025, viscosity=0.01, wall_viscosity=0.01)
    x = scenes.lattice(0.5, 0.3, 0.025)
    wall = boundary.box(0.5, 0.5, 0.025, params.rho0, params.h)
    nb = density.neighbourhood(x, params.h, params.kernel, wall)
    return params, x, wall, nb, density.summation_density(nb, params.mass, wall.psi)


def test_walls_moving_with_the_fluid_exert_nothing(block):
    """Fluid and walls moving together at U: the viscous force and the rate of change of the
    density vanish to round-off, as at rest (Galilean invariance); walls at rest drag every
    fluid particle near them back, against U."""
    params, x, wall, nb, rho = block
    U = np.array([1.3, -0.4])
    v = np.tile(U, (len(x), 1))
    moving = boundary.Boundary(wall.x, wall.psi, np.tile(U, (wall.n, 1)))
    assert moving.moving and not wall.moving
    nu, m = params.viscosity, params.mass
    at_rest = forces.viscosity_acceleration(nb, m, rho, v, nu, nu, wall.psi)
    along = forces.viscosity_acceleration(nb, m, rho, v, nu, nu, wall.psi, moving.v)
    assert np.abs(along).max() <= 1e-12 * np.abs(at_rest).max()
    near = np.isin(np.arange(len(x)), nb.bi)
    assert near.sum() > 40 and np.all(at_rest[near] @ U < 0) and np.all(at_rest[~near] == 0.0)
    op = PressureOperator(nb, m, rho, wall.psi)
    assert np.abs(op.divergence(v)).max() > 1.0                 # the walls' term, at rest
    flux = op.wall_flux(moving.v)
    np.testing.assert_allclose(flux, density.wall_sum(nb, wall.psi[nb.bk] * (nb.bgw @ U)), rtol=1e-12,
                               atol=1e-12 * np.abs(flux).max())
    assert np.abs(op.divergence(v) - flux).max() <= 1e-12 * np.abs(flux).max()


def test_a_sliding_floor_drags_the_water_along(block):
    """One WCSPH step of water at rest (no gravity) on a floor sliding at 1 m/s: the two rows
    within the floor's reach move with it, the first more; deeper rows feel nothing (away
    from the side walls)."""
    _, x, wall, _, _ = block
    v_wall = np.zeros_like(wall.x)
    v_wall[wall.x[:, 1] < 0, 0] = 1.0
    floor = boundary.Boundary(wall.x, wall.psi, v_wall)
    calm = sph.Params(spacing=0.025, viscosity=0.01, wall_viscosity=0.01, gravity=(0.0, 0.0),
                      sound_speed=20.0)
    _, v, _ = wcsph.step(x, np.zeros_like(x), calm, floor, dt=1e-4)
    row = np.round(x[:, 1] / 0.025 - 0.5).astype(int)
    middle = (x[:, 0] > calm.support) & (x[:, 0] < 0.5 - calm.support)     # away from the sides
    drag = [v[middle & (row == k), 0] for k in range(3)]
    assert np.all(drag[0] > 0) and np.all(drag[1] > 0) and drag[0].min() > drag[1].max()
    # the rest: round-off only (the lattice's density is ρ₀ to 1e-12: pressures of 1e-9 Pa)
    assert np.abs(v[middle & (row >= 2)]).max() < 1e-12 and np.abs(v[middle, 1]).max() < 1e-12


def test_no_slip_wall_velocity(block):
    """Adami et al.'s wall velocity 2 v_w - ṽ with ṽ = Σ_i v_i W_ik / Σ_i W_ik, against a
    plain loop; wall particles that no fluid reaches keep their own velocity."""
    params, x, wall, nb, rho = block
    rng = np.random.default_rng(3)
    v = rng.normal(size=x.shape)
    own = rng.normal(size=wall.x.shape)
    ghost = forces.no_slip_velocity(nb, v, own)
    for k in rng.choice(wall.n, 40, replace=False):
        w = kernels.cubic(np.linalg.norm(x - wall.x[k], axis=1), params.h)
        if w.sum() == 0:
            np.testing.assert_array_equal(ghost[k], own[k])
        else:
            np.testing.assert_allclose(ghost[k], 2 * own[k] - w @ v / w.sum(), rtol=1e-12, atol=1e-12)
    U = np.array([0.7, 0.2])                       # a uniform flow over walls at rest: ṽ = U
    reached = np.bincount(nb.bk, minlength=wall.n) > 0
    still = forces.no_slip_velocity(nb, np.tile(U, (len(x), 1)), n_wall=wall.n)
    np.testing.assert_allclose(still[reached], -U[None].repeat(reached.sum(), 0), rtol=1e-12)
    assert np.all(still[~reached] == 0.0)
    # in the viscous force: a uniform flow over a no-slip wall at rest is dragged twice as hard
    flow = np.tile(U, (len(x), 1))
    no_slip = sph.Params(spacing=0.025, viscosity=0.01, wall_viscosity=0.01, wall_velocity="no-slip")
    ghost = forces.viscous_wall_velocity(nb, no_slip, flow, wall)
    np.testing.assert_array_equal(ghost, still)
    assert forces.viscous_wall_velocity(nb, params, flow, wall) is None      # "own", at rest
    firm = forces.viscosity_acceleration(nb, params.mass, rho, flow, 0.01, 0.01, wall.psi, ghost)
    soft = forces.viscosity_acceleration(nb, params.mass, rho, flow, 0.01, 0.01, wall.psi)
    np.testing.assert_allclose(firm, 2 * soft, rtol=1e-12, atol=1e-15)


def test_gate_positions_speed_and_clearance():
    """A gate continues the lattice past x = a, rises at its speed, and leaves the walls once
    its lowest particle is above the given height."""
    params = sph.Params(spacing=0.1)
    g = boundary.gate(1.0, 2.5, 0.1, params.rho0, params.h, speed=2.0)
    np.testing.assert_allclose(np.unique(g.x[:, 0]), [1.05, 1.15])
    np.testing.assert_allclose(np.unique(g.x[:, 1]), np.arange(25) * 0.1 + 0.05)
    assert np.all(g.psi == params.mass) and g.bottom(0.3) == pytest.approx(0.65)
    box = boundary.box(6.0, 2.5, 0.1, params.rho0, params.h)
    walls = g.walls(box, 0.3)
    assert walls.n == box.n + len(g.x) and walls.moving
    np.testing.assert_allclose(walls.x[box.n:], g.x + np.array([0.0, 0.6]))
    np.testing.assert_array_equal(walls.v[box.n:], np.tile([0.0, 2.0], (len(g.x), 1)))
    assert not np.any(walls.v[:box.n]) and g.walls(box, 0.3, clear=0.6) is box
    assert boundary.gate(1.0, 2.5, 0.1, 1000.0, params.h).walls(box, 0.0) is box    # speed inf
    with pytest.raises(ValueError, match="speed"):
        boundary.gate(1.0, 2.5, 0.1, 1000.0, params.h, speed=-1.0)
    with pytest.raises(ValueError, match="velocities v"):
        boundary.Boundary(box.x, box.psi, np.zeros((3, 2)))


def test_a_gate_holds_the_water_until_it_opens():
    """A gate lifted at 1 mm/s keeps the column in for 0.1 s (its particles stay within a
    twentieth of a spacing of the gate's face); released at once, the foot has moved out
    by more than half a spacing by then. A fast gate limits the step (it moves at most
    λ Δx per step) while it touches the water, and is gone from the walls once it has
    cleared them."""
    dx = scenes.column_spacing(200)[0]
    slow = scenes.dam_break_simulation(200, gate_speed=1e-3)
    slow.run(0.1)
    assert scenes.front(slow.x, dx) <= 1.0 + 0.05 * dx             # jiggles, stays in
    once = scenes.dam_break_simulation(200)
    once.run(0.1)
    assert scenes.front(once.x, dx) > 1.0 + 0.5 * dx
    fast = scenes.dam_break_simulation(200, gate_speed=40.0)
    fast.run(0.12)
    limit = fast.params.cfl * dx / 40.0
    t, dt = np.array(fast.history["t"]), np.array(fast.history["dt"])
    touching = fast.gate.bottom(t - dt) < 2.0              # below the column's top at the start
    assert touching.sum() > 20 and np.max(dt[touching]) <= limit * (1 + 1e-12)
    assert fast.walls() is fast.wall and max(fast.history["dt"]) > 2 * limit
    T, Z = scenes.dam_break(n_particles=200, t_end=0.05, gate_speed=40.0)
    assert T[0] == 0.0 and Z[0] == 1.0 and np.all(np.diff(T) > 0)

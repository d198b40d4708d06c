"""XPBD, its sweeps over independent spring sets, and long range attachments, against
independent references.

The vectorized sweep is a Gauss–Seidel loop over springs: it equals a Python loop over the
springs in set order. XPBD's fused sweep equals the same loop with the update written with
``delta_lambda``. One XPBD iteration on one damped spring is backward Euler exactly, and
small steps converge to the motion (first order, as implicit Euler). Tethers put a particle
that strayed too far from a pin back at its limit, move nothing else, and hold a hanging
chain at its rest length.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from course_lib import cloth as C
from course_lib import springs as S
from course_lib.largestep import XPBD, ColouredSprings, LongRangeAttachments, delta_lambda

G = np.array([0.0, -9.81, 0.0])


def deformed_cloth(n=7, seed=3):
    """A small grid, deformed and moving, two pins, unequal masses (no two alike)."""
    x0, net = S.cloth_grid(n, n, 0.05, k_struct=500.0, k_shear=50.0, k_bend=10.0, c=0.02)
    rng = np.random.default_rng(seed)
    x = x0 + 0.004 * rng.normal(size=x0.shape)
    mass = rng.uniform(1e-3, 3e-3, n * n)
    return x0, net, x, mass, [0, n - 1]


def loop_sweep(springs, net, inverse_mass, p, update):
    """The reference: a Python loop over springs, set by set, moving each spring's ends by
    ``Δλ u/m`` with ``Δλ = update(spring, d)``."""
    p = p.copy()
    for q in springs.sets:
        for s in q.spring[q.used]:
            i, j = net.i[s], net.j[s]
            d = p[i] - p[j]
            u = d / np.linalg.norm(d)
            dl = update(s, d)
            p[i] += inverse_mass[i] * dl * u
            p[j] -= inverse_mass[j] * dl * u
    return p


def test_sets_are_independent_cover_every_spring_once_and_a_grid_needs_twelve():
    _, net, _, mass, pins = deformed_cloth()
    inv = np.where(np.isin(np.arange(net.n_particles), pins), 0.0, 1.0 / mass)
    springs = ColouredSprings(net, inv)
    assert len(springs.sets) == 12
    listed = np.concatenate([q.spring[q.used] for q in springs.sets])
    assert np.array_equal(np.sort(listed), np.arange(net.n_springs))
    for q in springs.sets:
        s = q.spring[q.used]
        ends = np.r_[net.i[s], net.j[s]]
        assert np.unique(ends).size == ends.size
    # A network without bands (random springs) is coloured greedily and gathered.
    rng = np.random.default_rng(4)
    i, j = rng.integers(0, 40, 150), rng.integers(0, 40, 150)
    keep = i != j
    rand = S.SpringNetwork(i[keep], j[keep], 1.0, 1.0, 0.0, 40)
    sets = ColouredSprings(rand, np.ones(40)).sets
    listed = np.concatenate([q.spring[q.used] for q in sets])
    assert np.array_equal(np.sort(listed), np.arange(rand.n_springs))
    assert any(q.ends is not None for q in sets)                  # some springs gathered
    for q in sets:
        s = q.spring[q.used]
        ends = np.r_[rand.i[s], rand.j[s]]
        assert np.unique(ends).size == ends.size


@pytest.mark.parametrize("kind", ["grid", "random"])
def test_the_vectorized_sweep_is_a_loop_over_springs(kind):
    if kind == "grid":
        _, net, x, mass, pins = deformed_cloth()
    else:
        rng = np.random.default_rng(8)
        i, j = rng.integers(0, 30, 90), rng.integers(0, 30, 90)
        keep = i != j
        net = S.SpringNetwork(i[keep], j[keep], rng.uniform(0.5, 1.5, keep.sum()), 3.0, 0.0, 30)
        x, mass, pins = rng.normal(size=(30, 3)), rng.uniform(1.0, 2.0, 30), [0]
    inv = np.where(np.isin(np.arange(net.n_particles), pins), 0.0, 1.0 / mass)
    springs = ColouredSprings(net, inv)
    stiffness = 0.7                                # PBD-like: Δλ = -s C/(w_i + w_j)

    def rule(q, d, squared):
        length = np.sqrt(squared)
        return np.where(q.used, stiffness * (length - q.rest) / np.where(q.used, q.w, 1.0), 0.0) \
            / np.maximum(length, 1e-300)

    buffer = springs.load(springs.buffer(3), x)
    got = springs.sweep(buffer, rule)[:, :net.n_particles].T
    w = inv[net.i] + inv[net.j]
    want = loop_sweep(springs, net, inv, x, lambda s, d: -stiffness
                      * (np.linalg.norm(d) - net.rest[s]) / w[s])
    assert np.allclose(got, want, rtol=0, atol=1e-14)
    assert np.array_equal(got[pins], x[pins])


def test_xpbd_sweep_is_the_loop_with_delta_lambda():
    _, net, x, mass, pins = deformed_cloth()
    h = 1 / 600
    rng = np.random.default_rng(5)
    solver = XPBD(net, mass, pinned=pins, gravity=G)
    solver._constants(h)
    start = solver.springs.load(solver.springs.buffer(3), x)
    p = x + 0.002 * rng.normal(size=x.shape)
    p[pins] = x[pins]
    solver._begin(start)
    buffer = solver.springs.load(solver.springs.buffer(3), p)
    solver._sweep(buffer)
    inv = solver.inverse_mass
    w = inv[net.i] + inv[net.j]

    def update(s, d):                              # λ = 0 at the start of a small step
        u = d / np.linalg.norm(d)
        rate = u @ (d - (x[net.i[s]] - x[net.j[s]]))
        return delta_lambda(np.linalg.norm(d) - net.rest[s], 0.0, w[s], 1 / net.k[s], h,
                            net.c[s] / (net.k[s] * h), rate)

    want = loop_sweep(solver.springs, net, inv, p, update)
    assert np.allclose(buffer[:, :net.n_particles].T, want, rtol=0, atol=1e-14)


@pytest.mark.parametrize("n, rows", [(12, 12), (32, 14), (64, 14)])
def test_only_long_bands_of_small_offset_are_split_into_rows(n, rows):
    # A band of offset 2 whose blocks run along the long axis is swept as two strided rows
    # once it is long (32² and up); a short one stays one operation per set (a 12² sheet,
    # whose sweep costs the overhead of each operation). Never one row per residue of a
    # larger offset (that made a sweep of three 12² sheets side by side 80 rows).
    c = C.sheet(n=n, k_struct=300.0, damping_ratio=0.1)
    solver = XPBD(c.network, c.mass, pinned=c.pinned, gravity=G)
    solver.step(c.x0, np.zeros_like(c.x0), 1 / 600)
    P, X = solver._stacked(3)
    assert len(solver.springs.sets) == 12 and len(solver._bound(P, X)) == rows


@pytest.mark.parametrize("equal_masses", [True, False])
def test_xpbd_steps_are_the_loop_over_springs(equal_masses):
    # step() runs its fastest path on a cloth of equal masses (the free ends' 1/m folded
    # into the coefficients, pinned ends moved and put back, band sets of offset 2 split
    # into strided rows, d and d0 from one stacked buffer): three small steps of it equal
    # the plain loop over springs with delta_lambda, damping included.
    _, net, x, mass, pins = deformed_cloth()
    if equal_masses:
        mass = np.full_like(mass, 2e-3)
    rng = np.random.default_rng(11)
    v = 0.05 * rng.normal(size=x.shape)
    v[pins] = 0.0
    dt, substeps = 1 / 200, 3
    solver = XPBD(net, mass, pinned=pins, gravity=G, substeps=substeps)
    got_x, got_v = solver.step(x, v, dt)
    h = dt / substeps
    inv = solver.inverse_mass
    w = inv[net.i] + inv[net.j]
    free = inv[:, None] > 0
    px, pv = x.copy(), v.copy()
    for _ in range(substeps):
        start = px.copy()

        def update(s, d, start=start):
            u = d / np.linalg.norm(d)
            rate = u @ (d - (start[net.i[s]] - start[net.j[s]]))
            return delta_lambda(np.linalg.norm(d) - net.rest[s], 0.0, w[s], 1 / net.k[s], h,
                                net.c[s] / (net.k[s] * h), rate)

        p = np.where(free, px + h * pv + h * h * G, px)
        p = loop_sweep(solver.springs, net, inv, p, update)
        pv, px = (p - px) / h, p
    assert any(q.uniform and q.held.size for q in solver.springs.sets) == equal_masses
    assert np.allclose(got_x, px, rtol=0, atol=1e-13)
    assert np.allclose(got_v, pv, rtol=0, atol=1e-13 / h)
    assert np.array_equal(got_x[pins], x[pins])


@pytest.mark.parametrize("c", [0.0, 3.0])
def test_one_xpbd_iteration_on_one_spring_is_backward_euler(c):
    # Along the spring, m s'' = -k s - c s': backward Euler steps the stretch and its rate
    # with (I - h J)⁻¹; one XPBD update from λ = 0 lands exactly there (with damping γ).
    k, m, h, L = 60.0, 0.4, 0.05, 1.0
    net = S.SpringNetwork([1], [0], L, k, c, 2)
    x = np.array([[0.0, 0.0, 0.0], [L + 0.15, 0.0, 0.0]])
    v = np.array([[0.0, 0.0, 0.0], [-0.4, 0.0, 0.0]])
    solver = XPBD(net, m, pinned=[0])
    P = np.linalg.inv(np.eye(2) - h * np.array([[0.0, 1.0], [-k / m, -c / m]]))
    state = np.array([0.15, -0.4])
    for _ in range(6):
        state = P @ state
        x, v = solver.step(x, v, h)
        assert np.allclose([x[1, 0] - L, v[1, 0]], state, rtol=1e-12, atol=1e-14)


def test_small_steps_converge_to_the_motion_at_first_order():
    # A damped chain of 5 stiff springs falls from horizontal for 0.2 s; the reference is
    # an 8th-order Runge–Kutta solution of the same ODE (error far below XPBD's).
    n, rest, k, m, c, T = 6, 0.1, 2000.0, 0.01, 0.05, 0.2
    x0 = np.zeros((n, 3))
    x0[:, 0] = rest * np.arange(n)
    net = S.SpringNetwork(np.arange(n - 1), np.arange(1, n), rest, k, c, n)
    free = np.ones((n, 1))
    free[0] = 0.0

    def rhs(_t, y):
        x, v = y[:3 * n].reshape(n, 3), y[3 * n:].reshape(n, 3)
        return np.r_[(v * free).ravel(), ((net.forces(x, v) / m + G) * free).ravel()]

    ref = solve_ivp(rhs, (0, T), np.r_[x0.ravel(), np.zeros(3 * n)], method="DOP853",
                    rtol=1e-11, atol=1e-13).y[:3 * n, -1].reshape(n, 3)
    errors = []
    for substeps in (100, 200, 400):
        x, _ = XPBD(net, m, pinned=[0], gravity=G, substeps=substeps).step(x0, np.zeros_like(x0), T)
        errors.append(np.abs(x - ref).max())
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    # first order: halving the step halves the error (the O(h²) term is 1/100 of it here)
    assert np.all(np.abs(ratios - 2.0) < 0.1), ratios
    assert errors[-1] < 1e-3


def test_tethers_bring_strays_back_and_move_nothing_else():
    rest = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [3.0, 4.0, 0.0]])
    tethers = LongRangeAttachments(rest, [0], scale=1.1)
    assert np.allclose(tethers.limits, [[np.inf, 1.1, 2.2, 5.5]])
    p = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [6.0, 8.0, 0.0]])
    out = tethers.project(p.T.copy()).T
    assert np.array_equal(out[0], p[0]) and np.array_equal(out[2], p[2])   # pin; within reach
    assert np.allclose(out[1], [1.1, 0.0, 0.0], rtol=1e-15)             # back along the line
    assert np.allclose(out[3], [3.3, 4.4, 0.0], rtol=1e-15)
    assert tethers.excess(out) == pytest.approx(0.0, abs=1e-15) and tethers.excess(p) > 0
    two = LongRangeAttachments(rest, [0, 1])
    q = two.project(p.T.copy()).T
    assert np.array_equal(q[:2], p[:2])                                   # pins never move
    for bad, match in (({"scale": 0.9}, "scale"), ({"distances": np.ones((2, 4))}, "distances")):
        with pytest.raises(ValueError, match=match):
            LongRangeAttachments(rest, [0], **bad)
    with pytest.raises(ValueError, match="rest_positions"):
        LongRangeAttachments(rest[:, :, None], [0])
    with pytest.raises(TypeError, match="tethers"):
        XPBD(S.SpringNetwork([0], [1], 1.0, 1.0, 0.0, 4), 1.0, tethers="yes")


def test_tethers_hold_a_soft_hanging_chain_at_its_rest_length():
    # Soft springs stretch under the chain's weight; with tethers at scale 1 no particle
    # gets farther from the pin than its rest distance along the chain.
    n, rest, k, m = 6, 0.1, 2.0, 0.01
    x0 = np.zeros((n, 3))
    x0[:, 1] = -rest * np.arange(n)
    net = S.SpringNetwork(np.arange(n - 1), np.arange(1, n), rest, k, 0.0, n)
    x, v = x0.copy(), np.zeros_like(x0)
    free = XPBD(net, m, pinned=[0], gravity=G, substeps=10)
    held = XPBD(net, m, pinned=[0], gravity=G, substeps=10,
                tethers=LongRangeAttachments(x0, [0]))
    xf, xh = x.copy(), x.copy()
    vf, vh = v.copy(), v.copy()
    for _ in range(100):
        xf, vf = free.step(xf, vf, 0.01)
        xh, vh = held.step(xh, vh, 0.01)
    assert -xf[-1, 1] > 1.5 * rest * (n - 1)                             # stretched
    assert np.all(np.linalg.norm(xh - xh[0], axis=1) <= rest * np.arange(n) * (1 + 1e-12))


def test_cloth_simulate_builds_tethers_from_the_rest_shape():
    c = C.sheet(n=6, k_struct=30.0)
    plain = C.simulate(c, "xpbd", frames=10, fps=60, options={"substeps": 10})
    tied = C.simulate(c, "xpbd", frames=10, fps=60, options={"substeps": 10, "tethers": True})
    scaled = C.simulate(c, "xpbd", frames=10, fps=60, options={"substeps": 10, "tethers": 1.05})
    reach = np.linalg.norm(c.x0[:, None] - c.x0[c.pinned][None], axis=-1)
    away = reach > 0

    def stretch(run):                       # the largest distance from a pin over its reach
        far = np.linalg.norm(run.x[-1][:, None] - run.x[-1][c.pinned][None], axis=-1)
        return float(np.max(far[away] / reach[away]))

    # The tethers of the two pins are met one after the other (Gauss–Seidel), so the second
    # can pull a particle a little off the first's limit: within 1 % here, against 18 %
    # beyond it without tethers.
    assert stretch(plain) > 1.1
    assert 1.0 <= stretch(tied) < 1.01 and 1.05 <= stretch(scaled) < 1.05 * 1.01

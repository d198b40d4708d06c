"""Every number quoted in solutions/08_hair_chains.ipynb, its widget, and its exercise checks."""

import numpy as np
import pytest
from notebook_helpers import drive_kept_figure, printed_holds
from planted import Plant, judge

import course_lib as cl
from course_lib import hair as H
from course_lib import springs as S
from course_lib import strands
from course_lib.check import RESULTS
from course_lib.check import nb08 as check
from course_lib.lessons import nb08_hair_chains as nb08
from course_lib.lessons import nb08_hair_view as view08

M, K = H.MASS, H.STRAND["k_edge"]


@pytest.mark.roundoff
def test_strand_setup_and_swing():
    """The swing is a whip: round-off of 1e-15 grows to ~3e-9 m in 1.3 s (measured), so the
    strain it quotes, 0.0229, moves by ~1e-8 between roundings, far below its last digit."""
    x0, net = S.hair_chain(**H.STRAND)
    assert net.n_springs == 15 and net.rest[0] == pytest.approx(0.02)
    assert M * H.STRAND["n"] * 1e3 == pytest.approx(1.6)             # total mass 1.6 g
    swing = H.simulate(x0, net, frames=40, substeps=160)
    assert swing.dt == pytest.approx(1 / 4800) and swing.stable
    assert swing.frames.shape == (41, 16, 3)
    assert np.all(swing.x[:, 0] == x0[0])                      # the root stays pinned
    assert H.max_strain(swing, net) == pytest.approx(0.0229, abs=5e-5)
    # the largest stretch comes from the whip near t = 1.3 s, about 60x the hanging 0.04%
    per_step = np.max(np.abs(net.strain(swing.x)), axis=1)
    assert np.argmax(per_step) * swing.dt == pytest.approx(1.3, abs=0.05)
    assert round(per_step.max() / (15 * M * 9.81 / (K * 0.02)), -1) == 60
    # over the first 12 frames (0.4 s) the same strand stretches by only 0.17%
    assert per_step[: 12 * 160 + 1].max() * 100 == pytest.approx(0.17, abs=0.005)


@pytest.mark.parametrize(("k_bend", "zigzag", "sag_cm"), [
    (0.0, 0.0, 28.01), (2000.0, 0.0, 24.85), (0.0, 0.3, 29.24), (2000.0, 0.3, 3.31)])
def test_held_strand_sag(k_bend, zigzag, sag_cm):
    assert nb08.tip_sag(k_bend, zigzag) * 100 == pytest.approx(sag_cm, abs=0.005)


@pytest.fixture(scope="module")
def escape():
    """Section 2's held zigzag: its planar minimum and the run that leaves it (two tests)."""
    return nb08.saddle_escape(k_bend=2000.0, zigzag=0.3)


def test_the_held_zigzag_is_a_saddle_in_3d(escape):
    """Section 2's saddle: what the notebook prints, with tolerances from the solver's
    force tolerance (1e-9 of the weight) and the run's sampling (every 5 ms)."""
    esc = escape
    assert f"{esc.planar.lowest:.3g}" == "0.0431" and esc.planar.lowest > 0
    assert np.round(esc.lowest, 1).tolist() == [-21.8, -12.0, -6.6]
    assert (f"{esc.planar.energy * 1e3:.3f}", f"{esc.minimum.energy * 1e3:.3f}") == ("-0.056", "-1.734")
    assert f"{esc.minimum.lowest:.2g}" == "0.0026" and esc.minimum.lowest > 0
    assert f"{-esc.minimum.x[-1, 1] * 100:.1f}" == "25.7"
    assert f"{abs(esc.minimum.x[-1, 2]) * 1e3:.1f}" == "4.8"
    assert np.all(esc.planar.x[:, 2] == 0.0)
    # a nudge of 1 µm: 1 cm away after 0.04 s, at rest near the minimum (or its mirror)
    assert f"{esc.t[np.argmax(esc.away > 0.01)]:.2f}" == "0.04"
    assert esc.near[-1] < 2e-3
    # the growth rate the prose quotes: sqrt(22 / 1e-4) ≈ 470 /s
    assert np.sqrt(-esc.lowest[0] / M) == pytest.approx(470, rel=0.02)
    # "almost as low as a plain chain (28 cm)": the edges-only tip sag
    assert -esc.minimum.x[-1, 1] < nb08.tip_sag(0.0, 0.0)


def test_simulate_is_integrate_to_round_off():
    """Section 1: the fast loop's numbers are integrate's (its speed is measured in the
    notebook, and by make bench, never by a timed unit test)."""
    x0, net = S.hair_chain(**H.STRAND)
    run = H.simulate(x0, net, frames=3, substeps=160)
    traj = cl.integrate(H.strand_system(net), cl.stack_state(x0, 0 * x0), (0.0, 0.1), run.dt,
                        "symplectic_euler")
    assert np.allclose(traj.y[:, 0], run.x[:481], rtol=0, atol=1e-12)


def test_static_shape_is_an_equilibrium():
    x0, net = nb08.held_strand(2000.0, 0.3)
    x = H.static_shape(x0, net)
    F = net.forces(x) + M * np.array([0.0, -9.81, 0.0])
    assert np.abs(F[2:]).max() < 1e-4 * M * 9.81 * 16


def test_spring_families():
    _, net3 = S.hair_chain(**H.STRAND, k_bend=2000.0, k_twist=500.0)
    counts = {k: net3.select(k).n_springs for k in ("edge", "bend", "twist")}
    assert counts == {"edge": 15, "bend": 14, "twist": 13}
    ends = {k: ((int(net3.select(k).i[0]), int(net3.select(k).j[0])),
                (int(net3.select(k).i[-1]), int(net3.select(k).j[-1]))) for k in counts}
    assert ends == {"edge": ((0, 1), (14, 15)), "bend": ((0, 2), (13, 15)), "twist": ((0, 3), (12, 15))}


def test_chain_step_limit():
    sqrt_mk = np.sqrt(M / K)
    assert sqrt_mk * 1e3 == pytest.approx(0.2236, abs=5e-5)
    x0, net = S.hair_chain(**H.STRAND)
    w = S.max_frequency(net, x0, M, pinned=[0])
    assert w == pytest.approx(S.chain_max_frequency(15, K, M), rel=1e-12)
    assert w == pytest.approx(8898.38, abs=0.005)
    assert 2e3 / w == pytest.approx(0.22476, abs=5e-6)
    measured = H.chain_dt_max(net, x0)
    assert measured * 1e3 == pytest.approx(0.22475, abs=5e-6)
    assert measured * w / 2 == pytest.approx(0.99996, abs=5e-6)       # "to 0.004%"
    assert measured == pytest.approx(2 / w, rel=1e-2)
    assert measured / sqrt_mk == pytest.approx(1.0051, abs=5e-5)       # "0.5% above sqrt(m/k)"
    # substeps per frame at 30 fps
    assert int(np.ceil((1 / 30) / measured)) == 149


@pytest.mark.parametrize(("zigzag", "omega", "limit_ms", "measured_ms", "over_sqrt"), [
    (0.0, 11044.26, 0.18109, 0.18108, 0.8098), (0.3, 10901.17, 0.18347, 0.18346, 0.8205)])
def test_bending_springs_table(zigzag, omega, limit_ms, measured_ms, over_sqrt):
    x, net = S.hair_chain(**H.STRAND, k_bend=2000.0, zigzag=zigzag)
    w = S.max_frequency(net, x, M, pinned=[0])
    assert w == pytest.approx(omega, abs=0.005)
    assert 2e3 / w == pytest.approx(limit_ms, abs=5e-6)
    measured = H.chain_dt_max(net, x)
    assert measured * 1e3 == pytest.approx(measured_ms, abs=5e-6)
    assert measured * w / 2 == pytest.approx(0.99996, abs=5e-6)
    assert measured / np.sqrt(M / K) == pytest.approx(over_sqrt, abs=5e-5)


def test_bending_springs_lower_the_limit():
    xb, netb = S.hair_chain(**H.STRAND, k_bend=2000.0)
    w = S.max_frequency(netb, xb, M, pinned=[0])
    assert (2 / w) / np.sqrt(M / K) == pytest.approx(0.81, abs=5e-4)
    assert int(np.ceil((1 / 30) / (2 / w))) == 185
    # a straight chain at rest has no stiffness across its axis: the modes are along it
    Kmat = S.stiffness_matrix(netb, xb).reshape(16, 3, 16, 3)
    assert np.all(Kmat[:, 1:, :, :] == 0) and np.all(Kmat[:, :, :, 1:] == 0)
    xz, netz = S.hair_chain(**H.STRAND, k_bend=2000.0, zigzag=0.3)
    assert 2e3 / S.max_frequency(netz, xz, M, pinned=[0]) == pytest.approx(0.18347, abs=5e-6)
    # the held strand (two particles pinned) of the widget: 0.1837 ms without damping, 0.1835
    # ms with c = 2e-3 kg/s (notebook 07's w² dt² + 2 (c/m) dt < 4, the fastest mode binding)
    undamped = nb08.run_held_strand(damping=0.0, dt=1e-4, t_end=0.01).dt_limit
    damped = nb08.run_held_strand(damping=2e-3, dt=1e-4, t_end=0.01).dt_limit
    assert round(undamped * 1e3, 4) == 0.1837 and round(damped * 1e3, 4) == 0.1835
    w = 2.0 / undamped
    gamma = 2e-3 / M
    assert (w * damped) ** 2 + 2 * gamma * damped == pytest.approx(4.0, rel=1e-12)


@pytest.mark.parametrize("damping", [0.0, 0.01, 0.05])
def test_widget_limit_with_damping_is_the_measured_one(damping):
    """The widget's printed limit is where the run turns unstable, with damping too (the
    review's case: c = 0.05 kg/s blew up at 0.1815 ms under the undamped 0.184 ms)."""
    lim = nb08.run_held_strand(k_bend=2000.0, damping=damping, dt=1e-4, t_end=0.01).dt_limit
    below = nb08.run_held_strand(k_bend=2000.0, damping=damping, dt=0.995 * lim, t_end=0.3)
    above = nb08.run_held_strand(k_bend=2000.0, damping=damping, dt=1.005 * lim, t_end=0.3)
    assert below.stable and not above.stable


def test_strain_against_substeps():
    budgets = [10, 20, 40, 80, 160]
    strains = np.array(nb08.max_strain_vs_substeps(budgets))
    assert nb08.stiffest_edge(10) == pytest.approx(4.5) and nb08.stiffest_edge(160) == pytest.approx(1152.0)
    assert [nb08.stiffest_edge(S_) for S_ in budgets] == pytest.approx([4.5, 18.0, 72.0, 288.0, 1152.0])
    assert strains == pytest.approx([0.62341, 0.18409, 0.05122, 0.01284, 0.00303], abs=5e-6)
    ratios = strains[:-1] / strains[1:]
    assert np.all(np.diff(strains) < 0)
    assert ratios == pytest.approx([3.39, 3.59, 3.99, 4.23], abs=0.005)
    # "the 2000 N/m strand of section 1 stretches by 0.17% over the same 0.4 s" (printed)
    x0, net = S.hair_chain(**H.STRAND)
    swing = H.simulate(x0, net, frames=12, substeps=160)
    first_fall = np.abs(net.strain(swing.x)).max()
    assert f"{first_fall * 100:.2f}" == "0.17"


def test_damping_calms_the_strand():
    eq = None
    spans = {}
    for c in (0.0, 2e-3, 1e-2):
        run = nb08.run_held_strand(k_bend=2000.0, damping=c, dt=1e-4, t_end=0.5)
        assert run.stable
        late = run.tip_y[run.params["t"] > 0.4]
        spans[c] = (late.min(), late.max())
        eq = run.equilibrium[-1, 1]
    assert eq * 100 == pytest.approx(-2.71, abs=0.005)
    assert eq == pytest.approx(nb08.held_strand(2000.0, 0.3)[0][-1, 1] - nb08.tip_sag(2000.0, 0.3), abs=1e-12)
    printed = {0.0: (-6.11, -4.07), 2e-3: (-2.73, -2.65), 1e-2: (-2.35, -2.15)}
    for c, (lo, hi) in printed.items():
        assert spans[c][0] * 100 == pytest.approx(lo, abs=0.005)
        assert spans[c][1] * 100 == pytest.approx(hi, abs=0.005)
    # c = 2e-3 kg/s: settled, within 0.6 mm of the equilibrium over 0.4-0.5 s
    assert round(max(abs(spans[2e-3][0] - eq), abs(spans[2e-3][1] - eq)) * 1e3, 1) == 0.6
    # c = 1e-2 kg/s: over-damped, still 0.4 to 0.6 cm above the equilibrium
    assert round((spans[1e-2][0] - eq) * 100, 1) == 0.4 and round((spans[1e-2][1] - eq) * 100, 1) == 0.6


def test_the_planar_minimum_is_only_local(escape):
    """Section 2: started turned down by 1 rad, the same held zigzag settles at another
    minimum in its plane: the bend at particle 2 snapped through, sag 25.26 cm, 1.6 mJ lower.
    The solver stops at 1e-9 of the weight in force, so the shape is good to ~1e-9 m."""
    x_rest, net = nb08.held_strand(2000.0, 0.3)
    snapped = nb08.drooped_equilibrium(2000.0, 0.3, droop=1.0)
    planar = escape.planar
    sag = x_rest[-1, 1] - snapped.x[-1, 1]
    printed_holds(sag * 100, "5.2f", "25.26", 1e-6)
    assert round(sag * 100, 1) == 25.3
    printed_holds(snapped.energy * 1e3, ".3f", "-1.658", 1e-8)
    printed_holds(snapped.lowest, ".3f", "0.026", 1e-6)
    assert snapped.lowest > 0                              # a minimum among planar shapes
    assert nb08.flipped_bends(snapped.x, x_rest).tolist() == [2]
    assert nb08.flipped_bends(planar.x, x_rest).tolist() == []   # the held-out one: none
    # "its energy lies 1.6 mJ below the held-out shape's"
    assert round((planar.energy - snapped.energy) * 1e3, 1) == 1.6
    # it is an equilibrium: the net force on the free coordinates vanishes (to 1e-9 of mg)
    force = net.forces(snapped.x) + M * np.array([0.0, -9.81, 0.0])
    assert np.abs(force[2:, :2]).max() < 1e-6 * M * 9.81
    # the same minimum from any drooped start between 0.5 and 2 rad: not a fluke of one start
    for droop in (0.5, 1.5, 2.0):
        other = nb08.drooped_equilibrium(2000.0, 0.3, droop=droop)
        assert np.abs(other.x - snapped.x).max() < 1e-6
    # in 3D it is a saddle as well (a planar truss again)
    from course_lib.statics import curvature
    assert curvature(net, snapped.x, (0, 1))[0] < 0


def test_hairstyle_substeps_margin():
    """Section 6: 180 substeps where 2/ω_max asks for 149; 149 runs stable too."""
    center, R = np.zeros(3), 0.1
    xs, net, roots = H.hairstyle(n_strands=7, center=center, radius=R, k_bend=200.0, k_twist=100.0)
    w = S.max_frequency(net, xs, M, pinned=roots)
    need = int(np.floor(1 / (30 * 2 / w))) + 1
    assert need == 149 and 1 - 149 / 180 == pytest.approx(0.2, abs=0.035)     # "a fifth"
    bare = H.simulate(xs, net, frames=45, substeps=149, pinned=roots, damping=2e-3,
                      post_step=H.head_collision(center, R, pinned=roots))
    assert bare.stable


def test_widget_blowup_state():
    run = nb08.run_held_strand(k_bend=2000.0, damping=2e-3, dt=1.9e-4, t_end=0.5)
    assert not run.stable and run.message == "unstable at step 32, t = 6.08 ms (a speed past 100 m/s)"
    assert np.abs(run.last_finite).max() < 1.0            # the positions were not what passed 100
    assert run.last_step == 32 and np.all(np.isfinite(run.last_finite))
    assert run.growth.shape == (33,) and run.growth[-1] > 1e-3 and run.growth[0] == 0.0
    # the speed panel: symplectic Euler's speeds are the position differences over dt; the
    # run stops at the step where one passes 100 m/s
    assert run.speed.shape == (32,) and run.speed[-1] > 100.0 and run.speed[-2] < 100.0
    x, _ = H.symplectic_euler_run(*nb08.held_strand(2000.0, 0.3), 1.9e-4, 5, pinned=(0, 1),
                                  damping=2e-3)
    v = np.linalg.norm(x[1:] - x[:-1], axis=2).max(axis=1) / 1.9e-4
    assert np.allclose(run.speed[:5], v, rtol=1e-12)
    fig = nb08.draw_held_strand(run)
    labels = [t.get_text() for t in fig.axes[1].get_legend().texts]
    assert labels == ["largest |x - x0| of any particle (m)", "largest speed of any particle (m/s)"]


def test_widget_key_states():
    soft = nb08.run_held_strand(k_bend=10.0, damping=2e-3, dt=1e-4, t_end=0.3)
    assert soft.stable and round(-soft.equilibrium[-1, 1] * 100) == 27      # "27 cm below"
    assert soft.tip_y[-1] > soft.equilibrium[-1, 1] + 0.05                   # still falling
    assert nb08.tip_sag(10.0, 0.3) < nb08.tip_sag(0.0, 0.3)                   # "almost as low"


def test_held_strand_explorer_view():
    view = nb08.held_strand_explorer(k_bend=2000.0, damping=2e-3, dt=1e-4)
    r = view.result
    assert r.stable and r.params["steps"] == 3000 and r.params["t_shown"] == pytest.approx(0.3)
    assert "updated in" in view.status.value
    view.controls["dt"].value = 3e-4                      # past the 0.184 ms limit
    assert not view.result.stable and "stopped after step" in view.figure.texts[1].get_text()
    view.controls["dt"].value = 2e-5                      # the cap: 3000 steps, 0.06 s
    r = view.result
    assert r.params["steps"] == view08.MAX_STEPS == 3000 and r.params["t_shown"] == pytest.approx(0.06)
    assert "the widget's cap" in view.figure.texts[1].get_text()
    view.controls["k_bend"].value = 10.0                  # soft bending springs: droops
    view.controls["dt"].value = 1e-4
    r = view.result
    assert r.stable and r.params["k_bend"] == pytest.approx(10.0, rel=1e-2)
    assert r.equilibrium[-1, 1] < -0.25
    # the widget runs what run_held_strand runs
    same = nb08.run_held_strand(k_bend=view.controls["k_bend"].value, damping=2e-3, dt=1e-4,
                                t_end=0.3, max_steps=3000)
    assert np.array_equal(same.tip_y, r.tip_y)


def test_hair_widget_redraws_only_the_curves_and_its_picture_is_right():
    """Driven through its sliders: 1% steps of dt reuse the kept background (axes, ticks,
    legends), a blow-up or a new scale redraws it, and each picture equals a full redraw of
    the figure; the time axis holds the run."""
    view = nb08.held_strand_explorer(k_bend=2000.0, damping=2e-3, dt=1e-4)
    moves = [("dt", 1.01e-4), ("dt", 1.02e-4), ("dt", 1.03e-4), ("dt", 3e-4), ("dt", 2e-5),
             ("k_bend", 10.0), ("damping", 0.0)]
    redrawn = []
    for _, _, run, fresh in drive_kept_figure(view, moves):
        redrawn.append(fresh)
        ax_t = view.figure.axes[1]
        assert ax_t.get_xlim()[1] >= run.params["t"][run.last_step]
        assert ax_t.get_yscale() == ("linear" if run.stable else "log")
    assert redrawn[:4] == [False, False, False, True]   # dt = 0.3 ms blows up: a new scale


def test_hairstyle_one_network_and_head_collision():
    center, R = np.zeros(3), 0.1
    xs, net, roots = H.hairstyle(n_strands=7, center=center, radius=R, k_bend=200.0, k_twist=100.0)
    assert xs.shape == (112, 3) and net.n_springs == 7 * (15 + 14 + 13) == 294
    assert roots.tolist() == list(range(0, 112, 16))
    assert np.allclose(np.linalg.norm(xs[roots] - center, axis=1), R)
    assert np.allclose(net.strain(xs), 0.0) and np.allclose(net.forces(xs), 0.0, atol=1e-9)
    # curly: every strand is a helix, so its bending springs are shorter than two segments
    bend = net.select("bend")
    assert np.all(bend.rest < 2 * 0.02 - 1e-4)
    w = S.max_frequency(net, xs, M, pinned=roots)
    assert 2e3 / w == pytest.approx(0.2247, abs=5e-5)
    assert 1e3 / (30 * 180) == pytest.approx(0.1852, abs=5e-5) and 1 / (30 * 180) < 2 / w
    style = H.simulate(xs, net, frames=45, substeps=180, pinned=roots, damping=2e-3,
                       post_step=H.head_collision(center, R, pinned=roots))
    assert style.stable
    assert np.linalg.norm(style.x - center, axis=-1).min() >= R * (1 - 1e-12)
    assert H.max_strain(style, net) == pytest.approx(0.0026, abs=5e-5)
    assert np.all(style.x[:, roots] == xs[roots])
    # "settle onto it": at 1.5 s the median particle moves at 9 mm/s, the fastest at 0.1 m/s
    # (printed as 9 mm/s and 0.1 m/s; contact makes the run sensitive, so the bounds are wide
    # enough for another rounding and narrow enough for the printed digits)
    speed = np.linalg.norm(style.x[-1] - style.x[-2], axis=1) / style.dt
    assert 8.5e-3 <= np.median(speed) < 9.5e-3 and 0.05 <= speed.max() < 0.15
    assert f"{np.median(speed) * 1e3:.0f}" == "9" and f"{speed.max():.1f}" == "0.1"
    # at rest after 1.5 s: the strands hang below the top of the head
    assert np.all(style.frames[-1][:, 1] < 0.1 + 1e-9)


def test_fast_loop_is_symplectic_euler():
    x0, net = S.hair_chain(**H.STRAND, k_bend=300.0, zigzag=0.3)
    for damping, pinned in ((0.0, (0,)), (2e-3, (0, 1))):
        system = H.strand_system(net, M, pinned, damping)
        traj = cl.integrate(system, cl.stack_state(x0, np.zeros_like(x0)), (0.0, 0.2), 1e-4,
                            "symplectic_euler")
        x, message = H.symplectic_euler_run(x0, net, 1e-4, 2000, pinned=pinned, damping=damping)
        assert message == "ok" and np.abs(traj.y[:, 0] - x).max() < 1e-12
    # the same verdict as integrate when it blows up
    system = H.strand_system(net, M, (0,), 0.0)
    traj = cl.integrate(system, cl.stack_state(x0, np.zeros_like(x0)), (0.0, 2000 * 2.5e-4),
                        2.5e-4, "symplectic_euler", blowup_bound=100.0)
    x, message = H.symplectic_euler_run(x0, net, 2.5e-4, 2000, blowup_bound=100.0)
    assert message == traj.message == "unstable at step 29, t = 0.00725 (|y| > 100)"
    assert np.all(np.isnan(x[30:])) and np.all(np.isfinite(x[:30]))
    # damping along the springs and a post-step response go through too
    _, net_c = S.hair_chain(**H.STRAND, c_edge=0.05)
    ground = cl.collisions.plane(normal=(0.0, 1.0, 0.0), offset=-0.1, restitution=0.0)
    system = H.strand_system(net_c, M, (0,), 0.0)
    traj = cl.integrate(system, cl.stack_state(x0, np.zeros_like(x0)), (0.0, 0.1), 1e-4,
                        "symplectic_euler", post_step=ground)
    x, _ = H.symplectic_euler_run(x0, net_c, 1e-4, 1000, post_step=ground)
    assert np.abs(traj.y[:, 0] - x).max() < 1e-12


def test_newton_equilibrium():
    for k_bend, zigzag in ((0.0, 0.0), (2000.0, 0.0), (2000.0, 0.3), (10.0, 0.3), (1e4, 0.3)):
        x0, net = nb08.held_strand(k_bend, zigzag)
        x = H.static_shape(x0, net, axes=(0, 1))                     # the planar problem
        F = net.forces(x) + M * np.array([0.0, -9.81, 0.0])
        assert np.linalg.norm(F[2:]) < 1e-9 * 14 * M * 9.81          # balanced to 1e-9
        assert np.all(x[:2] == x0[:2])                              # the clamp holds
        # a minimum in the strand's plane: the stiffness matrix of the free particles'
        # x and y is positive semidefinite
        in_plane = (np.arange(2, 16)[:, None] * 3 + np.arange(2)).ravel()
        K = S.stiffness_matrix(net, x)
        assert np.linalg.eigvalsh(K[np.ix_(in_plane, in_plane)]).min() > -1e-9 * np.abs(K).max()
        # out of the plane the held-out zigzag is unstable: its compressed springs give
        # negative stiffness across the plane (it would flop sideways)
        out = np.arange(2, 16) * 3 + 2
        lowest = np.linalg.eigvalsh(K[np.ix_(out, out)]).min()
        assert (lowest < -1.0) == (k_bend >= 2000.0 and zigzag > 0), (k_bend, zigzag, lowest)
        if (k_bend, zigzag) == (2000.0, 0.3):
            assert round(np.linalg.eigvalsh(K[6:, 6:]).min()) == -22        # "about -22 N/m"


def test_twist_needs_a_non_planar_strand():
    shapes = nb08.twist_shapes()
    angles = np.geomspace(1e-3, 1e-2, 8)
    slopes = {}
    for name, x0 in shapes.items():
        E = nb08.twist_energy(x0, angles)
        if name == "straight":
            assert E.max() < 1e-28                                  # a rigid rotation: 0
            continue
        slopes[name] = np.polyfit(np.log(angles), np.log(E), 1)[0]
        # without torsion springs no shape resists a twist at all (edge/bending springs span
        # three particles, always coplanar with the axis)
        assert nb08.twist_energy(x0, angles, k_twist=0.0).max() < 1e-28
    assert slopes["planar curl"] == pytest.approx(4.0, abs=5e-4)
    assert slopes["zigzag"] == pytest.approx(4.0, abs=5e-4)
    assert slopes["helix"] == pytest.approx(2.0, abs=5e-3)
    assert {k: f"{v:.3f}" for k, v in slopes.items()} == {
        "planar curl": "4.000", "zigzag": "4.000", "helix": "2.003"}
    assert f"{nb08.twist_energy(shapes['helix'], 1e-3)[0]:.3e}" == "4.540e-10"
    # the first-order rate 2 (b - a).(u x (b - x_p)) vanishes for planar shapes only
    for name, x0 in shapes.items():
        u = (x0[2] - x0[1]) / np.linalg.norm(x0[2] - x0[1])
        rate = 2 * (x0[3] - x0[0]) @ np.cross(u, x0[3] - x0[2])
        assert (abs(rate) > 1e-6) == (name == "helix"), name
    # released: the helix untwists, the planar ones stay twisted
    released = nb08.twist_releases({name: shapes[name] for name in ("planar curl", "zigzag", "helix")})
    final = {name: angle[-1] for name, (_, angle, _) in released.items()}
    assert {message for _, _, message in released.values()} == {"ok"}
    # the notebook's one run of the three strands is each strand's own run (0.2 s of it)
    for name, (t, angle, _) in released.items():
        t_one, angle_one, message = nb08.twist_release(shapes[name], t_end=0.2)
        assert message == "ok" and np.array_equal(t_one, t[:t_one.size])
        np.testing.assert_allclose(angle_one, angle[:angle_one.size], rtol=0, atol=1e-12)
    assert round(final["helix"], 2) == 0.01
    assert final["planar curl"] == pytest.approx(0.3, abs=1e-3)
    assert final["zigzag"] == pytest.approx(0.3, abs=6e-3)


def test_twist_tools():
    x0 = strands.helix(16, 0.3, 0.01, np.pi / 3)
    seg = np.linalg.norm(np.diff(x0, axis=0), axis=1)
    assert np.allclose(seg, 0.02, rtol=1e-12)
    x = strands.twist(x0, 0.25, 4)
    assert strands.twist_angle(x, x0, 4) == pytest.approx(0.25, rel=1e-12)
    assert np.allclose(np.linalg.norm(np.diff(x, axis=0), axis=1), 0.02)   # a rigid turn
    net = strands.strand_network(x0, 2000.0, 100.0, 50.0)
    assert {k: net.select(k).n_springs for k in ("edge", "bend", "twist")} == {
        "edge": 15, "bend": 14, "twist": 13}
    xs, net_chain = S.hair_chain(**H.STRAND, k_bend=100.0, k_twist=50.0, zigzag=0.3)
    same = strands.strand_network(xs, 2000.0, 100.0, 50.0)
    assert np.array_equal(same.i, net_chain.i) and np.allclose(same.rest, net_chain.rest)
    with pytest.raises(ValueError, match="chord"):
        strands.helix(16, 0.3, radius=0.05, turn=np.pi / 2)


# --- the exercise checks -------------------------------------------------------------------


def _status(name):
    return RESULTS[f"nb08.{name}"]["status"]


def _springs(x0):
    x0 = np.asarray(x0, dtype=float)
    n = len(x0)
    i = np.concatenate([np.arange(n - o) for o in (1, 2, 3)])
    j = np.concatenate([np.arange(o, n) for o in (1, 2, 3)])
    return i, j, np.linalg.norm(x0[i] - x0[j], axis=1)


STEP_RIGHT = """def step_limit(K, mass, pinned, fps):
    d = K.shape[0] // len(mass)
    free = np.setdiff1d(np.arange(len(mass)), pinned)
    rows = (free[:, None] * d + np.arange(d)).ravel()
    scale = 1.0 / np.sqrt(np.repeat(mass, d)[rows])
    lam = np.linalg.eigvalsh(scale[:, None] * K[np.ix_(rows, rows)] * scale[None, :])
    omega = np.sqrt(lam[-1])
    dt = 2.0 / omega
    return omega, dt, int(np.floor(1.0 / (fps * dt))) + 1"""
LOOP_RIGHT = """def hair_frames(x0, spring_forces, mass, pinned, damping, head, frames, substeps, fps):
    center, radius = np.asarray(head[0], dtype=float), head[1]
    g = np.array([0.0, -9.81, 0.0])
    m = np.asarray(mass, dtype=float)[:, None]
    free = np.ones((len(x0), 1))
    free[list(pinned)] = 0.0
    dt = 1.0 / (fps * substeps)
    x = np.array(x0, dtype=float)
    v = np.zeros_like(x)
    out = [x.copy()]
    for step in range(1, frames * substeps + 1):
        force = spring_forces(x) + m * g - damping * v
        v += dt * free * force / m
        x += dt * v
        r = x - center
        dist = np.linalg.norm(r, axis=1, keepdims=True)
        inside = (dist[:, 0] < radius) & (free[:, 0] > 0)
        n = r / dist
        x[inside] = center + radius * n[inside]
        vn = np.sum(v * n, axis=1, keepdims=True)
        v[inside] -= (np.minimum(vn, 0.0) * n)[inside]
        if step % substeps == 0:
            out.append(x.copy())
    return np.array(out)"""
HEAD_BLOCK = """        r = x - center
        dist = np.linalg.norm(r, axis=1, keepdims=True)
        inside = (dist[:, 0] < radius) & (free[:, 0] > 0)
        n = r / dist
        x[inside] = center + radius * n[inside]
        vn = np.sum(v * n, axis=1, keepdims=True)
        v[inside] -= (np.minimum(vn, 0.0) * n)[inside]
"""
KICK_DRIFT = "        v += dt * free * force / m\n        x += dt * v\n"
DRIFT_KICK = "        x += dt * v\n        v += dt * free * force / m\n"
SPRINGS_RIGHT = """def strand_springs(x0):
    x0 = np.asarray(x0, dtype=float)
    n = len(x0)
    i = np.concatenate([np.arange(n - o) for o in (1, 2, 3)])
    j = np.concatenate([np.arange(o, n) for o in (1, 2, 3)])
    return i, j, np.linalg.norm(x0[i] - x0[j], axis=1)"""
SIMULATED = """def step_limit(K, mass, pinned, fps):
    d = K.shape[0] // len(mass)
    free = np.setdiff1d(np.arange(len(mass)), pinned)
    rows = (free[:, None] * d + np.arange(d)).ravel()
    A = K[np.ix_(rows, rows)] / np.repeat(mass, d)[rows][:, None]
    def stable(dt):
        x = 1e-6 * np.ones(len(rows))
        v = np.zeros(len(rows))
        for _ in range(300):
            v = v - dt * (A @ x)
            x = x + dt * v
        return np.abs(x).max() < 1.0
    lo, hi = 1e-7, 1e-1
    for _ in range(60):
        mid = (lo * hi) ** 0.5
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return 2 / lo, lo, int(np.floor(1 / (fps * lo))) + 1"""

PLANTS = [
    Plant("strand_springs", "other", "right", SPRINGS_RIGHT, "correct", ""),
    Plant("strand_springs", "delegating", "cl.strands.strand_network",
          "def strand_springs(x0):\n    net = cl.strands.strand_network(x0, 1.0, 1.0, 1.0)\n"
          "    return net.i, net.j, net.rest", "incorrect", "course_lib.strands.strand_network"),
    Plant("strand_springs", "delegating", "cl.springs.chain_pairs",
          "def strand_springs(x0):\n    n = len(x0)\n"
          "    pairs = [cl.springs.chain_pairs(n, o) for o in (1, 2, 3)]\n"
          "    i = np.concatenate([p[0] for p in pairs])\n    j = np.concatenate([p[1] for p in pairs])\n"
          "    return i, j, np.linalg.norm(x0[i] - x0[j], axis=1)", "incorrect", "uses the reference"),
    Plant("strand_springs", "shortcut", "rest = offset × segment (right only for a straight strand)",
          SPRINGS_RIGHT.replace("np.linalg.norm(x0[i] - x0[j], axis=1)",
                                "np.linalg.norm(x0[1] - x0[0]) * (j - i)"),
          "incorrect", "on a curly strand a bending spring is shorter than two segments"),
    Plant("strand_springs", "misconception", "bending/torsion springs between neighbours",
          "def strand_springs(x0):\n    n = len(x0)\n"
          "    i = np.concatenate([np.arange(n - 1)] + [np.arange(1, n - 1)] + [np.arange(2, n - 1)])\n"
          "    j = i + 1\n    return i, j, np.linalg.norm(x0[i] - x0[j], axis=1)", "incorrect",
          "those are edges again"),
    Plant("strand_springs", "other", "one torsion spring short",
          SPRINGS_RIGHT.replace("np.arange(n - o) for o in (1, 2, 3)",
                                "np.arange(n - o - (o == 3)) for o in (1, 2, 3)")
          .replace("np.arange(o, n) for o in (1, 2, 3)", "np.arange(o, n - (o == 3)) for o in (1, 2, 3)"),
          "incorrect", "the family 3 apart has the wrong count"),
    Plant("strand_springs", "other", "every spring listed twice, (i, j) and (j, i)",
          SPRINGS_RIGHT.replace("    return i, j, np.linalg.norm(", "    i, j = np.r_[i, j], np.r_[j, i]\n"
                                "    return i, j, np.linalg.norm("), "incorrect",
          "you listed some springs twice", avoid="wrong count"),
    Plant("strand_springs", "other", "a wrong rest length shows one spring, not the table",
          SPRINGS_RIGHT.replace("np.linalg.norm(x0[i] - x0[j], axis=1)",
                                "(j - i) * np.linalg.norm(x0[1] - x0[0])"), "incorrect",
          "values differ; the worst, spring (i, j, rest) number", avoid="[[ "),
    Plant("hair_frames", "other", "right", LOOP_RIGHT, "correct", ""),
    Plant("hair_frames", "other", "pinned ignored: particle 0 held only, named in the frames",
          LOOP_RIGHT.replace("free[list(pinned)] = 0.0", "free[0] = 0.0"), "incorrect",
          "the frames: 768 of 1296 values differ; the worst, frame 8, particle 32"),
    Plant("hair_frames", "other", "pinned ignored: the hint under the frames",
          LOOP_RIGHT.replace("free[list(pinned)] = 0.0", "free[0] = 0.0"), "incorrect",
          "only particle 0 is held", avoid="project every free particle"),
    Plant("hair_frames", "other", "head: position only; the gap is printed (rows print alike)",
          LOOP_RIGHT.replace("v[inside] -= (np.minimum(vn, 0.0) * n)[inside]", "pass"),
          "incorrect", "(off by 0.00066 m)"),
    Plant("hair_frames", "delegating", "cl.hair.simulate", LOOP_RIGHT.split("\n")[0] + """
    return cl.hair.simulate(x0, spring_forces.__self__, frames=frames, substeps=substeps,
                            fps=fps, mass=mass, pinned=pinned, damping=damping,
                            post_step=cl.hair.head_collision(*head, pinned=pinned)).frames""",
          "incorrect", "course_lib.hair.simulate"),
    Plant("hair_frames", "delegating", "cl.collisions.sphere for the head",
          LOOP_RIGHT.replace(HEAD_BLOCK, """        head_at = cl.collisions.sphere(center, radius)
        y = head_at(0, np.stack((x, v)))
        keep = free[:, 0] > 0
        x[keep], v[keep] = y[0][keep], y[1][keep]
"""), "incorrect", "uses the reference"),
    Plant("hair_frames", "shortcut", "only the first pinned particle held",
          LOOP_RIGHT.replace("free[list(pinned)] = 0.0", "free[pinned[0]] = 0.0"), "incorrect",
          "only the first particle in pinned is held"),
    Plant("hair_frames", "shortcut", "one mass for all (breaks on the tapered strand)",
          LOOP_RIGHT.replace("m = np.asarray(mass, dtype=float)[:, None]", "m = float(np.mean(mass))"),
          "incorrect", "each particle has its own mass"),
    Plant("hair_frames", "shortcut", "a loop over the particles for the head",
          LOOP_RIGHT.replace(HEAD_BLOCK, """        for p in range(len(x)):
            r = x[p] - center
            dist = np.linalg.norm(r)
            if dist < radius and free[p, 0] > 0:
                n = r / dist
                x[p] = center + radius * n
                v[p] -= min(v[p] @ n, 0.0) * n
"""), "incorrect", "loops over the particles one at a time"),
    Plant("hair_frames", "misconception", "forward Euler (drift before the kick)",
          "import warnings\nwarnings.simplefilter('ignore')\n" + LOOP_RIGHT.replace(KICK_DRIFT, DRIFT_KICK),
          "incorrect", "check the order of the updates"),
    Plant("hair_frames", "other", "forward Euler, second try: named, no code",
          "import warnings\nwarnings.simplefilter('ignore')\n" + LOOP_RIGHT.replace(KICK_DRIFT, DRIFT_KICK),
          "incorrect", "update v from the forces first", avoid="x +=", attempt=1),
    Plant("hair_frames", "other", "no head at all",
          LOOP_RIGHT.replace("inside = (dist[:, 0] < radius) & (free[:, 0] > 0)",
                             "inside = dist[:, 0] < 0"), "incorrect", "end up inside the head"),
    Plant("hair_frames", "other", "projected but the velocity kept",
          LOOP_RIGHT.replace("        v[inside] -= (np.minimum(vn, 0.0) * n)[inside]\n", ""),
          "incorrect", "keeps the velocity that carried it"),
    Plant("hair_frames", "other", "stopped dead on the head",
          LOOP_RIGHT.replace("v[inside] -= (np.minimum(vn, 0.0) * n)[inside]",
                             "v[inside & (vn[:, 0] < 0)] = 0.0"), "incorrect", "stop dead"),
    Plant("hair_frames", "other", "bounces off the head",
          LOOP_RIGHT.replace("v[inside] -= (np.minimum(vn, 0.0) * n)[inside]",
                             "v[inside] -= (2 * np.minimum(vn, 0.0) * n)[inside]"),
          "incorrect", "bounces off"),
    Plant("hair_frames", "other", "no damping",
          LOOP_RIGHT.replace("force = spring_forces(x) + m * g - damping * v",
                             "force = spring_forces(x) + m * g"), "incorrect", "left out the damping"),
    Plant("hair_frames", "other", "every substep returned",
          LOOP_RIGHT.replace("        if step % substeps == 0:\n            out.append(x.copy())",
                             "        out.append(x.copy())"), "incorrect", "keep one state per frame"),
    Plant("step_limit", "other", "right", STEP_RIGHT, "correct", ""),
    Plant("step_limit", "misconception", "the rule of thumb 2√(k/m), k from K's diagonal",
          """def step_limit(K, mass, pinned, fps):
    omega = 2 * np.sqrt(np.max(np.diag(K)) / 2 / np.min(mass))
    dt = 2.0 / omega
    return omega, dt, int(np.floor(1.0 / (fps * dt))) + 1""", "incorrect",
          "% off: an estimate (the rule of thumb"),
    Plant("step_limit", "other", "pinned kept: the step's digits show the difference",
          STEP_RIGHT.replace("free = np.setdiff1d(np.arange(len(mass)), pinned)",
                             "free = np.arange(len(mass))"), "incorrect",
          "apart relative to the size"),
    Plant("step_limit", "other", "pinned kept, second try: escalated",
          STEP_RIGHT.replace("free = np.setdiff1d(np.arange(len(mass)), pinned)",
                             "free = np.arange(len(mass))"), "incorrect",
          "keep the rows p·d ... p·d + d - 1", attempt=1),
    Plant("step_limit", "delegating", "cl.max_stable_dt for the step",
          STEP_RIGHT.replace("dt = 2.0 / omega", "dt = cl.max_stable_dt('symplectic_euler', 1j * omega)"),
          "incorrect", "course_lib.stability.max_stable_dt"),
    Plant("step_limit", "delegating", "scipy.integrate to measure it",
          "import scipy.integrate\n" + STEP_RIGHT.replace(
              "    omega = np.sqrt(lam[-1])",
              "    scipy.integrate.solve_ivp(lambda t, y: -y, (0, 1), [1.0])\n    omega = np.sqrt(lam[-1])"),
          "incorrect", "scipy.integrate"),
    Plant("step_limit", "shortcut", "one mass for all (breaks on the tapered strand)",
          STEP_RIGHT.replace("1.0 / np.sqrt(np.repeat(mass, d)[rows])",
                             "np.full(len(rows), 1.0 / np.sqrt(mass[0]))"), "incorrect",
          "each coordinate has its own mass"),
    Plant("step_limit", "shortcut", "drops particle 0 only (breaks on a clamp and on [15, 0])",
          STEP_RIGHT.replace("rows = (free[:, None] * d + np.arange(d)).ravel()",
                             "rows = np.arange(d, K.shape[0])"), "incorrect",
          "you dropped particle 0 only"),
    Plant("step_limit", "shortcut", "assumes 3D (breaks on the 2D cloth)",
          STEP_RIGHT.replace("d = K.shape[0] // len(mass)", "d = 3"), "incorrect",
          "this network is in 2D"),
    Plant("step_limit", "shortcut", "assumes 3D, rows past the end dropped",
          STEP_RIGHT.replace("d = K.shape[0] // len(mass)", "d = 3").replace(
              "rows = (free[:, None] * d + np.arange(d)).ravel()",
              "rows = (free[:, None] * d + np.arange(d)).ravel()\n"
              "    rows = rows[rows < K.shape[0]]"), "incorrect", "this network is in 2D"),
    Plant("step_limit", "other", "largest eigenvalue in size (breaks on the squeezed strand)",
          STEP_RIGHT.replace("omega = np.sqrt(lam[-1])", "omega = np.sqrt(np.abs(lam).max())"),
          "incorrect", "not the largest in size"),
    Plant("step_limit", "shortcut", "a search by simulation (NumPy only)", SIMULATED, "incorrect",
          "(a simulation or a bisection)"),
    Plant("step_limit", "misconception", "dt = 1 / ω",
          STEP_RIGHT.replace("dt = 2.0 / omega", "dt = 1.0 / omega"),
          "incorrect", "not 1/ω_max"),
    Plant("step_limit", "other", "eigenvalues of K without the masses",
          STEP_RIGHT.replace("scale[:, None] * K[np.ix_(rows, rows)] * scale[None, :]",
                             "K[np.ix_(rows, rows)]"),
          "incorrect", "divide by the masses"),
    Plant("step_limit", "other", "no square root", STEP_RIGHT.replace("np.sqrt(lam[-1])", "lam[-1]"),
          "incorrect", "take the square root"),
    Plant("step_limit", "other", "pinned particles kept",
          STEP_RIGHT.replace("free = np.setdiff1d(np.arange(len(mass)), pinned)",
                             "free = np.arange(len(mass))"), "incorrect", "drop their rows"),
    Plant("step_limit", "other", "pinned rows instead of particles",
          STEP_RIGHT.replace("rows = (free[:, None] * d + np.arange(d)).ravel()",
                             "rows = np.setdiff1d(np.arange(K.shape[0]), pinned)"),
          "incorrect", "each particle owns d rows"),
    Plant("step_limit", "other", "rounds the substeps down",
          STEP_RIGHT.replace("int(np.floor(1.0 / (fps * dt))) + 1", "int(1.0 / (fps * dt))"),
          "incorrect", "round up"),
    Plant("step_limit", "other", "takes the square root of every eigenvalue (NaN when compressed)",
          STEP_RIGHT.replace("omega = np.sqrt(lam[-1])",
                             "with np.errstate(invalid='ignore'):\n        omega = np.sqrt(lam).max()")
          .replace("int(np.floor(1.0 / (fps * dt))) + 1", "np.floor(1.0 / (fps * dt)) + 1"),
          "incorrect", "their square roots are NaN"),
]


_VERDICTS: dict[tuple[str, str, int], dict] = {}


@pytest.mark.parametrize("plant", PLANTS, ids=lambda p: f"{p.exercise}: {p.label}")
def test_planted_answer(plant):
    """Each plant's verdict and hint; two plants of the same answer at the same attempt (the
    pinned mistake: its frames and its hint) share one run of the check."""
    key = (plant.exercise, plant.source, plant.attempt)
    if key not in _VERDICTS:
        _VERDICTS[key] = judge(check, plant)
        return
    verdict = _VERDICTS[key]                     # judge's assertions, on the shared verdict
    failed = "\n".join(verdict["failed_cases"])
    assert verdict["status"] == plant.status, (plant.label, verdict["status"], failed)
    assert plant.says in failed and not (plant.avoid and plant.avoid in failed), (plant.label, failed)
    if plant.kind == "delegating":
        assert verdict["reference"] and "uses the reference" in verdict["reference"], plant.label


def test_every_exercise_has_the_three_kinds_of_plants():
    for exercise in ("strand_springs", "hair_frames", "step_limit"):
        kinds = {p.kind for p in PLANTS if p.exercise == exercise}
        assert {"delegating", "shortcut", "misconception"} <= kinds, exercise


def test_step_limit_check_agrees_with_the_library():
    """The check's limit is the library's max_frequency; on the notebook's strand it is the
    exact formula of section 3, and the substeps are the 149 the prose quotes."""
    from course_lib.check.nb08 import _step_cases, _substeps

    for _, net, x, mass, pinned, fps in _step_cases():
        omega = S.max_frequency(net, x, mass, pinned)
        assert omega > 0
        assert 1.0 / (fps * _substeps(2 / omega, fps)) < 2 / omega
        assert 1.0 / (fps * (_substeps(2 / omega, fps) - 1)) >= 2 / omega
    x0, net = S.hair_chain(**H.STRAND)
    w = S.max_frequency(net, x0, M, [0])
    assert w == pytest.approx(S.chain_max_frequency(15, K, M), rel=1e-12)
    assert _substeps(2 / w, 30.0) == 149


def test_check_strand_springs(capsys):
    check.strand_springs(_springs)
    assert _status("strand_springs") == "correct"

    def shuffled(x0):                     # any order, either orientation
        i, j, rest = _springs(x0)
        order = np.random.default_rng(1).permutation(i.size)
        return j[order], i[order], rest[order].astype(np.float32)

    check.strand_springs(shuffled)
    assert _status("strand_springs") == "correct"
    capsys.readouterr()

    def neighbours(x0):                   # bending written as (i+1, i+2), torsion (i+2, i+3)
        n = len(x0)
        i = np.r_[np.arange(n - 1), np.arange(n - 2) + 1, np.arange(n - 3) + 2]
        return i, i + 1, np.linalg.norm(x0[i] - x0[i + 1], axis=1)

    def straight_rest(x0):                # rest lengths as on a straight strand
        i, j, _ = _springs(x0)
        return i, j, np.linalg.norm(x0[1] - x0[0]) * (j - i)

    def no_torsion(x0):
        n = len(x0)
        i = np.r_[np.arange(n - 1), np.arange(n - 2)]
        j = np.r_[np.arange(1, n), np.arange(2, n)]
        return i, j, np.linalg.norm(x0[i] - x0[j], axis=1)

    def one_too_many(x0):
        n = len(x0)
        i = np.r_[np.arange(n - 1), np.arange(n - 1), np.arange(n - 3)]
        j = np.r_[np.arange(1, n), np.arange(2, n + 1), np.arange(3, n)]
        return i, j, np.ones(i.size)

    for answer, hint in [(neighbours, "join neighbours, e.g. (i+1, i+2)"),
                         (straight_rest, "measure each rest length on the rest shape"),
                         (no_torsion, "the family 3 apart has the wrong count"),
                         (one_too_many, "off by one")]:
        check.strand_springs(answer)
        assert _status("strand_springs") == "incorrect"
        assert hint in capsys.readouterr().out, hint

    def borrowed(x0):
        net = cl.strands.strand_network(x0, 1.0, 1.0, 1.0)
        return net.i, net.j, net.rest

    borrowed.__module__ = "__main__"
    check.strand_springs(borrowed)
    assert "uses the reference" in capsys.readouterr().out

    def pending(x0):
        raise NotImplementedError()

    check.strand_springs(pending)
    assert _status("strand_springs") == "pending"


def test_hanging_strand_stretch():
    strain_formula = 15 * M * 9.81 / (K * 0.02)
    assert strain_formula * 100 == pytest.approx(0.04, abs=0.005)
    x0, net = S.hair_chain(**H.STRAND, direction=(0.0, -1.0, 0.0))
    x = H.static_shape(x0, net, pinned=(0,))
    assert np.max(np.abs(net.strain(x))) == pytest.approx(strain_formula, rel=1e-3)

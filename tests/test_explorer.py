"""The stability explorer: the pure computation, and the view driven through its controls."""

from __future__ import annotations

import io
import warnings

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest
from notebook_helpers import drive_kept_figure
from PIL import Image

import course_lib as cl
from course_lib.lessons import nb03_explorer_view as exv
from course_lib.lessons import nb03_problems
from course_lib.lessons import nb03_stability as ex
from course_lib.plotting import METHOD_LABELS

pytestmark = pytest.mark.roundoff  # numerics: make test repeats it under a second rounding


@pytest.fixture(scope="module")
def view():
    return exv.stability_explorer()


def test_controls_cover_every_method_with_readable_labels(view):
    assert set(view.controls) == {"problem", "method", "dt", "rate"}
    options = view.controls["method"].options
    assert [v for _, v in options] == list(cl.METHODS)
    assert [label for label, _ in options] == [METHOD_LABELS[m] for m in cl.METHODS]
    assert all("_" not in label for label, _ in options)
    assert [v for _, v in view.controls["problem"].options] == ["decay", "oscillator"]
    assert type(view.controls["dt"]).__name__ == "FloatLogSlider"


def test_forward_euler_decay_flips_between_1_9_and_2_1(view):
    view.controls["problem"].value = "decay"
    view.controls["method"].value = "forward_euler"
    view.controls["rate"].value = 1.0
    view.controls["dt"].value = 1.9
    r = view.result
    assert r.stable and r.blowup_step is None and r.verdict.startswith("stable")
    assert r.z == pytest.approx(-1.9) and r.abs_R == pytest.approx(0.9, abs=1e-14)
    assert r.dt_max == pytest.approx(2.0, rel=1e-12)
    assert "stable for dt ≤ 2 s" in r.verdict
    view.controls["dt"].value = 2.1
    r = view.result
    assert not r.stable
    assert r.abs_R == pytest.approx(1.1, abs=1e-14)
    # observed: |x_n| = 1.1^n passes the bound 2 at n = 8 (1.1^7 = 1.95, 1.1^8 = 2.14)
    assert r.blowup_step == 8
    assert "unstable" in r.verdict and "blew up at step 8" in r.verdict
    # the whole run is kept (the log panel shows it): x_n = (-1.1)^n
    assert np.allclose(r.x, (-1.1) ** np.arange(r.t.size), rtol=1e-13)
    # the view rendered the figure to a PNG of the figure's size
    png = Image.open(io.BytesIO(view.image.value))
    assert png.size == tuple(round(v * view.figure.dpi) for v in exv.FIGSIZE)
    assert "blew up at step 8" in view.figure.texts[0].get_text()


def test_view_says_it_is_busy_while_it_computes():
    view = exv.stability_explorer()
    seen = []
    compute = view.compute

    def spy(**params):
        seen.append(view.status.value)
        return compute(**params)

    view.compute = spy
    view.controls["dt"].value = 1.0
    assert seen and "computing" in seen[-1]
    assert view.status.value == ""  # cleared once the picture is up


def test_view_has_a_readable_text_fallback(view):
    bundle = view._repr_mimebundle_()
    assert "application/vnd.jupyter.widget-view+json" in bundle
    assert "VBox" not in bundle["text/plain"] and "kernel" in bundle["text/plain"]


def test_rk4_oscillator_limit_2_sqrt_2(view):
    view.controls["problem"].value = "oscillator"
    view.controls["method"].value = "rk4"
    view.controls["rate"].value = 1.0
    view.controls["dt"].value = 2.8
    r = view.result
    assert r.stable and r.z == pytest.approx(2.8j)
    assert r.dt_max == pytest.approx(2 * np.sqrt(2), rel=1e-10)
    view.controls["dt"].value = 2.9
    r = view.result
    assert not r.stable and r.blowup_step == 4
    theta = 2.9
    assert r.abs_R == pytest.approx(np.sqrt(1 - theta**6 / 72 + theta**8 / 576), rel=1e-12)


def test_rate_scales_the_limit(view):
    view.controls["problem"].value = "decay"
    view.controls["method"].value = "forward_euler"
    view.controls["rate"].value = 4.0
    view.controls["dt"].value = 0.45
    assert view.result.stable and view.result.dt_max == pytest.approx(0.5, rel=1e-12)
    view.controls["dt"].value = 0.55
    assert not view.result.stable
    view.controls["rate"].value = 1.0


def test_symplectic_methods_on_decay_do_not_apply(view):
    view.controls["problem"].value = "decay"
    for method in sorted(cl.NEWTONIAN_METHODS):
        view.controls["method"].value = method
        r = view.result
        assert not r.applicable and not r.stable
        assert "does not apply" in r.verdict and "oscillator" in r.verdict


@pytest.mark.parametrize("method", sorted(cl.NEWTONIAN_METHODS))
def test_symplectic_methods_stable_iff_omega_dt_below_2(method):
    for omega in (1.0, 2.0):
        ok = ex.run_experiment("oscillator", method, dt=1.9 / omega, rate=omega)
        assert ok.stable and ok.blowup_step is None, ok.verdict
        assert ok.abs_R == pytest.approx(1.0, abs=1e-12)
        assert ok.dt_max == pytest.approx(2.0 / omega, rel=1e-10)
        assert f"stable for dt < {2 / omega:g} s" in ok.verdict
        bad = ex.run_experiment("oscillator", method, dt=2.1 / omega, rate=omega)
        assert not bad.stable and bad.blowup_step is not None, bad.verdict


@pytest.mark.parametrize("method", sorted(cl.NEWTONIAN_METHODS))
def test_symplectic_edge_omega_dt_2_is_unstable_linear_growth(method):
    r = ex.run_experiment("oscillator", method, dt=2.0, rate=1.0, t_end=400.0)
    assert not r.stable and "Jordan block" in r.verdict
    assert r.abs_R == pytest.approx(1.0, abs=1e-12)  # |R| = 1, yet unbounded
    M = ex.step_matrix(method, "oscillator", 1.0, 2.0)
    y = ex.linear_run(M, [1.0, 0.5], 200)  # a generic start
    even = y[::2]
    assert np.allclose(np.diff(even, axis=0), even[1] - even[0], rtol=1e-9, atol=1e-9)
    assert np.linalg.norm(y[-1]) > 50 * np.linalg.norm(y[0])
    if method == "symplectic_euler":  # the explorer's own start (1, 0) grows too
        assert r.size[-1] > 50 * r.size[0]
    else:  # (1, 0) is Verlet's one eigenvector there: that run alone stays bounded
        assert np.allclose(r.size, 1.0)
    assert np.allclose(np.linalg.eigvals(M), [-1.0, -1.0], atol=1e-7)
    assert not np.allclose(M, -np.eye(2))  # not diagonal: a Jordan block


def test_forward_euler_never_stable_on_oscillator():
    r = ex.run_experiment("oscillator", "forward_euler", dt=0.1)
    assert not r.stable and r.dt_max == 0.0
    assert r.abs_R == pytest.approx(np.sqrt(1 + 0.1**2), rel=1e-14)
    assert "unstable for every dt" in r.verdict


def test_implicit_methods_have_no_limit():
    r = ex.run_experiment("decay", "backward_euler", dt=8.0, rate=2.0)
    assert r.stable and np.isinf(r.dt_max) and r.abs_R == pytest.approx(1 / 17)
    assert "stable for every dt" in r.verdict
    r = ex.run_experiment("oscillator", "trapezoidal", dt=5.0)
    assert r.stable and np.isinf(r.dt_max) and r.abs_R == pytest.approx(1.0, abs=1e-14)


@pytest.mark.parametrize("method", list(cl.METHODS))
@pytest.mark.parametrize("problem", ["decay", "oscillator"])
def test_step_matrix_run_is_the_integrate_run(problem, method):
    """The fast path (powers of the step matrix) reproduces stepping with integrate."""
    if problem == "decay" and method in cl.NEWTONIAN_METHODS:
        return
    for rate, dt in [(1.0, 0.3), (2.5, 0.9), (0.25, 3.0)]:
        r = ex.run_experiment(problem, method, dt=dt, rate=rate, t_end=40 * dt)
        f, jac = nb03_problems._rhs(problem, rate)
        y0 = np.atleast_1d(ex.exact_solution(problem, rate, 0.0))
        kw = {"jac": jac} if method in cl.IMPLICIT_METHODS else {}
        traj = cl.integrate(f, y0, (0.0, 40 * dt), dt, method, blowup_bound=1e300, **kw)
        ref = traj.y[:, 0] if problem == "decay" else traj.y
        assert np.allclose(r.y, ref, rtol=1e-11, atol=1e-12 * np.max(np.abs(ref)))


@pytest.mark.parametrize("n", [0, 1, 2, 3, 7, 8, 9, 31, 32, 33, 1000])
def test_linear_run_by_doubling_equals_a_loop(n):
    rng = np.random.default_rng(n)
    M = rng.normal(size=(2, 2)) / 1.5
    y0 = rng.normal(size=2)
    loop = [y0]
    for _ in range(n):
        loop.append(M @ loop[-1])
    got = ex.linear_run(M, y0, n)
    assert got.shape == (n + 1, 2)
    scale = np.maximum(np.abs(np.array(loop)).max(axis=1, keepdims=True), 1e-300)
    assert np.allclose(got / scale, np.array(loop) / scale, rtol=0, atol=1e-12)


def test_linear_run_overflow_becomes_nan_after_the_first_inf():
    y = ex.linear_run(np.array([[1e200]]), [1.0], 4)
    assert y[1, 0] == 1e200 and np.isinf(y[2, 0]) and np.all(np.isnan(y[3:, 0]))


def test_run_experiment_never_steps_integrate(monkeypatch):
    """The explorer computes from the step matrix: no Python loop over the run's steps."""
    def forbidden(*args, **kwargs):
        raise AssertionError("run_experiment called integrate")

    monkeypatch.setattr(cl, "integrate", forbidden)
    monkeypatch.setattr(cl.integrators, "integrate", forbidden)
    r = ex.run_experiment("oscillator", "trapezoidal", dt=0.01, rate=0.25)
    assert r.t.size == round(ex.default_t_end("oscillator", 0.25) / 0.01) + 1


def test_long_runs_are_thinned_for_drawing():
    plot = exv.ExperimentPlot()
    plot(ex.run_experiment("oscillator", "velocity_verlet", dt=0.01, rate=0.25))
    assert len(plot.num_line.get_xdata()) <= exv.MAX_DRAWN
    assert len(plot.size_line.get_xdata()) <= exv.MAX_DRAWN + 1


@pytest.mark.parametrize("method", list(cl.METHODS))
@pytest.mark.parametrize("problem", ["decay", "oscillator"])
def test_small_step_matches_exact_solution(problem, method):
    r = ex.run_experiment(problem, method, dt=0.01, rate=1.0, t_end=2.0)
    if not r.applicable:
        return
    exact = ex.exact_solution(problem, 1.0, r.t)
    tol = 2e-2 if cl.ORDER[method] == 1 else 1e-4
    assert np.max(np.abs(r.y - exact)) < tol
    assert r.blowup_step is None


@pytest.mark.parametrize("method", list(cl.METHODS))
@pytest.mark.parametrize("problem", ["decay", "oscillator"])
@pytest.mark.parametrize("dt", [0.1, 1.0, 1.99, 2.0, 2.01, 2.9, 10.0])
def test_verdict_is_theory_and_never_warns(problem, method, dt):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = ex.run_experiment(problem, method, dt=dt)
    if not r.applicable:
        return
    edge = method in cl.NEWTONIAN_METHODS and dt >= 2.0
    assert r.stable == (bool(cl.is_stable(method, r.z)) and not edge)
    if r.stable:  # a stable run never passes the bound
        assert r.blowup_step is None


def test_draw_static_figure_has_labelled_panels():
    import matplotlib.pyplot as plt

    fig = exv.draw_experiment(ex.run_experiment("decay", "forward_euler", 2.1))
    ax_t, ax_n, ax_z = fig.axes
    assert ax_t.get_xlabel() == "time t (s)" and "Re z" in ax_z.get_xlabel()
    assert ax_n.get_yscale() == "log" and ax_n.get_xlabel() == "step n"
    assert ax_z.get_aspect() == 1.0
    plt.close(fig)


def test_blitted_picture_matches_a_full_redraw():
    fast, full = exv.ExperimentPlot(blit=True), exv.ExperimentPlot(snap=True)
    for args in [("decay", "forward_euler", 2.1), ("oscillator", "rk4", 2.9),
                 ("oscillator", "velocity_verlet", 1.0), ("decay", "rk4", 0.5)]:
        r = ex.run_experiment(*args)
        fast(r)
        full(r)
        a = np.asarray(Image.open(io.BytesIO(fast.png()))).astype(int)
        b = np.asarray(Image.open(io.BytesIO(full.png()))).astype(int)
        assert a.shape == b.shape
        assert np.mean(np.any(a != b, axis=-1)) < 2e-3  # antialiasing at a few edges only


def test_nice_limits_contain_the_data_at_round_values():
    from course_lib.widgets import nice_limits

    rng = np.random.default_rng(2026)
    for lo, span in zip(rng.uniform(-50, 50, 200), 10 ** rng.uniform(-6, 4, 200), strict=True):
        a, b = nice_limits(lo, lo + span)
        assert a <= lo and b >= lo + span and b - a <= 3 * span      # contains, not far off
        a, b = nice_limits(span, 7 * span, log=True)
        assert a <= span and b >= 7 * span and b <= 100 * span
        assert np.log10(a) == pytest.approx(round(np.log10(a)), abs=1e-9)  # whole decades
    # kept while they hold the data and are not too wide; replaced otherwise
    assert nice_limits(0.1, 0.9, keep=(0.0, 1.0)) == (0.0, 1.0)
    assert nice_limits(0.1, 1.1, keep=(0.0, 1.0)) != (0.0, 1.0)
    assert nice_limits(0.45, 0.55, keep=(0.0, 1.0)) != (0.0, 1.0)
    assert nice_limits(3e-6, 0.5, log=True, keep=(1e-6, 1.0)) == (1e-6, 1.0)
    assert nice_limits(3e-4, 0.5, log=True, keep=(1e-6, 1.0)) == (1e-4, 1.0)


def test_png_of_decodes_to_the_canvas_exactly():
    from course_lib.plotting import detached_figure
    from course_lib.widgets import png_of

    fig = detached_figure((3.1, 2.3))                  # odd pixel sizes
    ax = fig.subplots()
    ax.imshow(np.random.default_rng(2026).random((20, 30, 4)))     # varied, translucent
    ax.set_title("a title", color="red")
    fig.canvas.draw()
    png = png_of(fig)
    image = Image.open(io.BytesIO(png))
    assert image.format == "PNG" and image.mode == "RGBA"
    assert np.array_equal(np.asarray(image), np.asarray(fig.canvas.buffer_rgba()))
    pillow = io.BytesIO()
    image.save(pillow, format="png", compress_level=1)
    assert len(png) < 1.5 * len(pillow.getvalue())     # compressed about as well


def test_widget_keeps_its_background_over_small_steps_and_redraws_when_limits_change():
    """Driven through the slider: the kept background is reused over small changes of dt,
    redrawn when a limit changes, and every picture equals a full redraw of the figure;
    the panels' limits hold the run."""
    view = exv.stability_explorer()
    redrawn = []
    moves = [("dt", dt) for dt in (0.505, 0.51, 0.515, 0.52, 1.9, 2.1, 0.02)]
    for _, _, r, fresh in drive_kept_figure(view, moves):
        redrawn.append(fresh)
        ax_t, ax_n = view.draw.ax_t, view.draw.ax_n
        assert ax_t.get_xlim()[1] >= r.t_end and ax_n.get_xlim()[1] >= r.size.size - 1
        lo, hi = ax_n.get_ylim()
        shown = r.size[: (r.blowup_step or r.size.size - 1) + 1]
        assert lo <= shown.min() and hi >= shown.max()
    assert sum(redrawn) <= 3  # 0.505 ... 0.52 reuse the background


def test_bad_choices_raise():
    with pytest.raises(ValueError, match="problem"):
        ex.run_experiment("spring")
    with pytest.raises(ValueError, match="method"):
        ex.run_experiment("decay", "euler")
    with pytest.raises(ValueError, match="dt"):
        ex.run_experiment("decay", "rk4", dt=-1.0)
    with pytest.raises(ValueError, match="t_end"):
        ex.run_experiment("decay", "rk4", dt=1e-3, t_end=1e4)

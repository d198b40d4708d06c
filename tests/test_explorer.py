"""The stability explorer: the pure computation, and the view driven through its controls."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import warnings

import numpy as np
import pytest

import course_lib as cl
from course_lib.lessons import nb03_explorer_view as exv
from course_lib.lessons import nb03_stability as ex


@pytest.fixture(scope="module")
def view():
    return exv.stability_explorer()


def test_controls_cover_every_method_and_both_problems(view):
    assert set(view.controls) == {"problem", "method", "dt", "rate"}
    assert [v for _, v in view.controls["method"].options] == list(cl.METHODS)
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
    view.controls["dt"].value = 2.1
    r = view.result
    assert not r.stable
    assert r.abs_R == pytest.approx(1.1, abs=1e-14)
    # observed: |x_n| = 1.1^n passes the bound 2 at n = 8 (1.1^7 = 1.95, 1.1^8 = 2.14)
    assert r.blowup_step == 8
    assert "unstable" in r.verdict and "blew up at step 8" in r.verdict
    # the run is drawn on past the marker (it grows by -1.1 per step over the whole window)
    assert np.allclose(r.x, (-1.1) ** np.arange(r.t.size))
    # the view really drew the figure (off-screen, with Agg)
    assert type(view.figure.canvas).__name__ == "FigureCanvasAgg"
    height, width = np.asarray(view.figure.canvas.buffer_rgba()).shape[:2]
    assert (width, height) == tuple(round(v * view.figure.dpi) for v in exv.FIGSIZE)
    assert "blew up at step 8" in view.figure.texts[0].get_text()


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
    assert not r.stable and r.blowup_step is not None
    assert r.t[r.blowup_step] <= r.t_end
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
def test_symplectic_methods_on_oscillator_stable_iff_omega_dt_le_2(method):
    for omega in (1.0, 2.0):
        ok = ex.run_experiment("oscillator", method, dt=1.9 / omega, rate=omega)
        assert ok.stable and ok.blowup_step is None, ok.verdict
        assert ok.abs_R == pytest.approx(1.0, abs=1e-12)
        assert ok.dt_max == pytest.approx(2.0 / omega, rel=1e-10)
        bad = ex.run_experiment("oscillator", method, dt=2.1 / omega, rate=omega)
        assert not bad.stable and bad.blowup_step is not None, bad.verdict


def test_forward_euler_never_stable_on_oscillator():
    r = ex.run_experiment("oscillator", "forward_euler", dt=0.1)
    assert not r.stable and r.dt_max == 0.0
    assert r.abs_R == pytest.approx(np.sqrt(1 + 0.1**2), rel=1e-14)
    assert "unstable for every dt" in r.verdict


def test_implicit_methods_have_no_limit():
    r = ex.run_experiment("decay", "backward_euler", dt=8.0, rate=2.0)
    assert r.stable and np.isinf(r.dt_max) and r.abs_R == pytest.approx(1 / 17)
    r = ex.run_experiment("oscillator", "trapezoidal", dt=5.0)
    assert r.stable and np.isinf(r.dt_max) and r.abs_R == pytest.approx(1.0, abs=1e-14)


@pytest.mark.parametrize("method", [m for m in cl.METHODS])
@pytest.mark.parametrize("problem", ["decay", "oscillator"])
def test_small_step_matches_exact_solution(problem, method):
    r = ex.run_experiment(problem, method, dt=0.01, rate=1.0, t_end=2.0)
    if not r.applicable:
        return
    exact = ex.exact_solution(problem, 1.0, r.t)
    tol = 2e-2 if cl.ORDER[method] == 1 else 1e-4
    assert np.max(np.abs(r.y - exact)) < tol
    # the theory verdict and the observation agree on whether anything blew up
    assert r.blowup_step is None


@pytest.mark.parametrize("method", list(cl.METHODS))
@pytest.mark.parametrize("problem", ["decay", "oscillator"])
@pytest.mark.parametrize("dt", [0.1, 1.0, 1.99, 2.01, 2.9, 10.0])
def test_verdict_is_theory_and_never_warns(problem, method, dt):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = ex.run_experiment(problem, method, dt=dt)
    if not r.applicable:
        return
    assert r.stable == bool(cl.is_stable(method, r.z))
    if r.stable:  # a stable run never passes the bound
        assert r.blowup_step is None


def test_draw_static_figure_has_labelled_equal_aspect_plane():
    import matplotlib.pyplot as plt

    fig = exv.draw_experiment(ex.run_experiment("decay", "forward_euler", 2.1))
    ax_t, ax_z = fig.axes
    assert ax_t.get_xlabel() == "time t (s)" and "Re z" in ax_z.get_xlabel()
    assert ax_z.get_aspect() == 1.0
    plt.close(fig)


def test_bad_choices_raise():
    with pytest.raises(ValueError, match="problem"):
        ex.run_experiment("spring")
    with pytest.raises(ValueError, match="method"):
        ex.run_experiment("decay", "euler")
    with pytest.raises(ValueError, match="dt"):
        ex.run_experiment("decay", "rk4", dt=-1.0)


def test_fast_blowup_is_drawn_until_far_past_the_bound():
    r = ex.run_experiment("decay", "forward_euler", dt=10.0, rate=1.0, t_end=100.0)
    assert not r.stable and r.blowup_step == 1          # |R| = 9: past 2 after one step
    assert np.allclose(r.x[:3], [1.0, -9.0, 81.0])      # 81 > 20 * 2: the last point drawn
    assert np.all(np.isnan(r.x[3:]))

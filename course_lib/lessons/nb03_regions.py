"""Notebook 03 (stability): stability regions and growth plots, drawn with matplotlib.

- :func:`region_grid` evaluates ``|R(z)|`` on a grid of the complex plane (cached);
- :func:`draw_region` shades a method's stable set ``|R(z)| <= 1`` on an axes (for the
  symplectic methods, whose stable set is the open segment ``(-2i, 2i)``, a thick line);
- :func:`draw_region_panels` draws several methods' regions in a grid of panels, with
  marked points and their verdicts; :func:`zoom_inset` magnifies one point of a panel;
- :func:`draw_growth` plots the size of runs against the step number on a logarithmic
  axis, where ``|R|^n`` is a straight line and an unstable run stays visible.

Imports the core (stability), the lesson's computation
(:mod:`~course_lib.lessons.nb03_stability`) and the view helpers of
:mod:`course_lib.plotting`.
"""

from __future__ import annotations

import functools

import matplotlib.pyplot as plt
import numpy as np

from ..integrators import NEWTONIAN_METHODS
from ..plotting import EXACT_STYLE, METHOD_COLORS
from ..stability import amplification_factor
from .nb03_stability import theory_stable, unit_dt_max

#: Window of the complex plane shown for a region (Re z, Im z limits).
REGION_WINDOW = (-5.0, 3.0, -3.5, 3.5)


@functools.lru_cache(maxsize=16)
def region_grid(method: str, window: tuple = REGION_WINDOW, n: int = 241):
    """``(re, im, |R|)`` of ``method`` on an ``n × n`` grid of the complex plane (cached)."""
    re = np.linspace(window[0], window[1], n)
    im = np.linspace(window[2], window[3], n)
    Z = re[None, :] + 1j * im[:, None]
    absR = np.abs(amplification_factor(method, Z))
    absR.setflags(write=False)
    return re, im, absR


def draw_region(
    ax, method: str, window: tuple = REGION_WINDOW, *, label: bool = True, decorate: bool = True
) -> list:
    """Shade ``|R(z)| <= 1`` of ``method`` on ``ax`` (equal aspect, labelled axes).

    The symplectic methods' stable set (for ``x'' = λ² x``) is the open segment
    ``(-2i, 2i)`` of the imaginary axis, which has no area: it is drawn as a thick line
    with open circles at its excluded ends. ``decorate=False`` draws the region only (no
    axis lines, limits or labels). Returns the artists drawn for the region.
    """
    color = METHOD_COLORS[method]
    before = set(ax.get_children())
    if method in NEWTONIAN_METHODS:
        half = unit_dt_max(method, "oscillator")
        ax.plot([0, 0], [-half, half], color=color, lw=5, solid_capstyle="butt",
                label="stable: open segment |Im z| < 2" if label else None)
        ax.plot([0, 0], [-half, half], "o", ms=8, mfc="white", mec=color, mew=2)
    else:
        re, im, absR = region_grid(method, window)
        ax.contourf(re, im, absR, levels=[0.0, 1.0], colors=[color], alpha=0.3)
        ax.contour(re, im, absR, levels=[1.0], colors=[color], linewidths=1.5)
        if label:
            ax.fill([], [], color=color, alpha=0.3, label="|R| ≤ 1")
    artists = [a for a in ax.get_children() if a not in before]
    if decorate:
        ax.axhline(0, color="0.4", lw=0.8)
        ax.axvline(0, color="0.4", lw=0.8)
        ax.set_xlim(window[0], window[1])
        ax.set_ylim(window[2], window[3])
        ax.set_aspect("equal")
        ax.set_xlabel("Re z")
        ax.set_ylabel("Im z")
    return artists


def zoom_inset(ax, method: str, z: complex, half: float = 0.03,
               bounds=(0.64, 0.04, 0.34, 0.4), marker: str = "*"):
    """An inset in ``ax``: ``method``'s region within ``half`` of the point ``z``, marked,
    where the whole plane cannot show which side of the boundary ``z`` lies on (the
    midpoint's region meets the imaginary axis only at 0, but hugs it)."""
    z = complex(z)
    window = (z.real - half, z.real + half, z.imag - half, z.imag + half)
    inset = ax.inset_axes(bounds)
    draw_region(inset, method, window, label=False, decorate=False)
    inset.axvline(0, color="0.4", lw=0.8)
    inset.plot(z.real, z.imag, marker, color="black", ms=9)
    inset.set(xlim=window[:2], ylim=window[2:], xticks=[z.real - half / 2, z.real],
              xticklabels=[f"{z.real - half / 2:g}", f"{z.real:g}"], yticks=[], aspect="equal")
    inset.tick_params(labelsize=7, pad=1)
    for spine in inset.spines.values():  # a closed frame, whatever the course style hides
        spine.set_visible(True)
    inset.text(0.5, 0.97, f"|R({_fmt_point(z)})|\n= {abs(amplification_factor(method, z)):.4f}",
               transform=inset.transAxes, ha="center", va="top", fontsize=7,
               bbox={"facecolor": "white", "alpha": 0.85, "edgecolor": "none", "pad": 1})
    ax.indicate_inset_zoom(inset, edgecolor="0.3")
    return inset


def _fmt_point(z: complex) -> str:
    return f"{z.imag:g}i" if z.real == 0 else f"{z:g}"


def draw_region_panels(methods, titles: dict, marks: dict, ncols: int = 3):
    """One panel per method, ``ncols`` to a row, with the points ``marks`` and verdicts.

    Parameters
    ----------
    methods : sequence of str
        Methods to draw, in reading order.
    titles : dict
        ``method -> title`` of its panel.
    marks : dict
        ``z -> (marker, short name, legend label)``: points of the plane to mark. The
        verdict of each point (stable / unstable / does not apply) is written in the panel.

    Returns
    -------
    matplotlib.figure.Figure
    """
    nrows = -(-len(methods) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(3.7 * ncols, 3.55 * nrows + 0.6),
                             sharex=True, sharey=True, squeeze=False)
    for ax, method in zip(axes.flat, methods, strict=False):
        draw_region(ax, method, label=False)
        verdicts = []
        for z, (marker, short, legend) in marks.items():
            z = complex(z)
            if method in NEWTONIAN_METHODS and z.real != 0:
                verdicts.append(f"{short}: does not apply")
                continue
            ax.plot(z.real, z.imag, marker, color="black", ms=9, label=legend)
            verdicts.append(f"{short}: {'stable' if theory_stable(method, z) else 'unstable'}")
        ax.text(0.03, 0.97, "\n".join(verdicts), transform=ax.transAxes, va="top", fontsize=9,
                bbox={"facecolor": "white", "alpha": 0.85, "edgecolor": "0.7"})
        ax.set_title(titles[method], fontsize=10)
        ax.label_outer()
    for ax in axes.flat[len(methods):]:
        ax.set_visible(False)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=10)
    fig.subplots_adjust(left=0.07, right=0.99, bottom=0.11, top=0.9, wspace=0.08, hspace=0.22)
    return fig


def draw_growth(ax, runs, *, exact=None, bound: float | None = None) -> None:
    """Plot ``|y_n|`` against the step ``n`` on a log axis, one line per run.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    runs : sequence of (label, color, marker, sizes)
        ``sizes`` of shape ``(n+1,)``: the size of each state (NaN after an overflow).
    exact : (label, steps, sizes), optional
        A reference curve, drawn in the exact style.
    bound : float, optional
        A blow-up bound, drawn as a dotted horizontal line.
    """
    for label, color, marker, sizes in runs:
        sizes = np.asarray(sizes, dtype=float)
        ax.semilogy(np.arange(sizes.size), sizes, marker=marker, ms=4, lw=1.2, color=color,
                    label=label)
    if exact is not None:
        label, steps, sizes = exact
        ax.semilogy(steps, sizes, **EXACT_STYLE, label=label)
    if bound is not None:
        ax.axhline(bound, color="0.45", ls=":", lw=1.2, label=f"blow-up bound {bound:g}")
    ax.set_xlabel("step n")
    ax.set_ylabel("size |y_n| (log scale)")

"""The count half of notebook 09's emit check: how a Reeves count y = mean + variance × U,
U ~ U(-1, 1), is made a whole number, and the hints for a wrong count.

Rounding y at random, ⌊y + u⌋ with u ~ U(0, 1), keeps the mean exact for every emitter.
Rounding to the nearest is unbiased only when the fractional part of y is spread evenly, as
it is when 2 × variance is a whole number; :data:`ROUNDING_EMITTER` (3.35 ± 0.3, y in
[3.05, 3.65]) is not, so that it rounds down three times in four and its mean is 3.25.
:func:`rounded_mean` gives the exact mean of each deterministic rounding (down, nearest,
up) of a uniform y, :func:`random_rounding_variance` the exact variance of the right
count, from which the check's tolerance is derived; :func:`rounding_rule` names the
rounding that a set of measured means shows. :func:`count_variance_hint` and
:func:`range_hint` name a wrong spread of the count.
"""

from __future__ import annotations

import numpy as np

from . import Hint
from . import _nb09_cases as _cases
from .tolerance import escalate

#: (mean count, variance, radius in m) of the emitter whose 2 × variance is not whole.
ROUNDING_EMITTER = (3.35, 0.3, 1.0)

#: Standard errors by which a mean count may miss: a right answer misses by more in about
#: 6e-7 of runs (two-sided normal tail); rounding to the nearest misses by 13 on
#: :data:`ROUNDING_EMITTER` over 4000 frames.
ROUNDING_Z = 5.0


def _floor_integral(x: float) -> float:
    """∫₀ˣ ⌊t⌋ dt."""
    f = np.floor(x)
    return float(f * (x - f) + f * (f - 1) / 2)


def rounded_mean(lo: float, hi: float, rule: str) -> float:
    """Exact E[rule(y)] for y uniform on [lo, hi] (``lo < hi``), with ``rule`` one of
    ``"down"`` (⌊y⌋, also int() for y ≥ 0), ``"nearest"`` (⌊y + ½⌋) or ``"up"`` (⌈y⌉)."""
    if rule == "down":
        return (_floor_integral(hi) - _floor_integral(lo)) / (hi - lo)
    if rule == "nearest":
        return rounded_mean(lo + 0.5, hi + 0.5, "down")
    if rule == "up":
        return -rounded_mean(-hi, -lo, "down")
    raise ValueError(f"rule must be 'down', 'nearest' or 'up', got {rule!r}")


def random_rounding_variance(lo: float, hi: float) -> float:
    """Exact variance of ⌊y + u⌋ for y uniform on [lo, hi] and u ~ U(0, 1): the variance
    of y plus E[φ(1 - φ)], φ the fractional part of y (the count is y plus a rounding of
    mean zero and variance φ(1 - φ) given y)."""
    def square_integral(x):                       # ∫₀ˣ φ(t)² dt
        f = np.floor(x)
        return float(f / 3 + (x - f) ** 3 / 3)
    phi = (lo + hi) / 2 - rounded_mean(lo, hi, "down")
    phi2 = (square_integral(hi) - square_integral(lo)) / (hi - lo)
    return (hi - lo) ** 2 / 12 + phi - phi2


_FIX = ("round at random, floor(y + u) with u ~ U(0, 1) (u = rng.random()): it rounds y up "
        "with a probability equal to its fractional part, so the mean stays exact")
_M, _V, _ = ROUNDING_EMITTER
_DOWN = (np.floor(_M) + 0.5 - (_M - _V)) / (2 * _V)      # P(y rounds down): 0.75 for 3.35 ± 0.3

#: The hint for each deterministic rounding: a nudge that names it, then the fix.
ROUNDING_HINTS = {
    "nearest": escalate(
        "rounding to the nearest whole number (round, np.round) biases the mean count when 2 × "
        f"variance is not whole: {_M:g} ± {_V:g} rounds down {_DOWN:.0%} of the time, a mean of "
        f"{rounded_mean(_M - _V, _M + _V, 'nearest'):g}; round at random instead",
        f"it is unbiased only when y's fractional part is spread evenly; {_FIX}"),
    "down": escalate(
        "int() truncates and np.floor rounds down: the count loses a fraction of a particle every "
        "frame, half of one on average",
        _FIX),
    "up": escalate(
        "np.ceil rounds up: the count gains a fraction of a particle every frame, half of one on "
        "average", _FIX),
}

#: The hint for a mean count that is off only on :data:`ROUNDING_EMITTER`, by no known rule.
ROUNDING_GENERIC = escalate("the mean count is off when 2 × variance is not a whole number: how "
                            "is y made a whole number?", _FIX)


def rounding_rule(means, emitters, se) -> str | None:
    """The deterministic rounding (``"down"``, ``"nearest"``, ``"up"``) whose exact mean
    every measured mean in ``means`` matches within :data:`ROUNDING_Z` of its standard error
    ``se``, for the ``emitters`` (mean, variance, radius) drawn; None if none or several."""
    found = [rule for rule in ROUNDING_HINTS
             if all(abs(c - rounded_mean(m - v, m + v, rule)) < ROUNDING_Z * s
                    for c, (m, v, _), s in zip(means, emitters, se, strict=True))]
    return found[0] if len(found) == 1 else None


def rounding_case(counts) -> tuple[bool, str, str | None]:
    """(right, detail, rule) of the mean of ``counts`` drawn from :data:`ROUNDING_EMITTER`:
    right if within :data:`ROUNDING_Z` standard errors of its exact mean, and the rounding
    that it shows (see :func:`rounding_rule`), if any."""
    m, v, _ = ROUNDING_EMITTER
    se = np.sqrt(random_rounding_variance(m - v, m + v) / counts.size)
    right = abs(counts.mean() - m) < ROUNDING_Z * se
    rule = rounding_rule([counts.mean()], [ROUNDING_EMITTER], [se])
    detail = (f"over {counts.size} frames of {m:g} ± {v:g} the mean count was {counts.mean():.3f} "
              f"(standard error {se:.3f})")
    return bool(right), detail, rule


def count_variance_hint(draws) -> Hint:
    """Name the spread a wrong count rule has, if every emitter shows the same one: counts
    that vary as variance/2 × U(-1, 1) (a halved spread), √variance × U(-1, 1) (Reeves'
    variance read as the statistical variance) or not at all. Rounding to a whole count adds
    up to 1/6 to the variance of each."""
    if all(counts.std() < 0.3 * v / np.sqrt(3) for (_, v, _), counts, _ in draws):
        return escalate("the count hardly varies: is a new random number drawn every frame?",
                        "draw a new count every frame: mean + variance × rng.uniform(-1, 1)")
    rules = {
        escalate("rng.random() spans [0, 1), half of U(-1, 1): the spread is halved",
                 "mean + variance × U(-1, 1) with U = rng.uniform(-1, 1): a spread of the whole width"):
            lambda v: v * v / 12,
        escalate("Reeves' variance is the half-width of the spread, not the statistical variance: do not "
                 "take its square root", "mean + variance × U(-1, 1): the count's standard deviation is "
                 "then variance/√3"): lambda v: v / 3,
    }
    for hint, spread in rules.items():
        if all(0.8 * spread(v) <= counts.var() <= 1.2 * (spread(v) + 1 / 6)
               for (_, v, _), counts, _ in draws):
            return hint
    if all(_cases.flat(counts) for _, counts, _ in draws):
        return _cases.WIDTH_HINT
    if all(counts.std() > v / np.sqrt(3) * 1.1 for (_, v, _), counts, _ in draws):
        return "the spread is uniform, variance × U(-1, 1), with standard deviation variance/√3"
    return None


def range_hint(outside) -> Hint:
    """The hint for counts outside [mean - variance, mean + variance]: a uniform draw of the
    wrong width, or an unbounded (normal) draw."""
    if outside and all(_cases.flat(c) for c in outside):
        return _cases.WIDTH_HINT
    return escalate("Reeves' count is never outside [mean - variance, mean + variance]: is your "
                    "random number bounded?",
                    "Reeves' count is mean + variance × U(-1, 1) with U uniform (rng.uniform(-1, 1)), "
                    "not a normal draw: it never leaves [mean - variance, mean + variance]")

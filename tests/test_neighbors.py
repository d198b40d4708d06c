"""course_lib.neighbors: the k-d tree and the all-pairs reference agree on every
configuration (hypothesis), and both agree with the definition computed independently."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from course_lib import neighbors as nb


def _same(a: nb.Pairs, b: nb.Pairs) -> None:
    assert np.array_equal(a.i, b.i) and np.array_equal(a.j, b.j)
    assert np.array_equal(a.offset, b.offset) and np.array_equal(a.distance, b.distance)


def _by_images(x, radius, box):
    """Pairs from the geometric definition, independently: the nearest of all images
    (3^dim shifts by whole boxes), distances by math.dist. Returns {(i, j): distance}."""
    import math
    n, dim = x.shape
    shifts = [np.zeros(dim)] if box is None else [np.array(s) * box
                                                   for s in itertools.product((-1, 0, 1), repeat=dim)]
    w = x if box is None else np.mod(x, box)
    out = {}
    for i in range(n):
        for j in range(i + 1, n):
            out[i, j] = min(math.dist(w[i], w[j] + s) for s in shifts)
    return out


@st.composite
def configurations(draw):
    """Points chosen to hit the edge cases: a lattice of spacing radius/2 (pairs at exactly
    the radius), coincident points, coordinates just inside and outside a periodic box,
    coordinates many boxes away, and plain random ones."""
    dim = draw(st.integers(1, 3))
    radius = draw(st.sampled_from([0.3, 1.0, 1.5, 2.0 / 3.0]))
    box = draw(st.one_of(st.none(), st.sampled_from([3.1, 4.0, 10.0, 7.3])))
    side = 10.0 if box is None else box
    edge = [0.0, -0.0, side, -side, side - 1e-12, 1e-300, -1e-300, 5e-324,
            np.nextafter(side, 0.0), np.nextafter(0.0, -1.0), 1e6 * side, -3.0 * side]
    coordinate = st.one_of(
        st.floats(-side, 2 * side, allow_nan=False, allow_infinity=False),
        st.integers(-8, 24).map(lambda k: k * radius / 2),
        st.sampled_from(edge),
    )
    n = draw(st.integers(0, 24))
    x = np.array(draw(st.lists(st.lists(coordinate, min_size=dim, max_size=dim),
                               min_size=n, max_size=n)), dtype=float).reshape(n, dim)
    if n > 2 and draw(st.booleans()):
        x[1] = x[0]                                            # coincident points
    return x, radius, box


@pytest.mark.roundoff
@settings(max_examples=120, deadline=None)  # make fuzz: x10
@given(configurations())
def test_the_tree_and_all_pairs_agree_on_every_configuration(case):
    x, radius, box = case
    tree, ref = nb.pairs(x, radius, box), nb.all_pairs(x, radius, box)
    _same(tree, ref)
    assert np.all(tree.i < tree.j)
    assert np.all(tree.distance <= radius)
    # the definition, computed another way: sure pairs are in, sure non-pairs out
    truth = _by_images(x, radius, box)
    found = set(zip(tree.i.tolist(), tree.j.tolist(), strict=True))
    slack = 1e-9 * (radius + (box or 0.0))
    for key, dist in truth.items():
        if dist < radius - slack:
            assert key in found, (key, dist)
        elif dist > radius + slack:
            assert key not in found, (key, dist)
    for k, key in enumerate(zip(tree.i.tolist(), tree.j.tolist(), strict=True)):
        assert tree.distance[k] == pytest.approx(truth[key], abs=slack)


def test_pairs_across_the_border_of_the_box():
    # 0.3 m apart through the border; a point a whole box away counts as its own image
    x = np.array([[0.2, 5.0], [9.9, 5.0], [10.2, 15.0], [-0.1, 5.0]])
    p = nb.pairs(x, 1.0, 10.0)
    assert list(zip(p.i.tolist(), p.j.tolist(), strict=True)) == [(0, 1), (0, 2), (0, 3),
                                                                 (1, 2), (1, 3), (2, 3)]
    assert np.allclose(p.offset[0], [-0.3, 0.0]) and np.allclose(p.distance[0], 0.3)
    assert np.allclose(p.offset[1], [0.0, 0.0], atol=1e-14)   # x2 is x0 shifted by (10, 10)
    _same(p, nb.all_pairs(x, 1.0, 10.0))
    far = nb.pairs(x, 1.0)                                     # open space: only 0 and 3
    assert far.i.tolist() == [0] and far.j.tolist() == [3]


def test_a_pair_at_exactly_the_radius_is_in_and_one_ulp_beyond_is_out():
    x = np.array([[0.0, 0.0], [3.0, 4.0], [3.0, np.nextafter(4.0, 5.0)]])
    for search in (nb.pairs, nb.all_pairs):
        p = search(x, 5.0)
        assert (0, 1) in set(zip(p.i.tolist(), p.j.tolist(), strict=True))
        assert (0, 2) not in set(zip(p.i.tolist(), p.j.tolist(), strict=True))


def test_per_axis_box_and_large_sets_in_blocks(monkeypatch):
    rng = np.random.default_rng(4)
    box = np.array([6.0, 9.0, 4.5])
    x = rng.uniform(-10, 20, (700, 3))
    monkeypatch.setattr(nb, "BLOCK_ENTRIES", 5_000)           # many blocks of rows
    tree, ref = nb.pairs(x, 1.1, box), nb.all_pairs(x, 1.1, box)
    _same(tree, ref)
    assert len(tree) > 1000
    unsorted = nb.pairs(x, 1.1, box, sort=False)
    order = np.lexsort((unsorted.j, unsorted.i))
    assert np.array_equal(unsorted.i[order], tree.i) and np.array_equal(unsorted.j[order], tree.j)


def test_bad_input_names_the_argument():
    with pytest.raises(ValueError, match="x must have shape"):
        nb.pairs(np.zeros(3), 1.0)
    with pytest.raises(ValueError, match="finite"):
        nb.pairs([[0.0, np.nan], [1.0, 1.0]], 1.0)
    with pytest.raises(ValueError, match="radius"):
        nb.pairs(np.zeros((2, 2)), 0.0)
    with pytest.raises(ValueError, match="radius"):
        nb.all_pairs(np.zeros((2, 2)), 1e200)
    with pytest.raises(TypeError, match="radius"):
        nb.pairs(np.zeros((2, 2)), "one")
    with pytest.raises(ValueError, match="box"):
        nb.pairs(np.zeros((2, 2)), 1.0, box=2.0)
    with pytest.raises(ValueError, match="box"):
        nb.pairs(np.zeros((2, 2)), 1.0, box=[3.0, 3.0, 3.0])
    assert len(nb.pairs(np.zeros((1, 2)), 1.0)) == 0
    assert nb.all_pairs(np.zeros((0, 3)), 1.0).offset.shape == (0, 3)

"""rwt.sample: determinism, bounds, density kinds, n=, monotonicity, errors."""

import resource
import threading
import time

import numpy as np
import pytest

import rwt_noise as rwt

RECT = (-3.0, 2.0, 17.0, 14.5)


def by_id(s):
    order = np.argsort(s.ids)
    return s.ids[order], s.points[order]


def same_points(a, b):
    ia, pa = by_id(a)
    ib, pb = by_id(b)
    np.testing.assert_array_equal(ia, ib)
    np.testing.assert_array_equal(pa, pb)


def wave(x, y):
    return 3.0 + 2.0 * np.sin(x) * np.cos(0.5 * y)


@pytest.mark.parametrize("density", [4.0, "map", wave])
def test_same_inputs_same_arrays(density, ramp_map):
    d = ramp_map / 255.0 * 6 if isinstance(density, str) else density
    a = rwt.sample(RECT, d, seed=3)
    b = rwt.sample(RECT, d, seed=3)
    assert len(a) > 300
    for field in ("points", "ids", "thresholds"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field))
    assert a.points.dtype == np.float64 and a.points.shape == (len(a), 2)
    assert a.ids.dtype == np.uint64 and a.ids.shape == (len(a),)
    assert len(np.unique(a.ids)) == len(a)
    other = rwt.sample(RECT, d, seed=4)
    assert not np.array_equal(other.points[:10], a.points[:10])


@pytest.mark.parametrize("density", [25.0, "map", wave])
def test_every_point_inside_the_half_open_rect(density, ramp_map):
    d = ramp_map / 255.0 * 25 if isinstance(density, str) else density
    p = rwt.sample(RECT, d, seed=1).points
    x0, y0, x1, y1 = RECT
    assert len(p) > 700
    assert ((p[:, 0] >= x0) & (p[:, 0] < x1) & (p[:, 1] >= y0) & (p[:, 1] < y1)).all()


def test_constant_array_and_callable_equal_the_constant():
    constant = rwt.sample(RECT, 7.5, seed=2)
    flat = rwt.sample(RECT, np.full((13, 29), 7.5), seed=2)
    np.testing.assert_array_equal(flat.points, constant.points)
    np.testing.assert_array_equal(flat.ids, constant.ids)
    same_points(rwt.sample(RECT, lambda x, y: np.full_like(x, 7.5), seed=2), constant)


def test_callable_is_exact_with_or_without_a_known_bound():
    grid = rwt.sample(RECT, wave, seed=5)
    known = rwt.sample(RECT, wave, seed=5, max_density=5.0)
    same_points(grid, known)
    # Every point is kept exactly where the density exceeds its threshold.
    assert (grid.thresholds < wave(grid.points[:, 0], grid.points[:, 1])).all()


def test_a_callable_is_called_in_batches():
    calls = []

    def f(x, y):
        calls.append(len(x))
        return 50.0 * np.exp(-((x - 5) ** 2 + (y - 8) ** 2) / 4)

    s = rwt.sample(RECT, f, seed=1)
    assert len(s) > 200
    assert len(calls) <= 4, calls


@pytest.mark.parametrize("density", [3.0, "map", wave])
def test_n_is_exact_and_a_prefix_of_more(density, ramp_map):
    d = ramp_map / 255.0 * 3 if isinstance(density, str) else density
    small = rwt.sample(RECT, d, n=57, seed=9)
    large = rwt.sample(RECT, d, n=400, seed=9)
    assert len(small) == 57 and len(large) == 400
    np.testing.assert_array_equal(small.points, large.points[:57])
    np.testing.assert_array_equal(small.ids, large.ids[:57])
    assert small.scale < large.scale
    # The reported scale gives exactly these points.
    scaled = d * small.scale if not callable(d) else (lambda x, y: wave(x, y) * small.scale)
    same_points(rwt.sample(RECT, scaled, seed=9), small)
    assert len(rwt.sample(RECT, d, n=0)) == 0


def test_n_with_a_huge_density_stays_within_the_budget():
    s = rwt.sample((0, 0, 1000, 1000), 1e9, n=15, seed=2)
    assert len(s) == 15 and s.scale < 1e-6


def test_raising_the_density_only_adds_points(ramp_map):
    low = rwt.sample(RECT, ramp_map / 255.0 * 4, seed=6)
    high = rwt.sample(RECT, ramp_map / 255.0 * 4 + 1.0, seed=6)
    assert len(high) > len(low)
    assert np.isin(low.ids, high.ids).all()
    c1, c2 = rwt.sample(RECT, 2.0), rwt.sample(RECT, 2.5)
    assert np.isin(c1.ids, c2.ids).all() and len(c2) > len(c1)


def test_array_placed_by_extent():
    # Zero on the left half of the extent: no point up to the last zero texel's centre.
    m = np.zeros((4, 8))
    m[:, 4:] = 10.0
    s = rwt.sample((0, 0, 3.5, 4), m, extent=(0, 0, 8, 4))
    assert len(s) == 0
    s = rwt.sample((4, 0, 8, 4), m, extent=(0, 0, 8, 4))
    assert len(s) > 100


@pytest.mark.parametrize("rect", [(0, 0, np.nan, 1), (0, 0, np.inf, 1), (5, 0, 1, 1),
                                  (0, 3, 1, 1), (0, 0, 1), "abcd", None])
def test_bad_rects_are_value_errors(rect):
    with pytest.raises(ValueError):
        rwt.sample(rect, 1.0)


@pytest.mark.parametrize("density", [
    np.ones(5), np.ones((2, 2, 2)), np.ones((0, 3)), np.array([[1 + 2j]]),
    np.array([["a"]]), np.array([[1.0, np.nan]]), np.array([[1.0, -1.0]]),
    np.array([[np.inf]]), -1.0, float("nan"), True, "dense",
])
def test_bad_densities_are_value_errors(density):
    with pytest.raises(ValueError):
        rwt.sample((0, 0, 1, 1), density)


@pytest.mark.parametrize("f", [
    lambda x, y: np.ones((len(x), 2)),
    lambda x, y: np.ones(len(x) + 1),
    lambda x, y: np.full(len(x), np.nan),
    lambda x, y: np.full(len(x), "x"),
])
def test_bad_callable_results_are_value_errors(f):
    with pytest.raises(ValueError, match="callable"):
        rwt.sample((0, 0, 2, 2), f)


def test_a_raising_callable_propagates_its_exception():
    class Mine(Exception):
        pass

    def f(x, y):
        raise Mine("from the callable")

    with pytest.raises(Mine, match="from the callable"):
        rwt.sample((0, 0, 2, 2), f)


def test_a_callable_above_max_density_is_refused():
    with pytest.raises(ValueError, match="max_density"):
        rwt.sample((0, 0, 5, 5), lambda x, y: 10.0 + x, max_density=4.0)


def test_a_runaway_density_is_refused_before_any_allocation():
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    start = time.perf_counter()
    for density in (1e12, np.full((3, 3), 1e12), lambda x, y: np.full_like(x, 1e12)):
        with pytest.raises(rwt.BudgetError, match="budget"):
            rwt.sample((0, 0, 1000, 1000), density)
    with pytest.raises(rwt.BudgetError):
        rwt.sample((0, 0, 100, 100), 10.0, budget=1000)
    assert isinstance(rwt.BudgetError("x"), ValueError)
    grown_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    assert grown_kb < 64 * 1024, f"peak memory grew by {grown_kb} KB"
    assert time.perf_counter() - start < 10


def test_the_gil_is_released_while_rust_runs():
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(1)

    t = threading.Thread(target=count)
    t.start()
    try:
        time.sleep(0.01)
        before = len(ticks)
        start = time.perf_counter()
        s = rwt.sample((0, 0, 1000, 1000), 3.0)
        elapsed = time.perf_counter() - start
        during = len(ticks) - before
    finally:
        done.set()
        t.join()
    assert len(s) > 2_000_000
    # Python ran beside the query: far more than the few switches a held GIL allows.
    assert during > 1000 * elapsed, (during, elapsed)


def test_default_tiles_give_blue_noise_at_any_scale():
    # A few points over a large area, and dense points in pixel units: both blue noise.
    for rect, n in (((0, 0, 5000, 3000), 40), ((0, 0, 384, 384), 9000), ((0, 0, 1e-3, 1e-3), 500)):
        s = rwt.sample(rect, 1.0, n=n, seed=1)
        assert rwt.analyse(s.points, rect).rho > 0.55, rect
    assert rwt.auto_tile_size((0, 0, 100, 60)) == 128.0
    assert rwt.auto_tile_size((3, 3, 3, 3)) == 1.0
    # The explicit tile size of `rwt points` gives its (here sparse, white-noise) points.
    sparse = rwt.sample((0, 0, 384, 384), 1.0, n=9000, seed=1, tile_size=1.0)
    assert rwt.analyse(sparse.points, (0, 0, 384, 384)).rho < 0.3


def test_a_large_query_on_all_cores_is_the_union_of_small_ones(ramp_map):
    rect, tile = (0.0, 0.0, 300.0, 200.0), rwt.auto_tile_size((0.0, 0.0, 300.0, 200.0))
    density = ramp_map / 255.0 * 10.0
    whole = rwt.sample(rect, density, seed=2)
    assert len(whole) > 200_000
    xs, ys = np.linspace(0, 300, 5), np.linspace(0, 200, 4)
    parts = [rwt.sample((xs[i], ys[j], xs[i + 1], ys[j + 1]), density, seed=2, tile_size=tile,
                        extent=rect) for i in range(4) for j in range(3)]
    assert all(len(p) < 50_000 for p in parts)  # each queried serially
    ids = np.concatenate([p.ids for p in parts])
    points = np.concatenate([p.points for p in parts])
    order = np.argsort(ids)
    same_points(whole, rwt.Sample(points=points[order], ids=ids[order],
                                  thresholds=np.zeros(len(ids)), scale=1.0))


def test_bad_options_are_value_errors():
    for kwargs in ({"seed": -1}, {"seed": 1.5}, {"n": -3}, {"tile_size": 0},
                   {"tile_size": float("nan")}, {"budget": -1}, {"extent": (0, 0, 1, 1)},
                   {"max_density": 3.0}):
        with pytest.raises(ValueError):
            rwt.sample((0, 0, 1, 1), 1.0, **kwargs)
    with pytest.raises(OSError):
        rwt.sample((0, 0, 1, 1), 1.0, tileset="/nonexistent/tiles.ron")


def test_clumps_gather_points_in_patches_as_in_rust():
    flowers = rwt.Clumps(clumps=0.004, per_clump=15.0, radius=3.0, kernel="matern", seed=5)
    box = (-200.0, -100.0, 200.0, 300.0)
    a = rwt.sample(box, flowers, seed=11, tile_size=3.0)
    b = rwt.sample(box, flowers, seed=11, tile_size=3.0)
    assert np.array_equal(a.points, b.points) and np.array_equal(a.ids, b.ids)
    # About 0.004 x 15 x 160 000 = 9 600 points (blue-noise counts follow the integral
    # closely; the border cuts some clumps).
    assert abs(len(a.points) - 9_600) < 0.06 * 9_600
    # Patches: most of the rectangle is empty. Of its 4-unit cells, the same number of
    # points spread evenly would fill about 62 %; the clumps (discs 6 units across) fill
    # about a quarter.
    cells = np.floor((a.points - [-200.0, -100.0]) / 4.0).astype(int)
    occupied = len({tuple(c) for c in cells})
    assert occupied < 0.35 * 100 * 100, occupied
    # A chunk's points are the whole's points inside it.
    half = rwt.sample((-200.0, -100.0, 0.0, 300.0), flowers, seed=11, tile_size=3.0)
    inside = a.points[:, 0] < 0.0
    assert np.array_equal(np.sort(a.ids[inside]), np.sort(half.ids))
    # Exactly n, the density scaled to fit.
    assert len(rwt.sample(box, flowers, n=500, seed=11, tile_size=3.0).points) == 500


def test_bad_clumps_are_value_errors_when_made():
    # They were accepted, and refused only by a later sample.
    for bad, words in [
        (dict(clumps=0.01, per_clump=5.0, radius=float("nan")), "radius is nan"),
        (dict(clumps=-1.0, per_clump=5.0, radius=1.0), "clumps is -1.0"),
        (dict(clumps=0.01, per_clump=5.0, radius=1.0, kernel="gauss"), "gauss"),
        (dict(clumps=0.01, per_clump=True, radius=1.0), "per_clump is True"),
        (dict(clumps=0.01, per_clump=5.0, radius=1.0, seed=-1), "seed"),
        (dict(clumps=0.01, per_clump=1e9, radius=1e-200), "too dense"),
    ]:
        with pytest.raises(ValueError, match=words):
            rwt.Clumps(**bad)


def _strip_counts(points, side, per_unit):
    strips = int(side * per_unit)
    cells = np.minimum((points * per_unit).astype(np.int64), strips - 1)
    return np.concatenate([np.bincount(cells[:, 0], minlength=strips),
                           np.bincount(cells[:, 1], minlength=strips)]).astype(float)


def _coincident(a, b):
    """The fraction of b's points within a millionth of a tile of one of a's, modulo the tile."""
    key = lambda p: np.round(np.mod(p, 1.0) * 1e6).astype(np.int64)
    ka = {tuple(k) for k in key(a)}
    kb = key(b)
    near = [any((x + dx, y + dy) in ka for dx in (-1, 0, 1) for dy in (-1, 0, 1)) for x, y in kb]
    return float(np.mean(near))


def test_seeds_are_independent_sets():
    # Ten pairs of seeds, beside ten pairs of white-noise sets of the same size.
    side, rect = 32.0, (0.0, 0.0, 32.0, 32.0)
    sets = [rwt.sample(rect, 64.0, seed=s, tile_size=1.0).points for s in range(1, 21)]
    rng = np.random.default_rng(7)
    worst, worst_white, shared, shared_white = 0.0, 0.0, 0.0, 0.0
    for a, b in zip(sets[0::2], sets[1::2]):
        c = np.corrcoef(_strip_counts(a, side, 8), _strip_counts(b, side, 8))[0, 1]
        worst = max(worst, abs(c))
        shared = max(shared, _coincident(a, b))
        wa, wb = rng.uniform(0, side, a.shape), rng.uniform(0, side, b.shape)
        cw = np.corrcoef(_strip_counts(wa, side, 8), _strip_counts(wb, side, 8))[0, 1]
        worst_white = max(worst_white, abs(cw))
        shared_white = max(shared_white, _coincident(wa, wb))
    print(f"strip correlation {worst:.3f} (white {worst_white:.3f}), "
          f"coincident {shared:.5f} (white {shared_white:.5f})")
    assert worst <= 0.1
    assert shared <= 3 * max(shared_white, 1.0 / len(sets[0]))


def test_radius_keeps_every_pair_apart():
    from scipy.spatial import cKDTree

    # From a handful of points to 100 000, several seeds each: the closest pair is r apart.
    for rect, radius, seeds in (((0, 0, 100, 60), 20.0, 20), ((0, 0, 100, 60), 6.0, 10),
                                ((0, 0, 1, 1), 0.01, 5), ((-5, 3, 5, 4), 0.002, 3)):
        for seed in range(seeds):
            s = rwt.sample(rect, radius=radius, seed=seed)
            assert len(s) >= 2
            gap = cKDTree(s.points).query(s.points, k=2)[0][:, 1].min()
            assert gap >= radius, (rect, radius, seed, gap)
    # About 0.44 / r^2 points per unit area: what 0.62 of the hexagonal spacing gives.
    assert abs(len(rwt.sample((0, 0, 1, 1), radius=0.01)) / 4438 - 1) < 0.03
    with pytest.raises(ValueError, match="radius"):
        rwt.sample((0, 0, 10, 10), radius=2.0, tile_size=1.0)
    with pytest.raises(ValueError, match="density or radius"):
        rwt.sample((0, 0, 1, 1), 5.0, radius=0.1)
    with pytest.raises(ValueError, match="n= and radius="):
        rwt.sample((0, 0, 1, 1), radius=0.1, n=5)
    with pytest.raises(ValueError, match="radius must be"):
        rwt.sample((0, 0, 1, 1), radius=-1)


def test_rng_follows_numpys_convention():
    rect = (0, 0, 20, 20)
    same_points(rwt.sample(rect, 2.0, rng=9), rwt.sample(rect, 2.0, seed=9))
    same_points(rwt.sample(rect, 2.0, rng=np.uint8(9)), rwt.sample(rect, 2.0, seed=9))
    # A generator draws the seed: the same generator state, the same points; and it moves on.
    a, b = np.random.default_rng(4), np.random.default_rng(4)
    first = rwt.sample(rect, 2.0, rng=a)
    same_points(first, rwt.sample(rect, 2.0, rng=b))
    assert not np.array_equal(rwt.sample(rect, 2.0, rng=a).points, first.points)
    # The default stays reproducible: seed 0.
    same_points(rwt.sample(rect, 2.0), rwt.sample(rect, 2.0, seed=0))
    with pytest.raises(ValueError, match="seed= or rng="):
        rwt.sample(rect, 2.0, seed=1, rng=2)
    with pytest.raises(ValueError, match="rng must be"):
        rwt.sample(rect, 2.0, rng=np.random.RandomState(1))


def test_bounds_as_scipy_names_them():
    same_points(rwt.sample(l_bounds=(1, 2), u_bounds=np.array([7.0, 9.0]), density=3.0),
                rwt.sample((1, 2, 7, 9), 3.0))
    for kwargs, what in (({"l_bounds": (0, 0)}, "u_bounds"), ({}, "rect"),
                         ({"rect": (0, 0, 1, 1), "l_bounds": (0, 0), "u_bounds": (1, 1)}, "not both"),
                         ({"l_bounds": (0, 0, 1), "u_bounds": (1, 1)}, "l_bounds")):
        with pytest.raises(ValueError, match=what):
            rwt.sample(density=1.0, **kwargs)


def test_a_callable_may_return_one_number():
    rect = (0, 0, 12, 8)
    same_points(rwt.sample(rect, lambda x, y: 3.0, max_density=3.0), rwt.sample(rect, 3.0))
    same_points(rwt.sample(rect, lambda x, y: np.float32(3.0)), rwt.sample(rect, 3.0))


def test_a_sample_behaves_like_its_points():
    s = rwt.sample((0, 0, 10, 10), 3.0, seed=2)
    assert np.asarray(s) is s.points and np.asarray(s, dtype=np.float32).dtype == np.float32
    assert s.shape == s.points.shape == (len(s), 2)
    rows = list(s)
    assert len(rows) == len(s) and np.array_equal(rows[3], s.points[3])
    assert np.array_equal(s[:5], s.points[:5])
    assert (s == s.points).all() and not (s != s).any()
    np.testing.assert_allclose(np.mean(s, axis=0), s.points.mean(axis=0))


def test_errors_name_their_argument():
    rect = (0, 0, 1, 1)
    for kwargs, what in (({"density": "5"}, "density must be a number.*string"),
                         ({"density": 1.0, "seed": 2**64}, "seed must be"),
                         ({"density": 1.0, "rng": 2**64}, "rng must be"),
                         ({"density": 1.0, "budget": 2**64}, "budget must be"),
                         ({"density": 1.0, "n": -1}, "n must be"),
                         ({"density": 1.0, "tile_size": "1"}, "tile_size must be")):
        with pytest.raises(ValueError, match=what):
            rwt.sample(rect, **kwargs)
    with pytest.raises(ValueError, match="seed must be"):
        rwt.stipple(np.full((8, 8), 0.5), seed=2**64)

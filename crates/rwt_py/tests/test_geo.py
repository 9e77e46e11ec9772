"""`mask=` (shapely) and `rwt_noise.geo.sample_frame` (GeoPandas): tested where installed."""

import numpy as np
import pytest

import rwt_noise as rwt

shapely = pytest.importorskip("shapely")
from shapely.geometry import LineString, MultiPolygon, Point, Polygon, box  # noqa: E402

# A square with a hole, and a second, triangular part.
STAND = MultiPolygon([
    Polygon([(0, 0), (40, 0), (40, 30), (0, 30)], [[(10, 10), (20, 10), (20, 20), (10, 20)]]),
    Polygon([(50, 0), (80, 0), (50, 25)]),
])


def inside(geometry, points):
    return shapely.contains_xy(geometry, points[:, 0], points[:, 1])


def test_a_mask_keeps_the_point_set_inside_it():
    whole = rwt.sample(STAND.bounds, 2.0, seed=4, tile_size=64.0)
    masked = rwt.sample(density=2.0, mask=STAND, seed=4, tile_size=64.0)
    assert len(masked) > 1000 and inside(STAND, masked.points).all()
    # The same points as without the mask, those outside left out.
    keep = inside(STAND, whole.points)
    np.testing.assert_array_equal(masked.ids, whole.ids[keep])
    # Two pieces of the stand give its points, each once.
    left, right = STAND.intersection(box(0, 0, 33, 30)), STAND.difference(box(0, 0, 33, 30))
    parts = [rwt.sample(density=2.0, mask=p, seed=4, tile_size=64.0) for p in (left, right)]
    np.testing.assert_array_equal(np.sort(np.concatenate([p.ids for p in parts])),
                                  np.sort(masked.ids))


def test_n_counts_the_points_inside_the_mask():
    for n in (1, 17, 500):
        s = rwt.sample(mask=STAND, density=1.0, n=n, seed=2)
        assert len(s) == n and inside(STAND, s.points).all()
    # Blue noise inside the polygon: at least 0.62 of the hexagonal spacing apart.
    r = 0.8
    s = rwt.sample(mask=STAND, radius=r)
    gaps = np.hypot(*(s.points[:, None, :] - s.points[None, :, :]).transpose(2, 0, 1))
    assert gaps[~np.eye(len(s), dtype=bool)].min() >= r


def test_bad_masks_are_value_errors():
    for mask, what in ((LineString([(0, 0), (1, 1)]), "area"), ("POLYGON", "shapely geometry"),
                       (Point(1, 1).buffer(0).difference(Point(1, 1).buffer(1)), "area")):
        with pytest.raises(ValueError, match=what):
            rwt.sample(density=1.0, mask=mask)


def test_a_frame_samples_each_row_in_its_crs():
    gpd = pytest.importorskip("geopandas")
    from rwt_noise.geo import sample_frame

    frame = gpd.GeoDataFrame({"trees": [0.05, 0.2, 0.1], "plots": [3, 9, 0],
                              "gap": [6.0, 3.0, 4.0]},
                             geometry=[box(0, 0, 100, 100), STAND, box(100, 0, 160, 40)],
                             index=["a", "b", "c"], crs="EPSG:3067")
    plots = sample_frame(frame, n="plots", seed=1)
    assert plots.crs == frame.crs
    assert plots.groupby("row").size().to_dict() == {"a": 3, "b": 9}
    for label, geometry in zip(frame.index, frame.geometry):
        mine = plots[plots.row == label].geometry
        assert mine.within(geometry).all()
    trees = sample_frame(frame, density="trees", seed=1)
    expected = (frame.area * frame.trees).to_dict()
    counts = trees.groupby("row").size().to_dict()
    assert all(abs(counts[k] / expected[k] - 1) < 0.15 for k in expected), (counts, expected)
    spaced = sample_frame(frame, radius="gap")
    assert set(spaced.row) == {"a", "b", "c"}
    same = sample_frame(frame, density=[0.05, 0.2, 0.1], seed=1)
    assert same.geometry.equals(trees.geometry)
    for kwargs, what in (({}, "one of"), ({"density": 1.0, "n": 3}, "one of"),
                         ({"density": "nope"}, "names no column"),
                         ({"n": [1, 2]}, "2 values for 3 rows")):
        with pytest.raises(ValueError, match=what):
            sample_frame(frame, **kwargs)

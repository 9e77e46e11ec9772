"""Blue-noise points in the polygons of a GeoDataFrame (needs geopandas:
``pip install "rwt-noise[geo]"``).

>>> import geopandas as gpd
>>> from shapely.geometry import box
>>> from rwt_noise.geo import sample_frame
>>> stands = gpd.GeoDataFrame({"trees": [0.02, 0.05]},
...                           geometry=[box(0, 0, 100, 100), box(100, 0, 200, 60)],
...                           crs="EPSG:32633")
>>> plots = sample_frame(stands, n=[12, 7])
>>> plots.groupby("row").size().tolist(), plots.crs == stands.crs
([12, 7], True)
>>> trees = sample_frame(stands, density="trees", seed=3)
>>> 250 < len(trees) < 550
True
"""

from __future__ import annotations

from typing import Any, List, Optional, Sequence, Union

import numpy as np

from ._sample import Count, Number, RngLike, _count, _seed, auto_tile_size, sample

#: A per-row value: one for every row, a column's name, or one per row.
PerRow = Union[Number, str, Sequence[Number]]


def sample_frame(
    frame: Any,
    *,
    density: Optional[PerRow] = None,
    radius: Optional[PerRow] = None,
    n: Optional[Union[Count, str, Sequence[Count]]] = None,
    seed: Optional[Count] = None,
    rng: Optional[RngLike] = None,
    tile_size: Optional[Number] = None,
) -> Any:
    """Points in each row's geometry of ``frame`` (a ``GeoDataFrame`` of polygons in a
    projected CRS: densities are per square unit of it), by ``density``, ``radius`` or
    ``n`` (exactly that many in the row's polygon): each one value for every row, a
    column's name, or one value per row. Every row samples one point set (one seed, one
    tile size, from the frame's bounds unless given), so rows of one density are blue noise
    across their borders. Returns a ``GeoDataFrame`` of points in the frame's CRS, with the
    index label of the row each point lies in as column ``row``."""
    import geopandas as gpd  # type: ignore[import-untyped, unused-ignore]

    given = [(k, v) for k, v in (("density", density), ("radius", radius), ("n", n))
             if v is not None]
    if len(given) != 1:
        raise ValueError("give one of density=, radius= or n= (a value, a column or a list)")
    what, value = given[0]
    if not isinstance(frame, gpd.GeoDataFrame):
        raise ValueError(f"frame must be a geopandas.GeoDataFrame, got {type(frame).__name__}")
    values = _per_row(frame, value, what)
    tile = auto_tile_size(frame.total_bounds) if tile_size is None else tile_size
    opts: Any = {"seed": _seed(seed, rng), "tile_size": tile}
    xs: List[np.ndarray] = []
    rows: List[Any] = []
    for label, geometry, v in zip(frame.index, frame.geometry, values):
        if geometry is None or geometry.is_empty:
            continue
        if what == "n":
            points = sample(mask=geometry, density=1.0, n=_count(v, "n"), **opts)
        else:
            points = sample(mask=geometry, **{what: v}, **opts)
        xs.append(points.points)
        rows += [label] * len(points)
    xy = np.concatenate(xs) if xs else np.zeros((0, 2))
    return gpd.GeoDataFrame({"row": rows}, geometry=gpd.points_from_xy(xy[:, 0], xy[:, 1]),
                            crs=frame.crs)


def _per_row(frame: Any, value: Any, what: str) -> List[Any]:
    """``value`` for each row: a column's values, a list's, or the one value."""
    if isinstance(value, str):
        if value not in frame.columns:
            raise ValueError(f"{what}={value!r} names no column of the frame")
        return list(frame[value])
    if isinstance(value, (list, tuple, np.ndarray)):
        if len(value) != len(frame):
            raise ValueError(f"{what} has {len(value)} values for {len(frame)} rows")
        return list(value)
    return [value] * len(frame)

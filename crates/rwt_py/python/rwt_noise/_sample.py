"""`rwt.sample`: blue-noise points of any density in a rectangle."""

from __future__ import annotations

import numbers
import os
from dataclasses import dataclass
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import _rwt

Rect = Tuple[float, float, float, float]
#: A density callable: ``f(x, y)`` on two float64 arrays, returning an array of their shape
#: or one number for all of them.
DensityFn = Callable[[np.ndarray, np.ndarray], Union[npt.ArrayLike, float]]
#: A number: Python's or numpy's.
Number = Union[float, int, "np.floating[Any]", "np.integer[Any]"]
#: A count or a seed: Python's or numpy's integers.
Count = Union[int, "np.integer[Any]"]
#: ``rng=``: an integer (the seed itself) or a numpy ``Generator`` (which draws one).
RngLike = Union[Count, np.random.Generator]

#: What a query returns: positions, identities, thresholds and the density at each point.
Found = Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
#: The points of a density times a factor.
PointsAt = Callable[[float], Found]
#: Options every native query takes (seed, tile size, budget, tile set).
Options = Dict[str, Any]

#: Largest seed (seeds are 64-bit).
MAX_SEED = 2**64 - 1

#: The normalized minimum distance ``radius=`` counts on: rwt's closest pairs, measured at
#: every density, lie at least 0.643 of the hexagonal spacing apart (0.650 with the default
#: tile size); this leaves room below both.
RADIUS_RHO = 0.62


@dataclass(frozen=True)
class Clumps:
    """A density of points in patches: ``clumps`` patches per unit area, whose centres are
    rwt's own sparse blue-noise points (seeded by ``seed``), each holding ``per_clump``
    points on average within ``radius`` of its centre: a Gaussian cut off at the radius
    (``kernel="thomas"``) or a uniform disc (``"matern"``).

    >>> import rwt_noise as rwt
    >>> flowers = rwt.Clumps(clumps=0.01, per_clump=12.0, radius=1.5, seed=9)
    >>> s = rwt.sample((0.0, 0.0, 200.0, 200.0), flowers, tile_size=2.0)
    >>> abs(len(s.points) - 4800) < 400
    True
    """

    clumps: float
    per_clump: float
    radius: float
    kernel: str = "thomas"
    seed: int = 0

    def __post_init__(self) -> None:
        # Checked when made, not at the first sample: a bad value names itself here.
        for field in ("clumps", "per_clump", "radius"):
            v = getattr(self, field)
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not (0 < float(v) < np.inf):
                raise ValueError(f"clump parameter {field} is {v!r}, not a finite positive number")
        if isinstance(self.seed, bool) or not isinstance(self.seed, numbers.Integral) \
                or not 0 <= self.seed < 2**64:
            raise ValueError(f"clump seed must be an integer in 0..2**64, got {self.seed!r}")
        if self.kernel not in ("thomas", "matern"):
            raise ValueError(f'clump kernel must be "thomas" or "matern", got {self.kernel!r}')
        # The native checks too (clumps too dense to place), on an empty rectangle.
        _rwt.query((0.0, 0.0, 0.0, 0.0), self._native())

    def _native(self) -> Tuple[int, float, float, float, str]:
        if self.kernel not in ("thomas", "matern"):
            raise ValueError(f'clump kernel must be "thomas" or "matern", got {self.kernel!r}')
        return (int(self.seed), float(self.clumps), float(self.per_clump),
                float(self.radius), self.kernel)


Density = Union[Number, npt.ArrayLike, DensityFn, Clumps]

#: Most points one call may produce unless ``budget=`` says otherwise (50 million).
DEFAULT_BUDGET: int = _rwt.DEFAULT_BUDGET

# A callable density is bounded from its values on a grid of at most this many nodes along
# the rectangle's longer side (one batch of at most 257 x 257 evaluations).
_GRID_NODES = 257
# The bound at a node is the largest value of its 3 x 3 neighbourhood times this.
_BOUND_MARGIN = 1.5
# Rounds of raising the bound where a candidate shows the callable above it.
_BOUND_ROUNDS = 8


@dataclass(frozen=True, eq=False)
class Sample:
    """Points of one query. It behaves as its ``points`` array: ``np.asarray(sample)``,
    ``len()``, iteration over rows, indexing, ``shape`` and elementwise ``==``.

    ``points``: positions, shape ``(N, 2)``, float64. ``ids``: a 64-bit identity per point
    (a hash of the tile it first appears in and its index there), the same in every query
    that produces the point. ``thresholds``: the density above which each point is present
    (points per unit area). ``scale``: the factor the density was multiplied by (1.0 unless
    ``n=`` was given).
    """

    points: np.ndarray
    ids: np.ndarray
    thresholds: np.ndarray
    scale: float

    def __len__(self) -> int:
        return len(self.points)

    def __array__(self, dtype: Optional[npt.DTypeLike] = None,
                  copy: Optional[bool] = None) -> np.ndarray:
        if dtype is None and not copy:
            return self.points
        return np.array(self.points, dtype=dtype, copy=True)

    def __iter__(self) -> Iterator[np.ndarray]:
        return iter(self.points)

    def __getitem__(self, key: Any) -> Any:
        return self.points[key]

    def __eq__(self, other: object) -> Any:
        return self.points == (np.asarray(other) if isinstance(other, Sample) else other)

    def __ne__(self, other: object) -> Any:
        return self.points != (np.asarray(other) if isinstance(other, Sample) else other)

    __hash__ = None  # type: ignore[assignment]  # as an array's

    @property
    def shape(self) -> Tuple[int, ...]:
        """The shape of ``points``: ``(N, 2)``."""
        return tuple(self.points.shape)


def sample(
    rect: Optional[npt.ArrayLike] = None,
    density: Optional[Density] = None,
    *,
    radius: Optional[Number] = None,
    l_bounds: Optional[npt.ArrayLike] = None,
    u_bounds: Optional[npt.ArrayLike] = None,
    seed: Optional[Count] = None,
    rng: Optional[RngLike] = None,
    n: Optional[Count] = None,
    mask: Optional[Any] = None,
    tileset: Optional[Union[str, "os.PathLike[str]"]] = None,
    extent: Optional[npt.ArrayLike] = None,
    max_density: Optional[Number] = None,
    tile_size: Optional[Number] = None,
    budget: Count = DEFAULT_BUDGET,
) -> Sample:
    """Blue-noise points in ``rect`` following ``density`` (points per unit area).

    ``rect`` is ``(x0, y0, x1, y1)``, or ``l_bounds=(x0, y0)`` and ``u_bounds=(x1, y1)``
    as ``scipy.stats.qmc`` names them; half-open: a point on ``x1`` or ``y1`` belongs to
    the next rectangle, so the points of adjacent rectangles are exactly those of their
    union. ``density`` is one of:

    - a number: the same density everywhere;
    - a :class:`Clumps`: points in patches around sparse blue-noise centres;
    - a 2-D array spread over ``extent`` (``rect`` by default), bilinear between texel
      centres; row 0 is the top edge (largest y), as in an image; zero outside ``extent``;
    - a callable ``f(x, y)`` taking two 1-D float64 arrays and returning an array of the
      same shape (or one number for all). It is called in batches: once on a grid that
      bounds it, then on the candidate points; a point is kept exactly where ``f`` at its
      position exceeds its threshold, as for the other kinds. A known upper bound
      ``max_density=`` replaces the grid (then the result is exact for any ``f``; without
      it, features narrower than 1/256 of the rectangle may be missed).

    ``mask`` is any shapely geometry (a polygon, a multipolygon, ...): only the points
    inside it are kept (``rect`` defaults to its bounds), and ``n=`` counts the points
    inside it. Masking keeps the point set as it is (the same points as without the mask,
    those outside left out), so masked pieces of one region combine exactly.

    ``radius=r`` instead of a density asks for points at least ``r`` apart, as
    ``scipy.stats.qmc.PoissonDisk(radius=r)`` does: the uniform density
    ``2 / sqrt(3) * (0.62 / r) ** 2``, at which rwt's closest pairs stay ``r`` apart. rwt's
    points lie at least 0.643 of the hexagonal spacing apart at every density (measured;
    0.650 with the default tile size, and ``r`` holds in the tests at every size from 5 to
    100 000 points); dart throwing packs to about 0.75, so a radius gives fewer points than
    PoissonDisk's. With a ``tile_size`` of your own, each tile must hold at least 4 points
    (sparser tiles' first points lie closer).

    The same arguments always give the same arrays, in the query's order (a large query
    over few base tiles is computed on all cores in an 8 x 8 grid of chunks and comes chunk
    by chunk). Raising the density anywhere only adds points. With ``n``, exactly ``n``
    points are returned, the density scaled to fit (``Sample.scale``), in the order in
    which they appear as the density grows: the first ``k`` of them are the result for
    ``n=k``.

    ``seed`` (an integer, 0 by default) picks one of many independent point sets: each seed
    turns and moves the whole tiling. ``rng`` follows numpy's convention (SPEC 7) instead:
    an integer is the seed, a ``numpy.random.Generator`` draws one (so that a program's one
    generator drives everything). ``tileset`` is a tile set file made by
    ``rwt tileset build`` (default: the one built in). ``tile_size`` is the width of a base
    tile in rectangle units (``rwt points --tile-size``); the points depend on it. By
    default it is :func:`auto_tile_size` of ``rect``, so that the points are blue noise at
    any density down to a few points per rectangle, whatever its units; queries meant to
    combine (chunks of one rectangle, points to match ``rwt points``) give the same
    ``tile_size`` explicitly. A query that may produce more than ``budget`` points raises
    :class:`rwt.BudgetError` before allocating them.

    >>> import rwt_noise as rwt
    >>> s = rwt.sample((0, 0, 10, 10), 5.0, seed=1)
    >>> s.points.shape[1], 400 < len(s) < 600
    (2, True)
    >>> len(rwt.sample((0, 0, 10, 10), lambda x, y: 2.0 * x, n=100))
    100
    >>> far = rwt.sample(l_bounds=(0, 0), u_bounds=(1, 1), radius=0.05, rng=7)
    >>> from scipy.spatial.distance import pdist
    >>> bool(pdist(far.points).min() >= 0.05)
    True
    """
    geometry = None if mask is None else _geometry(mask)
    box = _bounds(rect, l_bounds, u_bounds, geometry)
    tile = auto_tile_size(box) if tile_size is None else _positive(tile_size, "tile_size")
    if radius is not None:
        density = _radius_density(radius, density, n, tile, tile_size is not None)
    elif density is None:
        raise ValueError("give a density (or radius=)")
    opts = dict(seed=_seed(seed, rng), tile_size=tile,
                budget=_count(budget, "budget", MAX_SEED),
                tileset=None if tileset is None else os.fspath(tileset))
    if extent is not None and (callable(density) or isinstance(density, numbers.Real)):
        raise ValueError("extent places a density array; this density is not an array")
    if max_density is not None and not callable(density):
        raise ValueError("max_density bounds a callable density; this density is not one")
    points_at, estimate = _density_source(box, density, extent, max_density, opts)
    if geometry is not None:
        points_at, estimate = _masked(points_at, estimate, box, geometry)
    if n is None:
        pos, ids, thr, _ = points_at(1.0)
        return Sample(pos, ids, thr, 1.0)
    return _first_n(points_at, _count(n, "n", MAX_SEED), estimate)


def _bounds(rect: object, l_bounds: object, u_bounds: object, mask: Any = None) -> Rect:
    """The rectangle, from ``rect``, from ``l_bounds`` and ``u_bounds``, or from the bounds
    of ``mask`` (a checked geometry)."""
    if l_bounds is None and u_bounds is None:
        if rect is None and mask is not None:
            return _rect(mask.bounds, "mask's bounds")
        if rect is None:
            raise ValueError("give rect=(x0, y0, x1, y1), or l_bounds= and u_bounds=")
        return _rect(rect, "rect")
    if rect is not None:
        raise ValueError("give rect or l_bounds and u_bounds, not both")
    corners: List[float] = []
    for v, what in ((l_bounds, "l_bounds"), (u_bounds, "u_bounds")):
        try:
            x, y = (float(c) for c in np.asarray(v, dtype=np.float64).reshape(-1))
        except (TypeError, ValueError):
            raise ValueError(f"{what} must be two numbers (x, y), got {v!r}") from None
        corners += [x, y]
    return _rect(corners, "l_bounds and u_bounds")


def _geometry(mask: object) -> Any:
    """``mask`` as a prepared shapely geometry (shapely is needed only for masks)."""
    try:
        import shapely  # type: ignore[import-untyped, unused-ignore]
    except ImportError:
        raise ValueError("mask= needs shapely: pip install \"rwt-noise[geo]\"") from None
    if not isinstance(mask, shapely.Geometry):
        raise ValueError(f"mask must be a shapely geometry, got {type(mask).__name__}")
    if mask.is_empty or not mask.is_valid or not mask.area > 0:
        raise ValueError("mask must be a valid geometry with an area (a polygon or several), "
                         f"got {mask.wkt[:80]}")
    shapely.prepare(mask)
    return mask


def _masked(points_at: PointsAt, estimate: float, box: Rect,
            geometry: Any) -> Tuple[PointsAt, float]:
    """The points of ``points_at`` inside ``geometry`` (checked and prepared by
    :func:`_geometry`), and their expected number (the rectangle's, in proportion to the
    geometry's share of its area)."""
    import shapely  # type: ignore[import-untyped, unused-ignore]

    def inside(scale: float) -> Found:
        pos, ids, thr, at = points_at(scale)
        keep = shapely.contains_xy(geometry, pos[:, 0], pos[:, 1])
        return pos[keep], ids[keep], thr[keep], at[keep]

    area = (box[2] - box[0]) * (box[3] - box[1])
    share = min(1.0, float(geometry.area) / area) if area > 0 else 0.0
    return inside, estimate * share


def _seed(seed: object, rng: object) -> int:
    """The tiling seed from ``seed=`` or ``rng=`` (0 when neither is given)."""
    if rng is None:
        return 0 if seed is None else _count(seed, "seed", MAX_SEED)
    if seed is not None:
        raise ValueError("give seed= or rng=, not both")
    if isinstance(rng, np.random.Generator):
        return int(rng.integers(0, MAX_SEED, dtype=np.uint64, endpoint=True))
    if isinstance(rng, bool) or not isinstance(rng, numbers.Integral):
        raise ValueError(f"rng must be an integer or a numpy.random.Generator, got {rng!r}")
    return _count(rng, "rng", MAX_SEED)


def _radius_density(radius: object, density: object, n: object, tile: float,
                    own_tiles: bool) -> float:
    """The uniform density whose points lie at least ``radius`` apart."""
    if density is not None:
        raise ValueError("give a density or radius=, not both")
    if n is not None:
        raise ValueError("n= and radius= both set how many points: give one")
    r = _positive(radius, "radius")
    d = 2.0 / np.sqrt(3.0) * (RADIUS_RHO / r) ** 2
    if not np.isfinite(d):
        raise ValueError(f"radius {r} is too small: its density is not a finite number")
    if own_tiles and d * tile * tile < 4.0:
        raise ValueError(f"radius {r} gives {d * tile * tile:.3g} points per tile of "
                         f"tile_size={tile}: at least 4 are needed for the distance to hold "
                         "(leave tile_size out, or make it larger)")
    return float(d)


def auto_tile_size(rect: npt.ArrayLike) -> float:
    """The base tile width :func:`sample` uses by default for ``rect``: the smallest power
    of two at least as long as its longer side (1 for an empty rectangle), so that the
    rectangle lies in at most 2 x 2 base tiles and the tiles' recursive subdivision gives
    blue noise at every density. (Tiles much smaller than the point spacing give white
    noise: a tile's first points are drawn from a handful of positions.)"""
    x0, y0, x1, y1 = _rect(rect, "rect")
    longest = max(x1 - x0, y1 - y0)
    if longest <= 0:
        return 1.0
    return float(2.0 ** np.ceil(np.log2(longest)))


def _rect(rect: object, what: str) -> Rect:
    try:
        x0, y0, x1, y1 = (float(v) for v in rect)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be four numbers (x0, y0, x1, y1), got {rect!r}") from None
    if not all(np.isfinite([x0, y0, x1, y1])):
        raise ValueError(f"{what} {(x0, y0, x1, y1)} is not finite")
    if x1 < x0 or y1 < y0:
        raise ValueError(f"{what} {(x0, y0, x1, y1)} is inverted (x1 < x0 or y1 < y0)")
    return (x0, y0, x1, y1)


def _count(v: object, what: str, most: Optional[int] = None) -> int:
    """``v`` as a non-negative integer (at most ``most``), or a ``ValueError`` naming it."""
    if isinstance(v, bool) or not isinstance(v, numbers.Integral) or int(v) < 0 \
            or (most is not None and int(v) > most):
        bound = "" if most is None else f" up to {most}"
        raise ValueError(f"{what} must be a non-negative integer{bound}, got {v!r}")
    return int(v)


def _positive(v: object, what: str) -> float:
    if isinstance(v, bool) or not isinstance(v, numbers.Real) or not (0 < float(v) < np.inf):
        raise ValueError(f"{what} must be a positive finite number, got {v!r}")
    return float(v)


def _density_source(box: Rect, density: object, extent: object, max_density: object,
                    opts: Options) -> Tuple[PointsAt, float]:
    """``points_at(scale) -> (points, ids, thresholds, density at each point)`` for the
    density times ``scale``, and the expected number of points at scale 1."""
    area = (box[2] - box[0]) * (box[3] - box[1])
    if isinstance(density, Clumps):
        native = density._native()
        return (lambda s: _rwt.query(box, native, scale=s, **opts)), \
            density.clumps * density.per_clump * area
    if callable(density):
        return _callable_source(box, density, max_density, opts)
    if isinstance(density, (str, bytes)):
        raise ValueError("density must be a number, a 2-D array, a callable or rwt.Clumps, "
                         f"got the string {density!r}")
    if isinstance(density, np.ndarray) and density.ndim == 0 and density.dtype.kind in "fiu":
        density = density.item()
    if isinstance(density, bool):
        raise ValueError("density must be a number, a 2-D array or a callable, got a bool")
    if isinstance(density, numbers.Real):
        d = float(density)
        if not (np.isfinite(d) and d >= 0):
            raise ValueError(f"density must be a non-negative finite number, got {density!r}")
        return (lambda s: _rwt.query(box, d, scale=s, **opts)), d * area
    values = _density_array(density)
    over = box if extent is None else _rect(extent, "extent")
    return ((lambda s: _rwt.query(box, values, scale=s, extent=over, **opts)),
            float(values.mean()) * area)


def _density_array(density: object) -> np.ndarray:
    arr = np.asarray(density)
    if arr.dtype.kind not in "fiu":
        raise ValueError(f"density array must hold real numbers, got dtype {arr.dtype}")
    if arr.ndim != 2 or arr.size == 0:
        raise ValueError(f"density array must be 2-D and non-empty, got shape {arr.shape}")
    # Checked on the shape, before a copy: a broadcast view of 20000 x 20000 took 8.9 GB.
    if arr.size > _rwt.MAX_MAP_PIXELS:
        raise ValueError(f"density array of shape {arr.shape} has more than "
                         f"{_rwt.MAX_MAP_PIXELS} values (4096 x 4096): downsample it")
    values = np.ascontiguousarray(arr, dtype=np.float64)
    bad = ~(np.isfinite(values) & (values >= 0))
    if bad.any():
        row, col = np.argwhere(bad)[0]
        raise ValueError(f"density array: value {values[row, col]} at [{row}, {col}] "
                         "is not a non-negative finite number")
    return values


def _evaluate(f: DensityFn, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``f(x, y)`` checked: real, finite, the shape of ``x``; negative values count as 0."""
    out = np.asarray(f(x.copy(), y.copy()))
    if out.ndim == 0 and out.dtype.kind in "fiu":
        # One number for every point.
        out = np.full(x.shape, out, dtype=np.float64)
    if out.dtype.kind not in "fiu":
        raise ValueError(f"density callable returned dtype {out.dtype}, not real numbers")
    if out.shape != x.shape:
        raise ValueError(f"density callable returned shape {out.shape} for inputs of shape "
                         f"{x.shape}: it must return one value per point")
    out = out.astype(np.float64)
    bad = ~np.isfinite(out)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"density callable returned {out[i]} at ({x[i]}, {y[i]}): "
                         "densities must be finite")
    return np.asarray(np.maximum(out, 0.0))


def _callable_source(box: Rect, f: DensityFn, max_density: object,
                     opts: Options) -> Tuple[PointsAt, float]:
    """Candidates from a bound of ``f``, kept where ``f`` exceeds their thresholds."""
    area = (box[2] - box[0]) * (box[3] - box[1])
    bound: Union[_ConstantBound, _GridBound]
    if max_density is not None:
        top = _positive(max_density, "max_density")
        bound = _ConstantBound(top)
        estimate = top * area
    else:
        grid = _GridBound(box, f)
        bound, estimate = grid, grid.mean * area

    def points_at(scale: float) -> Found:
        for _ in range(_BOUND_ROUNDS):
            pos, ids, thr, at_bound = bound.query(box, scale, opts)
            value = _evaluate(f, pos[:, 0], pos[:, 1]) if len(pos) else np.zeros(0)
            over = value * scale > at_bound * (1 + 1e-9)
            if not over.any():
                keep = thr < value * scale
                return pos[keep], ids[keep], thr[keep], value[keep] * scale
            bound.raise_at(pos[over], value[over])
        raise ValueError("the density callable keeps exceeding its sampled bound (a spike "
                         "narrower than the bound grid?): pass max_density=")

    return points_at, estimate


class _ConstantBound:
    def __init__(self, top: float):
        self.top = top

    def query(self, box: Rect, scale: float, opts: Options) -> Found:
        return _rwt.query(box, self.top, scale=scale, **opts)

    def raise_at(self, pos: np.ndarray, value: np.ndarray) -> None:
        raise ValueError(f"the density callable returned {value.max()} at "
                         f"{tuple(pos[np.argmax(value)])}, above max_density={self.top}")


class _GridBound:
    """A bound of a callable on a grid of nodes (texel centres of a density map): each
    node holds the largest value of its 3 x 3 neighbourhood, times a margin, so bilinear
    interpolation in a cell is at least the largest value at the cell's corners."""

    def __init__(self, box: Rect, f: DensityFn):
        x0, y0, x1, y1 = box
        w, h = x1 - x0, y1 - y0
        step = max(w, h) / (_GRID_NODES - 1)
        nx = _nodes(w, step)
        ny = _nodes(h, step)
        self.x = np.linspace(x0, x1, nx)
        self.y = np.linspace(y0, y1, ny)
        gx, gy = np.meshgrid(self.x, self.y)
        values = _evaluate(f, gx.ravel(), gy.ravel()).reshape(ny, nx)
        self.mean = float(values.mean())
        self.nodes = _dilate(values) * _BOUND_MARGIN
        hx = (x1 - x0) / (nx - 1) if nx > 1 else 1.0
        hy = (y1 - y0) / (ny - 1) if ny > 1 else 1.0
        self.cell = (hx, hy)
        self.extent = (x0 - hx / 2, y0 - hy / 2, x0 + (nx - 0.5) * hx, y0 + (ny - 0.5) * hy)

    def query(self, box: Rect, scale: float, opts: Options) -> Found:
        # Row 0 of a density map is its top edge.
        return _rwt.query(box, np.ascontiguousarray(self.nodes[::-1]), scale=scale,
                          extent=self.extent, **opts)

    def raise_at(self, pos: np.ndarray, value: np.ndarray) -> None:
        ny, nx = self.nodes.shape
        i = np.clip(((pos[:, 0] - self.x[0]) / self.cell[0]).astype(np.int64), 0, nx - 1)
        j = np.clip(((pos[:, 1] - self.y[0]) / self.cell[1]).astype(np.int64), 0, ny - 1)
        for di in (-1, 0, 1, 2):
            for dj in (-1, 0, 1, 2):
                ii, jj = np.clip(i + di, 0, nx - 1), np.clip(j + dj, 0, ny - 1)
                np.maximum.at(self.nodes, (jj, ii), 2.0 * value)


def _nodes(length: float, step: float) -> int:
    if length <= 0:
        return 1
    return int(min(_GRID_NODES, max(2, np.ceil(length / step - 1e-9) + 1)))


def _dilate(values: np.ndarray) -> np.ndarray:
    """Largest value of each 3 x 3 neighbourhood (edges repeat)."""
    padded = np.pad(values, 1, mode="edge")
    ny, nx = values.shape
    out = values.copy()
    for dy in range(3):
        for dx in range(3):
            np.maximum(out, padded[dy:dy + ny, dx:dx + nx], out=out)
    return out


def _first_n(points_at: PointsAt, n: int, estimate: float) -> Sample:
    """Exactly ``n`` points: the density is scaled until more than ``n`` points exist, and
    the ``n`` that appear first as it grows are kept, in that order."""
    if n == 0:
        return Sample(np.zeros((0, 2)), np.zeros(0, np.uint64), np.zeros(0), 0.0)
    scale = 1.25 * (n + 1) / estimate if estimate > 0 else 1.0
    for _ in range(64):
        pos, ids, thr, at = points_at(scale)
        if len(pos) > n:
            break
        scale *= 16.0 if len(pos) == 0 else max(1.25, 1.25 * (n + 1) / len(pos))
    else:
        raise ValueError(f"the density is zero in the rectangle: {n} points cannot be placed")
    keys = thr / (at / scale)
    order = np.lexsort((ids, keys))
    first = order[:n]
    # Any density factor between the n-th and the next appearance gives these n points.
    fit = 0.5 * (keys[order[n - 1]] + keys[order[n]])
    return Sample(pos[first], ids[first], thr[first], float(fit))

"""Benchmark: rwt against ``scipy.stats.qmc.PoissonDisk`` at an equal point count.

    python -m rwt_noise.bench [--points 100000] [--repeat 5] [--scaling 100000,1000000,2000000,10000000]

Prints, from one run, points per second and rho (normalized minimum distance) of both on
the unit square, scipy's radius set so that it fills the square with the same number of
points, then rwt with ``radius=``, masked to a disc (with shapely), and on a variable density
scipy cannot produce, and the speed ratio; then ``rwt.sample``'s time at each count of
``--scaling`` (unit tiles at 2048 points per unit area) beside the Rust query's alone (one
thread, into a reused vector, as ``rwt bench`` times it), measured in the same run.
"""

from __future__ import annotations

import argparse
import time
from typing import Callable, List, Tuple

import numpy as np

import rwt_noise as rwt
from rwt_noise import _rwt

UNIT = (0.0, 0.0, 1.0, 1.0)


def best_time(run: Callable[[], np.ndarray], repeat: int) -> Tuple[float, np.ndarray]:
    """The fastest of ``repeat`` runs, in seconds, and the points of the last."""
    times: List[float] = []
    points = np.zeros((0, 2))
    for _ in range(repeat):
        start = time.perf_counter()
        points = run()
        times.append(time.perf_counter() - start)
    return min(times), points


def rho(points: np.ndarray) -> float:
    """The normalized minimum distance of points on the unit square."""
    return float(rwt.analyse(points, UNIT).rho)


def scipy_radius(count: int) -> float:
    """The radius at which scipy's PoissonDisk fills the unit square with about ``count``
    points: its count scales as ``1 / radius**2``, measured at a small size."""
    from scipy.stats import qmc  # type: ignore[import-untyped]  # scipy ships no stubs

    probe = 0.02
    filled = len(qmc.PoissonDisk(d=2, radius=probe, seed=0).fill_space())
    return float(probe * np.sqrt(filled / count))


def variable_density(count: int) -> np.ndarray:
    """A density map with a 20 : 1 range (a bright disc and a ramp) holding ``count``
    points on the unit square."""
    y, x = np.mgrid[0:256, 0:256] / 255.0
    shape = 0.05 + x + 3.0 * np.exp(-((x - 0.6) ** 2 + (y - 0.4) ** 2) / 0.02)
    return np.asarray(shape * (count / shape.mean()))


def main(argv: List[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m rwt_noise.bench", description=__doc__)
    parser.add_argument("--points", type=int, default=100_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--scaling", default="100000,1000000,2000000,10000000",
                        help="point counts of the scaling table, comma-separated")
    args = parser.parse_args(argv)
    n, repeat = args.points, max(1, args.repeat)
    from scipy.stats import qmc

    radius = scipy_radius(n)
    t_scipy, p_scipy = best_time(
        lambda: qmc.PoissonDisk(d=2, radius=radius, seed=1).fill_space(), max(1, repeat // 5))
    count = len(p_scipy)
    t_rwt, p_rwt = best_time(lambda: rwt.sample(UNIT, float(count), seed=1).points, repeat)
    t_n, p_n = best_time(lambda: rwt.sample(UNIT, 1.0, n=count, seed=1).points, repeat)
    dens = variable_density(count)
    t_var, p_var = best_time(lambda: rwt.sample(UNIT, dens, seed=1).points, repeat)
    # The radius at which rwt gives about as many points.
    gap = float(np.sqrt(2.0 / np.sqrt(3.0) / count) * rwt._sample.RADIUS_RHO)
    t_rad, p_rad = best_time(lambda: rwt.sample(UNIT, radius=gap, seed=1).points, repeat)
    r_rwt, r_scipy = rho(p_rwt), rho(p_scipy)
    print(f"{'':<34}{'points':>9}{'seconds':>10}{'points/s':>14}{'rho':>7}")
    rows = [
        ("scipy PoissonDisk (uniform)", p_scipy, t_scipy, f"{r_scipy:7.3f}"),
        ("rwt.sample (uniform)", p_rwt, t_rwt, f"{r_rwt:7.3f}"),
        ("rwt.sample (uniform, n=)", p_n, t_n, f"{rho(p_n):7.3f}"),
        (f"rwt.sample (radius={gap:.2e})", p_rad, t_rad, f"{rho(p_rad):7.3f}"),
        ("rwt.sample (variable, 20:1 map)", p_var, t_var, "      -"),
    ]
    masked = masked_row(count, repeat)
    if masked is not None:
        rows.append(masked)
    for name, pts, t, r in rows:
        print(f"{name:<34}{len(pts):>9}{t:>10.4f}{len(pts) / t:>14,.0f}{r}")
    speedup = (len(p_rwt) / t_rwt) / (len(p_scipy) / t_scipy)
    print(f"rwt is {speedup:.0f}x scipy's points per second at {count} points; "
          f"rho {r_rwt:.3f} against scipy's {r_scipy:.3f} ({r_rwt - r_scipy:+.3f})")
    scaling([int(c) for c in args.scaling.split(",") if c], repeat)


def masked_row(count: int, repeat: int) -> Tuple[str, np.ndarray, float, str] | None:
    """rwt in the disc inscribed in the unit square (with shapely), at the density that
    gives ``count`` points in the square."""
    try:
        from shapely.geometry import Point  # type: ignore[import-untyped, unused-ignore]
    except ImportError:
        return None
    disc = Point(0.5, 0.5).buffer(0.5, quad_segs=64)
    t, p = best_time(lambda: rwt.sample(UNIT, float(count), mask=disc, seed=1).points, repeat)
    return "rwt.sample (uniform, mask=disc)", p, t, "      -"


def scaling(counts: List[int], repeat: int) -> None:
    """``rwt.sample`` of each count on unit tiles at 2048 points per unit area (about one
    tile's points per tile, as ``rwt bench`` queries), beside the Rust query alone."""
    print(f"{'':<34}{'points':>9}{'sample s':>10}{'query s':>10}{'ratio':>7}{'ns/point':>10}")
    for n in counts:
        side = float(np.sqrt(n / 2048.0))
        rect = (0.0, 0.0, side, side)
        t_py, points = best_time(
            lambda: rwt.sample(rect, 2048.0, seed=1, tile_size=1.0).points, repeat)
        count, t_rust = _rwt.time_query(rect, 2048.0, tile_size=1.0, seed=1,
                                        repeat=repeat)
        print(f"{'rwt.sample / Rust query':<34}{len(points):>9}{t_py:>10.4f}{t_rust:>10.4f}"
              f"{t_py / t_rust:>7.2f}{t_py / len(points) * 1e9:>10.1f}")


if __name__ == "__main__":
    main()

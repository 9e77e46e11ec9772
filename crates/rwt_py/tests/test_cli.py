"""rwt.sample gives the points `rwt points` writes for the same inputs."""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import rwt_noise as rwt
from conftest import write_grey_png

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def cli() -> str:
    """The `rwt` binary: $RWT_CLI, or the workspace's debug build (built when missing)."""
    path = os.environ.get("RWT_CLI")
    if path:
        assert Path(path).is_file(), f"RWT_CLI={path} does not exist"
        return path
    built = ROOT / "target" / "debug" / "rwt"
    if not built.is_file():
        subprocess.run(["cargo", "build", "-q", "-p", "rwt_cli"], cwd=ROOT, check=True)
    return str(built)


def cli_points(cli, rect, density, seed, tile_size=1.0):
    out = subprocess.run(
        [cli, "points", "--rect", *map(repr, rect), "--density", density, "--seed", str(seed),
         "--tile-size", repr(tile_size)],
        check=True, capture_output=True, text=True).stdout
    rows = [line.split()[:2] for line in out.splitlines()]
    return np.array(rows, dtype=np.float64).reshape(-1, 2)


@pytest.mark.parametrize("rect,value,seed,tile", [
    ((0.0, 0.0, 12.0, 9.0), 6.0, 0, 1.0),
    ((-40.0, -25.5, 30.0, 31.0), 2.5, 7, 1.0),   # >= 256 tiles: the parallel query
    ((1.5, -2.0, 4.0, 3.0), 40.0, 3, 0.25),
])
def test_constant_density_matches_rwt_points(cli, rect, value, seed, tile):
    expected = cli_points(cli, rect, f"const:{value!r}", seed, tile)
    got = rwt.sample(rect, value, seed=seed, tile_size=tile).points
    assert len(expected) > 100
    np.testing.assert_array_equal(got, expected)


def test_a_large_query_has_the_points_of_rwt_points(cli):
    # Python computes it on all cores in chunks, the CLI serially: the same set.
    rect = (0.0, 0.0, 400.0, 300.0)
    tile = rwt.auto_tile_size(rect)
    expected = cli_points(cli, rect, "const:1.5", 8, tile)
    got = rwt.sample(rect, 1.5, seed=8).points
    assert len(expected) > 150_000
    np.testing.assert_array_equal(np.unique(got, axis=0), np.unique(expected, axis=0))
    assert len(np.unique(got, axis=0)) == len(got)


def test_density_array_matches_an_image_density(cli, tmp_path, ramp_map):
    png = tmp_path / "map.png"
    write_grey_png(png, ramp_map)
    rect = (-5.0, 0.0, 25.0, 20.0)
    expected = cli_points(cli, rect, f"image:{png}:12", 4)
    got = rwt.sample(rect, ramp_map / 255.0 * 12.0, seed=4, tile_size=1.0).points
    assert len(expected) > 1000
    np.testing.assert_array_equal(got, expected)

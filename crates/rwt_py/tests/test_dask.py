"""The Dask example: chunks computed as independent tasks are exactly one query."""

import sys
from pathlib import Path

import dask
import numpy as np
import pytest

import rwt_noise as rwt

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
from dask_chunks import sample_chunked  # noqa: E402


def exact_union(chunked, whole):
    order_c, order_w = np.argsort(chunked.ids), np.argsort(whole.ids)
    np.testing.assert_array_equal(chunked.ids[order_c], whole.ids[order_w])
    np.testing.assert_array_equal(chunked.points[order_c], whole.points[order_w])


@pytest.mark.parametrize("scheduler", ["threads", "sync", "processes"])
def test_chunks_are_exactly_one_query(scheduler):
    rect = (-130.0, 7.25, 170.0, 233.0)
    y, x = np.mgrid[0:64, 0:80]
    density = 0.5 + np.exp(-((x - 40) ** 2 + (y - 30) ** 2) / 300.0)
    with dask.config.set(scheduler=scheduler):
        chunked = sample_chunked(rect, density, chunks=(5, 3), seed=4)
    whole = rwt.sample(rect, density, seed=4)
    assert len(whole) > 20_000
    exact_union(chunked, whole)


def test_callable_chunks_are_exactly_one_query():
    rect = (0.0, 0.0, 90.0, 60.0)

    def f(x, y):
        return 2.0 + np.sin(x / 7.0) * np.cos(y / 5.0)

    with dask.config.set(scheduler="threads"):
        chunked = sample_chunked(rect, f, chunks=(3, 4), seed=2)
    exact_union(chunked, rwt.sample(rect, f, seed=2))

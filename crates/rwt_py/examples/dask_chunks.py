"""Blue noise over a large rectangle, computed as independent Dask tasks.

Every point of an rwt query belongs to exactly one half-open chunk ``[x0, x1) x [y0, y1)``
and does not depend on the others (given one tile size), so the chunks of a grid are
computed with no coordination at all, and their union is exactly the points of one query
over the whole rectangle. On one machine Dask's local scheduler runs the chunks on threads
(rwt releases the GIL); with ``dask.distributed.Client("scheduler:8786")`` the same
graph runs on a cluster.

    python examples/dask_chunks.py
"""

from __future__ import annotations

import dask
import numpy as np

import rwt_noise as rwt


def chunk_edges(lo: float, hi: float, count: int) -> np.ndarray:
    """Chunk boundaries: the ends are exactly ``lo`` and ``hi``, and neighbouring chunks
    share the very same float, so no point falls between two chunks or into both."""
    return np.linspace(lo, hi, count + 1)


def sample_chunked(rect, density, *, chunks=(4, 4), seed=0, extent=None) -> rwt.Sample:
    """The points of ``rwt.sample(rect, density, seed=seed)`` from ``chunks`` independent
    tasks. Every task uses the whole rectangle's tile size and places an array density over
    ``extent`` (``rect`` by default), as the whole query does."""
    x0, y0, x1, y1 = rect
    tile = rwt.auto_tile_size(rect)
    xs, ys = chunk_edges(x0, x1, chunks[0]), chunk_edges(y0, y1, chunks[1])
    # An array is placed over the whole rectangle (or its extent) in every chunk.
    placed = {"extent": tuple(extent or rect)} if isinstance(density, np.ndarray) else {}
    task = dask.delayed(rwt.sample, pure=True)
    parts = [
        task((xs[i], ys[j], xs[i + 1], ys[j + 1]), density, seed=seed, tile_size=tile,
             **placed)
        for j in range(chunks[1])
        for i in range(chunks[0])
    ]
    results = dask.compute(*parts)
    return rwt.Sample(
        points=np.concatenate([r.points for r in results]),
        ids=np.concatenate([r.ids for r in results]),
        thresholds=np.concatenate([r.thresholds for r in results]),
        scale=1.0,
    )


def main() -> None:
    rect = (0.0, 0.0, 2000.0, 2000.0)
    y, x = np.mgrid[0:256, 0:256]
    density = 1.0 + 3.0 * np.exp(-((x - 128) ** 2 + (y - 128) ** 2) / 3000.0)
    chunked = sample_chunked(rect, density, chunks=(8, 8), seed=1)
    whole = rwt.sample(rect, density, seed=1)
    same = np.array_equal(np.sort(chunked.ids), np.sort(whole.ids))
    print(f"{len(chunked)} points from 64 tasks; the same as one query: {same}")


if __name__ == "__main__":
    main()

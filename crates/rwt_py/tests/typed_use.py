"""A user's script as `mypy --strict` checks it (tests/test_types.py): numpy scalars, arrays
and generators where numbers, rectangles and seeds go."""

import numpy as np

import rwt_noise as rwt

rect = np.array([0.0, 0.0, 10.0, 10.0])
generator = np.random.default_rng(5)
a: rwt.Sample = rwt.sample(rect, np.float32(2.0), seed=np.uint32(3), tile_size=np.float64(4.0))
b = rwt.sample(l_bounds=np.zeros(2), u_bounds=(10, 10), radius=np.float64(0.5), rng=generator)
c = rwt.sample((0, 0, 1, 1), lambda x, y: 2.0, n=np.int64(20), budget=np.int64(1000))
d = rwt.sample([0, 0, 4, 4], np.ones((8, 8)), extent=[0, 0, 4, 4], rng=7)
points: np.ndarray = np.asarray(a)
figures: rwt.Analysis = rwt.analyse(points, rect, size=np.int64(64))
dots: rwt.Stipple = rwt.stipple(np.full((16, 16), 0.5).tolist(), seed=np.int8(1), gamma=1)
count: int = len(b) + len(c) + len(d) + len(dots.points)

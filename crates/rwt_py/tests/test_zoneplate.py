"""`rwt.zoneplate`: the paper's anti-aliasing claim, as `tests/zoneplate.rs` checks it."""

import numpy as np
import pytest

import rwt_noise as rwt


def test_rwt_removes_aliasing_like_jittering_with_less_noise(tmp_path):
    result = rwt.zoneplate(size=192, seed=1, out=tmp_path / "plate.png")
    rwt_, grid, jitter = (result.errors[k] for k in ("rwt", "grid", "jitter"))
    assert rwt_[1] > grid[1] + 1.0, result.errors
    assert rwt_[1] >= jitter[1] - 0.41, result.errors  # within 10 % of jittering's error
    assert rwt_[2] > jitter[2], result.errors
    assert result.claim() == (True, True)
    assert set(result.images) == {"reference", "rwt", "grid", "jitter", "white", "dart", "sobol"}
    assert all(image.shape == (192, 192) for image in result.images.values())
    # The grid reproduces the resolved centre exactly; the images are the plate's values.
    assert np.abs(result.images["reference"]).max() <= 1.0
    assert (tmp_path / "plate.png").stat().st_size > 10_000


def test_bad_sizes_are_value_errors():
    for size in (0, 8, 4096, -1, 2.5):
        with pytest.raises(ValueError, match="size"):
            rwt.zoneplate(size=size)

"""rwt.stipple: tone error within the Rust tests' bound, inputs and errors."""

import numpy as np
import pytest

import rwt_noise as rwt


def test_tone_error_within_the_rust_bound(sphere):
    s = rwt.stipple(sphere, render=True)
    assert s.points.shape[1] == 2 and len(s.points) > 500
    # tests/stipple.rs asserts a mean absolute tone error of at most 0.03.
    assert s.tone_error <= 0.03, s.tone_error
    assert s.tone_error < s.white_noise_tone_error
    h, w = sphere.shape
    assert s.raster.shape == (2 * h, 2 * w) and s.raster.dtype == np.float32
    # Dots in image pixels, x right and y down: the dark lower right has more of them.
    x, y = s.points[:, 0], s.points[:, 1]
    assert ((x >= 0) & (x < w) & (y >= 0) & (y < h)).all()
    assert (x > w / 2).sum() > 1.2 * (x < w / 2).sum()


def test_same_image_same_dots_and_dtypes_agree(sphere):
    a = rwt.stipple(sphere, dots=800, seed=2)
    b = rwt.stipple(sphere, dots=800, seed=2)
    np.testing.assert_array_equal(a.points, b.points)
    as_bytes = rwt.stipple(np.round(sphere * 255).astype(np.uint8), dots=800, seed=2)
    assert abs(len(as_bytes.points) - len(a.points)) < 0.05 * len(a.points)
    assert a.raster is None and a.tone_error is None


def test_radius_gives_the_dot_size(sphere):
    s = rwt.stipple(sphere, radius=1.5)
    assert s.radius == 1.5


@pytest.mark.parametrize("image", [np.ones((4, 4, 3)), np.ones(16), np.ones((0, 4)),
                                   np.array([["a"]]), np.ones((4, 4), dtype=complex)])
def test_bad_images_are_value_errors(image):
    with pytest.raises(ValueError):
        rwt.stipple(image)


def test_white_and_bad_settings_are_value_errors(sphere):
    with pytest.raises(ValueError, match="white"):
        rwt.stipple(np.ones((8, 8)))
    with pytest.raises(ValueError, match="gamma"):
        rwt.stipple(sphere, gamma=-1.0)
    with pytest.raises(ValueError, match="not both"):
        rwt.stipple(sphere, dots=10, radius=1.0)
    for kwargs in ({"dots": -5}, {"seed": 1.5}, {"radius": "big"}, {"scale": float("nan")},
                   {"max_dots": -1}, {"contrast": 0.0}):
        with pytest.raises(ValueError):
            rwt.stipple(sphere, **kwargs)


def test_limits_raise_budget_errors(sphere):
    with pytest.raises(rwt.BudgetError):
        rwt.stipple(sphere, dots=10_000, max_dots=1000)
    with pytest.raises(rwt.BudgetError):
        rwt.stipple(sphere, scale=1000.0)

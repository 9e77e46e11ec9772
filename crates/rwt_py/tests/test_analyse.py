"""rwt.analyse: figures that tell blue noise from white noise; errors."""

import numpy as np
import pytest

import rwt_noise as rwt


def test_blue_noise_against_white_noise():
    window = (0.0, 0.0, 60.0, 60.0)
    blue = rwt.analyse(rwt.sample(window, 3.0, seed=1).points, window)
    rng = np.random.default_rng(1)
    white = rwt.analyse(rng.uniform(0, 60, size=(10_800, 2)), window)
    assert blue.rho >= 0.6 and white.rho < 0.1
    assert blue.windows == white.windows == 16
    assert blue.power.shape == (128, 128)
    assert blue.frequencies.shape == blue.radial_power.shape == blue.anisotropy_db.shape
    # The blue-noise hole: little power at low frequencies, white noise's is flat near 1.
    low = slice(1, 8)
    assert blue.radial_power[low].mean() < 0.3 < white.radial_power[low].mean()
    assert abs(blue.density - 3.0) < 0.1


def test_points_outside_the_window_are_ignored():
    pts = rwt.sample((0, 0, 40, 40), 4.0).points
    inner = rwt.analyse(pts, (0, 0, 20, 20))
    same = rwt.analyse(pts[(pts[:, 0] < 20) & (pts[:, 1] < 20)], (0, 0, 20, 20))
    assert inner.rho == same.rho
    np.testing.assert_array_equal(inner.power, same.power)


@pytest.mark.parametrize("points,window", [
    (np.ones((10, 3)), (0, 0, 1, 1)),
    (np.ones(10), (0, 0, 1, 1)),
    (np.array([["a", "b"]]), (0, 0, 1, 1)),
    (np.random.default_rng(0).uniform(size=(100, 2)), (0, 0, np.nan, 1)),
    (np.random.default_rng(0).uniform(size=(100, 2)), (1, 0, 0, 1)),
    (np.zeros((1, 2)), (0, 0, 1, 1)),
])
def test_bad_inputs_are_value_errors(points, window):
    with pytest.raises(ValueError):
        rwt.analyse(points, window)


def test_a_bad_size_is_a_value_error():
    with pytest.raises(ValueError, match="size"):
        rwt.analyse(np.random.default_rng(0).uniform(size=(100, 2)), (0, 0, 1, 1), size=10_000)


def test_the_spectrum_reaches_past_its_peak_at_any_count():
    # 100 000 points: the windows shrink so that the spectrum reaches twice the peak,
    # which lies at about 1.2 sqrt(density) cycles per unit (it read 0.8 with windows of
    # 20 000 points, whose peak lay past the spectrum's edge).
    window = (0.0, 0.0, 100.0, 100.0)
    a = rwt.analyse(rwt.sample(window, 10.0, seed=3).points, window)
    peak = a.frequencies[np.argmax(a.radial_power)] / np.sqrt(a.density)
    assert 1.0 < peak < 1.4, peak
    assert a.frequencies[-1] > 2.0 * peak * np.sqrt(a.density)
    assert a.windows == 64 and a.rho > 0.6

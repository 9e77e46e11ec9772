"""`rwt.analyse`: blue-noise figures of a point set."""

from __future__ import annotations

from dataclasses import dataclass
import numpy as np
import numpy.typing as npt

from . import _rwt
from ._sample import Count, _count, _rect


@dataclass(frozen=True)
class Analysis:
    """Figures of the points in a window, as ``rwt analyse`` computes them.

    ``rho`` is measured in up to 4 x 4 square sub-windows (each holding about 500 to
    20 000 points); the spectrum in up to 8 x 8 sub-windows of ``side``, each of at most
    about ``(size / 4.8) ** 2`` points, so that its frequencies reach twice blue noise's
    principal peak (about ``1.2 sqrt(density)``) however many points there are. ``rho``:
    the normalized minimum distance (the smallest of any sub-window; 1 for a hexagonal lattice, about 0.75 for good Poisson-disk sets, near 0
    for white noise). ``density``: points per unit area in the window. ``windows``: how many
    periodograms were averaged. ``power``: the averaged periodogram, ``(size, size)``,
    frequency zero at ``[size // 2, size // 2]``, 1 being the level of white noise.
    ``frequencies``: the frequency of each annulus (cycles per unit length);
    ``radial_power``: the mean power of each annulus; ``anisotropy_db``: its anisotropy,
    ``10 log10(variance / mean**2)`` (isotropic noise is about ``-10 log10(windows)``).
    """

    rho: float
    density: float
    windows: int
    side: float
    frequencies: np.ndarray
    radial_power: np.ndarray
    anisotropy_db: np.ndarray
    power: np.ndarray


def analyse(points: npt.ArrayLike, window: npt.ArrayLike, *, size: Count = 128) -> Analysis:
    """Normalized minimum distance, radial power spectrum and anisotropy of ``points``
    (shape ``(N, 2)``) inside ``window`` ``(x0, y0, x1, y1)``; points outside are ignored.

    >>> import rwt_noise as rwt
    >>> s = rwt.sample((0, 0, 40, 40), 4.0)
    >>> a = rwt.analyse(s.points, (0, 0, 40, 40))
    >>> a.rho > 0.6, a.radial_power.shape == a.frequencies.shape
    (True, True)
    """
    box = _rect(window, "window")
    pts = np.asarray(points)
    if pts.dtype.kind not in "fiu" or pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"points must be a real array of shape (N, 2), got {pts.dtype} "
                         f"{pts.shape}")
    pts = np.ascontiguousarray(pts, dtype=np.float64)
    figures = _rwt.analyse(pts, box, size=_count(size, "size"))
    rho, density, windows, side, power, radial, aniso = figures
    frequencies = np.arange(len(radial)) / side
    return Analysis(rho, density, windows, side, frequencies, radial, aniso, power)

"""rwt_noise: blue-noise point sets of any density, fast and reproducible.

Recursive Wang tiles for real-time blue noise (Kopf et al., SIGGRAPH 2006): points of any
density anywhere in the plane by random access, with stable identities; raising the density
only adds points. numpy in and out; the work runs in Rust with the GIL released.

- :func:`sample`: the points of a rectangle for a constant, an array or a callable density,
  or exactly ``n`` of them.
- :func:`stipple`: tone-true stippling of a grey image.
- :func:`analyse`: normalized minimum distance, radial power spectrum and anisotropy.
- :func:`zoneplate`: the paper's anti-aliasing test, rwt beside other sampling patterns.
"""

from ._analyse import Analysis, analyse
from ._rwt import BudgetError
from ._sample import DEFAULT_BUDGET, Clumps, Sample, auto_tile_size, sample
from ._stipple import Stipple, stipple
from ._zoneplate import ZonePlateResult, zoneplate

__all__ = [
    "Analysis",
    "BudgetError",
    "Clumps",
    "DEFAULT_BUDGET",
    "Sample",
    "Stipple",
    "analyse",
    "auto_tile_size",
    "sample",
    "stipple",
    "zoneplate",
    "ZonePlateResult",
]
__version__ = "0.1.0"

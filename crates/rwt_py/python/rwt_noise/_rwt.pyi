"""Type stubs of the native module (called through `rwt`'s Python functions)."""

from typing import List, Optional, Tuple, Union

import numpy as np

Corners = Tuple[float, float, float, float]

DEFAULT_BUDGET: int
MAX_MAP_PIXELS: int
DEFAULT_MAX_IMAGE_PIXELS: int

class BudgetError(ValueError):
    """A request over its point, dot or raster budget, refused before any allocation."""

def query(
    rect: Corners,
    density: Union[float, np.ndarray, Tuple[int, float, float, float, str]],
    *,
    scale: float = 1.0,
    extent: Optional[Corners] = None,
    seed: int = 0,
    tile_size: float = 1.0,
    budget: int = ...,
    tileset: Optional[str] = None,
) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]: ...
def stipple(
    image: np.ndarray,
    *,
    dots: Optional[int] = None,
    radius: Optional[float] = None,
    gamma: Optional[float] = None,
    contrast: Optional[float] = None,
    seed: Optional[int] = None,
    scale: Optional[float] = None,
    render: bool = False,
    max_dots: Optional[int] = None,
    max_raster_pixels: Optional[int] = None,
    max_image_pixels: Optional[int] = None,
    tileset: Optional[str] = None,
) -> Tuple[np.ndarray, float, Optional[np.ndarray], Optional[Tuple[float, float]]]: ...
def analyse(
    points: np.ndarray, window: Corners, *, size: int = 128
) -> Tuple[float, float, int, float, np.ndarray, np.ndarray, np.ndarray]: ...
def zoneplate(
    *, size: int = 512, seed: int = 0
) -> Tuple[List[str], np.ndarray, np.ndarray, Tuple[bool, bool]]: ...
def time_query(
    rect: Corners, density: float, *, tile_size: float, seed: int = 0, repeat: int = 3
) -> Tuple[int, float]: ...

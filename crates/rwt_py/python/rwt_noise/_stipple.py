"""`rwt.stipple`: tone-true blue-noise stippling of a grey image."""

from __future__ import annotations

import numbers
import os
from dataclasses import dataclass
from typing import Optional, Union

import numpy as np
import numpy.typing as npt

from . import _rwt
from ._sample import MAX_SEED, Count, Number, _count


@dataclass(frozen=True)
class Stipple:
    """Dots of one radius that reproduce an image's tone.

    ``points``: dot centres in image pixels, shape ``(N, 2)``, x to the right and y down
    (row 0 of the image at y = 0). ``radius``: the dot radius in image pixels. With
    ``render=True``: ``raster``, the dots drawn as ink coverage (0 white .. 1 black,
    antialiased) at ``scale`` raster pixels per image pixel, and the tone errors: the mean
    absolute difference between the blurred stipple and the blurred image darkness
    (``tone_error``), beside that of the same number of dots placed by white noise
    (``white_noise_tone_error``), as ``rwt stipple`` prints them.
    """

    points: np.ndarray
    radius: float
    raster: Optional[np.ndarray]
    tone_error: Optional[float]
    white_noise_tone_error: Optional[float]


def stipple(
    image: npt.ArrayLike,
    *,
    dots: Optional[Count] = None,
    radius: Optional[Number] = None,
    gamma: Optional[Number] = None,
    contrast: Optional[Number] = None,
    seed: Optional[Count] = None,
    scale: Optional[Number] = None,
    render: bool = False,
    max_dots: Optional[Count] = None,
    max_raster_pixels: Optional[Count] = None,
    max_image_pixels: Optional[Count] = None,
    tileset: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> Stipple:
    """Stipples a grey image with blue-noise dots whose blurred ink keeps its tone.

    ``image`` is 2-D: grey levels, 0 black; uint8 (0..255), uint16 (0..65535), bool or
    float (0..1). Every setting left as ``None`` takes ``rwt stipple``'s default: one dot
    per four pixels (``dots=`` a count or ``radius=`` a dot radius in pixels instead),
    ``gamma`` and ``contrast`` 1 (darkness ``(contrast * (1 - grey)) ** gamma``), seed 0,
    and dots calibrated for a raster of ``scale`` 2 pixels per image pixel. More dots than
    ``max_dots`` (4 million), a raster over ``max_raster_pixels`` (2**24) or an image of
    more than ``max_image_pixels`` (2**22) raise :class:`rwt.BudgetError` before anything
    is allocated. Ctrl-C interrupts a long stipple within a fraction of a second.

    >>> import numpy as np, rwt_noise as rwt
    >>> ramp = np.tile(np.linspace(1.0, 0.0, 64), (32, 1))  # white to black
    >>> s = rwt.stipple(ramp, render=True)
    >>> s.tone_error < s.white_noise_tone_error
    True
    """
    counts = {k: None if v is None else _count(v, k, MAX_SEED) for k, v in
              (("dots", dots), ("seed", seed), ("max_dots", max_dots),
               ("max_raster_pixels", max_raster_pixels),
               ("max_image_pixels", max_image_pixels))}
    grey = _grey(image, counts["max_image_pixels"])
    reals = {k: None if v is None else _real(v, k) for k, v in
             (("radius", radius), ("gamma", gamma), ("contrast", contrast), ("scale", scale))}
    points, r, raster, tone = _rwt.stipple(
        grey, render=bool(render), tileset=None if tileset is None else os.fspath(tileset),
        dots=counts["dots"], seed=counts["seed"], max_dots=counts["max_dots"],
        max_raster_pixels=counts["max_raster_pixels"],
        max_image_pixels=counts["max_image_pixels"], radius=reals["radius"],
        gamma=reals["gamma"], contrast=reals["contrast"], scale=reals["scale"])
    blue, white = tone if tone is not None else (None, None)
    return Stipple(points, r, raster, blue, white)


def _real(v: object, what: str) -> float:
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise ValueError(f"{what} must be a number, got {v!r}")
    return float(v)


def _grey(image: object, max_pixels: Optional[int]) -> np.ndarray:
    arr = np.asarray(image)
    if arr.ndim != 2 or arr.size == 0:
        raise ValueError(f"image must be a non-empty 2-D grey array, got shape {arr.shape} "
                         "(for colour, pass its luma, e.g. rgb @ [0.2126, 0.7152, 0.0722])")
    # Checked on the shape, before the float32 copy.
    limit = _rwt.DEFAULT_MAX_IMAGE_PIXELS if max_pixels is None else max_pixels
    if arr.size > limit:
        raise _rwt.BudgetError(f"a {arr.shape[1]}x{arr.shape[0]} image is over the limit of "
                               f"{limit} pixels to stipple (raise max_image_pixels)")
    kind = arr.dtype.kind
    if kind == "b":
        grey = arr.astype(np.float32)
    elif kind == "u":
        grey = arr.astype(np.float32) / np.float32(np.iinfo(arr.dtype).max)
    elif kind == "f":
        grey = arr.astype(np.float32)
    else:
        raise ValueError(f"image must hold grey levels (uint8, uint16, bool or float), "
                         f"got dtype {arr.dtype}")
    return np.ascontiguousarray(grey)

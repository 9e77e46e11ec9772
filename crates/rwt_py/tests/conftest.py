"""Shared test data: seeded images and a minimal PNG writer (no imaging library needed)."""

import struct
import zlib

import numpy as np
import pytest


def write_grey_png(path, pixels: np.ndarray) -> None:
    """Writes an 8-bit grey PNG of ``pixels`` (uint8, row 0 at the top)."""
    h, w = pixels.shape
    raw = b"".join(b"\x00" + pixels[r].astype(np.uint8).tobytes() for r in range(h))

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
                + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def shaded_sphere(size: int = 96) -> np.ndarray:
    """A lit sphere on white, grey levels 0..1 (row 0 at the top): smooth tones, a sharp
    silhouette and a shadowed edge."""
    y, x = np.mgrid[0:size, 0:size]
    u = (x + 0.5) / size * 2 - 1
    v = (y + 0.5) / size * 2 - 1
    r2 = u * u + v * v
    z = np.sqrt(np.clip(1 - r2 / 0.8, 0, 1))
    light = np.clip(0.1 + 0.9 * (-0.5 * u - 0.5 * v + 0.7 * z), 0, 1)
    return np.where(r2 < 0.8, light, 1.0)


@pytest.fixture
def sphere() -> np.ndarray:
    return shaded_sphere()


@pytest.fixture
def ramp_map() -> np.ndarray:
    """A density map: 0..1 left to right, with a bright disc; contains exact 0 and 255."""
    y, x = np.mgrid[0:40, 0:60]
    img = (x / 59.0 * 200).astype(np.uint8)
    img[(x - 40) ** 2 + (y - 15) ** 2 < 64] = 255
    return img

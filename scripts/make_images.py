#!/usr/bin/env python3
"""Draws the project's own test images (no third-party data): a shaded sphere on a gradient
(`rwt stipple`, the quickstart and stipple_zoom examples) and a painted bush map with meadows
and a winding valley (open_world). Standard library only."""
import math, struct, zlib, pathlib

def png(path, w, h, pixels):
    raw = b"".join(b"\x00" + bytes(pixels[y * w:(y + 1) * w]) for y in range(h))
    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xffffffff)
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0))
    data += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    pathlib.Path(path).write_bytes(data)

def sphere(w=384, h=384):
    px = []
    light = (-0.5, 0.6, 0.62)
    for y in range(h):
        for x in range(w):
            u, v = (x + 0.5) / w * 2 - 1, 1 - (y + 0.5) / h * 2
            g = 0.92 - 0.35 * (y / h)  # background: light at the top, darker below
            # a soft ground shadow
            sx, sy = (u - 0.25) / 0.75, (v + 0.78) / 0.16
            if sx * sx + sy * sy < 1:
                g *= 0.55 + 0.45 * (sx * sx + sy * sy)
            r2 = (u / 0.72) ** 2 + ((v - 0.08) / 0.72) ** 2
            if r2 < 1:
                nz = math.sqrt(1 - r2)
                nx, ny = u / 0.72, (v - 0.08) / 0.72
                lam = max(0.0, nx * light[0] + ny * light[1] + nz * light[2])
                spec = max(0.0, nz * 0.9 + nx * -0.3 + ny * 0.3) ** 40
                g = min(1.0, 0.08 + 0.82 * lam + 0.6 * spec)
            px.append(int(max(0, min(255, g * 255))))
    return w, h, px

def meadows(w=256, h=256):
    """Bush density over open_world's central 6 km: soft blobs of meadow, empty along a
    winding valley, fading out towards the map's border."""
    blobs = [(0.3, 0.35, 0.12), (0.62, 0.3, 0.09), (0.7, 0.68, 0.14), (0.35, 0.72, 0.1),
             (0.5, 0.5, 0.07), (0.15, 0.55, 0.06), (0.85, 0.45, 0.07)]
    px = []
    for y in range(h):
        for x in range(w):
            u, v = (x + 0.5) / w, (y + 0.5) / h
            g = 0.15
            for bx, by, r in blobs:
                d2 = ((u - bx) ** 2 + (v - by) ** 2) / (r * r)
                g += 0.85 * math.exp(-d2)
            valley = abs(v - (0.5 + 0.18 * math.sin(u * 9.0)))
            g *= min(1.0, valley / 0.04)
            edge = min(u, v, 1 - u, 1 - v) / 0.1
            g *= min(1.0, edge)
            px.append(int(max(0, min(255, g * 255))))
    return w, h, px

if __name__ == "__main__":
    out = pathlib.Path(__file__).resolve().parent.parent / "assets" / "images"
    out.mkdir(parents=True, exist_ok=True)
    w, h, px = sphere()
    png(out / "sphere.png", w, h, px)
    print("wrote", out / "sphere.png")
    w, h, px = meadows()
    png(out / "meadows.png", w, h, px)
    print("wrote", out / "meadows.png")

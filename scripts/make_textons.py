#!/usr/bin/env python3
"""Draws the texton images of the paint_density example (paper figure 10) into
assets/textons/: a leaf, a pebble, a flower and a starfish, 64x64 RGBA with soft edges
(4x4 supersampling). Our own drawings; standard library only."""
import math, pathlib, struct, zlib

SIZE, SS = 64, 4

def png_rgba(path, w, h, px):
    raw = b"".join(b"\x00" + bytes(v for p in px[y * w:(y + 1) * w] for v in p) for y in range(h))
    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xffffffff)
    out = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
    out += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    pathlib.Path(path).write_bytes(out)

def render(shade):
    """shade(u, v) -> (r, g, b, a) or None, u, v in [-1, 1] (v up); averaged over SSxSS."""
    px = []
    for y in range(SIZE):
        for x in range(SIZE):
            acc = [0.0] * 4
            for sy in range(SS):
                for sx in range(SS):
                    u = ((x + (sx + 0.5) / SS) / SIZE) * 2 - 1
                    v = 1 - ((y + (sy + 0.5) / SS) / SIZE) * 2
                    c = shade(u, v)
                    if c:
                        for k in range(3):
                            acc[k] += c[k] * c[3]
                        acc[3] += c[3]
            n = SS * SS
            a = acc[3] / n
            rgb = [acc[k] / acc[3] if acc[3] > 0 else 0 for k in range(3)]
            px.append(tuple(int(max(0, min(255, round(c * 255)))) for c in rgb + [a]))
    return px

def leaf(u, v):
    # Pointed ellipse along the diagonal, darker midrib and veins, short stem.
    a = math.radians(35)
    x, y = u * math.cos(a) + v * math.sin(a), -u * math.sin(a) + v * math.cos(a)
    half = 0.42 * math.sqrt(max(0.0, 1 - (x / 0.85) ** 2)) * (1 - 0.35 * max(0, x))
    if abs(y) < half and abs(x) < 0.85:
        vein = abs(y) < 0.03 or abs((y - 0.0) - 0.6 * abs(x - round(x / 0.25) * 0.25)) < 0.02
        g = 0.55 - 0.25 * (abs(y) / max(half, 1e-6))
        return (0.18, 0.3 + g * 0.6, 0.12, 1.0) if not vein else (0.12, 0.32, 0.08, 1.0)
    if -0.98 < x < -0.8 and abs(y) < 0.03:
        return (0.35, 0.25, 0.1, 1.0)
    return None

def pebble(u, v):
    r = math.hypot(u / 0.85, v / 0.62) + 0.05 * math.sin(5 * math.atan2(v, u))
    if r < 1:
        light = 0.55 + 0.35 * (-u * 0.5 + v * 0.7) * (1 - r) + 0.15 * (1 - r)
        speck = 0.06 if (math.sin(u * 23) * math.sin(v * 19)) > 0.85 else 0.0
        c = 0.45 + 0.4 * light - speck
        return (c * 0.95, c * 0.93, c * 0.9, 1.0)
    return None

def flower(u, v):
    r, t = math.hypot(u, v), math.atan2(v, u)
    if r < 0.22:
        return (0.95, 0.7, 0.1, 1.0) if r < 0.17 else (0.75, 0.45, 0.05, 1.0)
    petal = 0.62 + 0.3 * abs(math.cos(2.5 * t))
    if r < petal:
        shade = 0.85 + 0.15 * (1 - r / petal)
        return (0.95 * shade, 0.45 * shade, 0.6 * shade, 1.0)
    return None

def starfish(u, v):
    r, t = math.hypot(u, v), math.atan2(v, u) + math.pi / 2
    arm = 0.3 + 0.62 * abs(math.cos(2.5 * t)) ** 3
    if r < arm:
        dots = (math.sin(u * 30) * math.sin(v * 30)) > 0.7
        k = 1 - 0.35 * r
        return (0.93 * k, 0.42 * k, 0.15 * k, 1.0) if not dots else (0.98, 0.75, 0.5, 1.0)
    return None

if __name__ == "__main__":
    out = pathlib.Path(__file__).resolve().parent.parent / "assets" / "textons"
    out.mkdir(parents=True, exist_ok=True)
    for name, f in [("leaf", leaf), ("pebble", pebble), ("flower", flower), ("starfish", starfish)]:
        png_rgba(out / f"{name}.png", SIZE, SIZE, render(f))
        print("wrote", out / f"{name}.png")

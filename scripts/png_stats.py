#!/usr/bin/env python3
"""Reads an 8-bit PNG (grey, RGB or RGBA, not interlaced) with the standard library only and
prints `WIDTH HEIGHT VARIANCE` (variance of luminance over all pixels, 0..255 scale).
`--half OUT.png` also writes the image at half size (2x2 box filter), for the README."""
import struct, sys, zlib

def read(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, hdr = 8, b"", None
    while pos < len(data):
        n, tag = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if tag == b"IHDR":
            hdr = struct.unpack(">IIBBBBB", body)
        elif tag == b"IDAT":
            idat += body
        pos += 12 + n
    w, h, depth, ctype, _, _, interlace = hdr
    assert depth == 8 and interlace == 0 and ctype in (0, 2, 6), "unsupported PNG"
    bpp = {0: 1, 2: 3, 6: 4}[ctype]
    raw = zlib.decompress(idat)
    stride = w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    rgb = [[(r[x * bpp], r[x * bpp + (1 if bpp > 2 else 0)], r[x * bpp + (2 if bpp > 2 else 0)])
            for x in range(w)] for r in rows]
    return w, h, rgb

def write(path, w, h, rgb):
    raw = b"".join(b"\x00" + bytes(v for px in row for v in px) for row in rgb)
    def chunk(tag, body):
        return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body) & 0xffffffff)
    out = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    out += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    open(path, "wb").write(out)

if __name__ == "__main__":
    w, h, rgb = read(sys.argv[1])
    lum = [0.299 * r + 0.587 * g + 0.114 * b for row in rgb for (r, g, b) in row]
    mean = sum(lum) / len(lum)
    var = sum((v - mean) ** 2 for v in lum) / len(lum)
    print(w, h, round(var, 2))
    if len(sys.argv) > 3 and sys.argv[2] == "--half":
        half = [[tuple(sum(rgb[2 * y + dy][2 * x + dx][k] for dy in (0, 1) for dx in (0, 1)) // 4
                       for k in range(3)) for x in range(w // 2)] for y in range(h // 2)]
        write(sys.argv[3], w // 2, h // 2, half)

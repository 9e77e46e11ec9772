#!/usr/bin/env python3
"""The hostile pass: several hundred inputs and signals a hostile or unlucky user could give
rwt's command line, its Python package and the files the plugin reads (tile sets, layer
files, edits, brush saves, images). Each case runs in its own process; the pass records its
exit status, the first line of its standard error, its peak memory and its time, and flags
what must never happen: a panic, an abort or a crash by signal, more than 60 s, more than
500 MB, a temporary file left behind, a previous output changed.

    scripts/hostile_pass.py                    # build what it needs, print the table
    scripts/hostile_pass.py --update TESTING.md  # and rewrite the table there

Needs `rwt` (target/debug/rwt), the plugin's file reader (the `read_file` example of
bevy_rwt) and the Python package in target/py-venv (scripts/python_env.sh); it builds the
first two. Standard library only.
"""

import argparse
import os
import pathlib
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib

ROOT = pathlib.Path(__file__).resolve().parent.parent
LIMIT_S = 60.0
LIMIT_MB = 500.0
BEGIN = "<!-- hostile-pass:begin -->"
END = "<!-- hostile-pass:end -->"


# ---------------------------------------------------------------- running one case

class Result:
    def __init__(self, group, name, code, first, peak_mb, seconds, flags):
        self.group, self.name, self.code, self.first = group, name, code, first
        self.peak_mb, self.seconds, self.flags = peak_mb, seconds, flags


def run(argv, cwd, timeout=LIMIT_S, env=None, on_start=None):
    """Runs `argv`; returns (exit code or -signal, stdout, stderr, peak MB, seconds,
    timed out). `on_start(pid)` runs once the process exists (signals are sent to that pid).

    The case runs under GNU time, which reports its peak memory: a process forked from this
    one would count this one's memory as its own (Linux keeps the high-water mark across
    fork and exec)."""
    out = tempfile.TemporaryFile()
    err = tempfile.TemporaryFile()
    peak_file = tempfile.NamedTemporaryFile(delete=False)
    peak_file.close()
    started = time.monotonic()
    proc = subprocess.Popen(["/usr/bin/time", "-f", "%M", "-o", peak_file.name, *argv],
                            cwd=cwd, stdout=out, stderr=err, stdin=subprocess.DEVNULL, env=env)
    child = None
    while child is None and time.monotonic() - started < 5:
        try:
            kids = pathlib.Path(f"/proc/{proc.pid}/task/{proc.pid}/children").read_text().split()
            child = int(kids[0]) if kids else None
        except (OSError, ValueError):
            pass
        if child is None:
            time.sleep(0.001)
    if on_start and child:
        on_start(child)
    timed_out = False
    while proc.poll() is None:
        if time.monotonic() - started > timeout:
            timed_out = True
            for pid in (child, proc.pid):
                try:
                    os.kill(pid, signal.SIGKILL)
                except (ProcessLookupError, TypeError):
                    pass
            proc.wait()
            break
        time.sleep(0.01)
    seconds = time.monotonic() - started
    out.seek(0)
    err.seek(0)
    text = err.read().decode(errors="replace")
    code = proc.returncode
    # GNU time exits with the child's status; its report says when a signal ended it.
    try:
        report = pathlib.Path(peak_file.name).read_text().splitlines()
        peak_kb = float(report[-1])
    except (OSError, ValueError, IndexError):
        report, peak_kb = [], 0.0
    for line in report:
        if line.startswith("Command terminated by signal "):
            code = -int(line.split()[-1])
    os.unlink(peak_file.name)
    return (code, out.read().decode(errors="replace"), text, peak_kb / 1024.0, seconds, timed_out)


def first_line(text):
    for line in text.splitlines():
        line = line.strip()
        if line and not line.startswith("Traceback"):
            return line
    return ""


def judge(group, name, outcome, cwd=None, extra_flags=()):
    code, out, err, peak, seconds, timed_out = outcome
    flags = list(extra_flags)
    if code == 101 or "panicked" in err or "PanicException" in err:
        flags.append("PANIC")
    # A crash (SIGSEGV, SIGABRT...); the signals cases send the others themselves.
    if code < 0 and not timed_out and -code not in (signal.SIGINT, signal.SIGTERM,
                                                    signal.SIGHUP, signal.SIGKILL):
        flags.append(f"SIGNAL {-code}")
    if timed_out:
        flags.append("HANG")
    if peak > LIMIT_MB:
        flags.append("MEMORY")
    if cwd is not None:
        left = [p.name for p in pathlib.Path(cwd).rglob("*.rwt-tmp")]
        if left:
            flags.append("TEMP LEFT")
    text = first_line(err) or first_line(out)
    return Result(group, name, code, text, peak, seconds, flags)


# ---------------------------------------------------------------- inputs

def png(path, width, height, rows, depth=8, colour=0, interlace=0):
    """Writes a PNG whose scanlines come from `rows()` (bytes per row, no filter byte),
    deflated as they come: a huge image never exists whole here."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(
            ">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    packer = zlib.compressobj(9)
    body = []
    for row in rows():
        body.append(packer.compress(b"\x00" + row))
    body.append(packer.flush())
    header = struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, interlace)
    pathlib.Path(path).write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header)
                                   + chunk(b"IDAT", b"".join(body)) + chunk(b"IEND", b""))


def flat_png(path, width, height, value=0, depth=8, colour=0):
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[colour]
    row = bytes([value]) * (width * channels * depth // 8)
    png(path, width, height, lambda: (row for _ in range(height)), depth, colour)


def png_header_only(path, width, height, depth=8, colour=0):
    header = struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, 0)
    ihdr = b"IHDR" + header
    data = (b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + ihdr
            + struct.pack(">I", zlib.crc32(ihdr) & 0xFFFFFFFF))
    pathlib.Path(path).write_bytes(data + b"\x00\x00\x00\x00IDAT\x35\xaf\x06\x1e")


def make_images(d):
    d.mkdir()
    flat_png(d / "grey.png", 64, 48, 90)
    flat_png(d / "black1.png", 1, 1, 0)
    flat_png(d / "thin_h.png", 20000, 1, 0)
    flat_png(d / "thin_v.png", 1, 20000, 0)
    flat_png(d / "big_grey.png", 8192, 8192, 0)
    flat_png(d / "big_rgba.png", 8192, 8192, 0, 8, 6)
    flat_png(d / "big_rgba16.png", 8192, 8192, 0, 16, 6)
    flat_png(d / "mid_rgb.png", 4096, 4096, 0, 8, 2)
    flat_png(d / "dark_2048.png", 2048, 2048, 60)
    flat_png(d / "huge.png", 20000, 20000, 0)
    flat_png(d / "grey16.png", 300, 200, 0, 16, 0)
    flat_png(d / "grey_alpha.png", 300, 200, 0, 8, 4)
    flat_png(d / "white.png", 64, 64, 255)
    png_header_only(d / "claims_65535.png", 65535, 65535)
    png_header_only(d / "claims_zero.png", 0, 10)
    png_header_only(d / "claims_1x1e9.png", 1, 1_000_000_000)
    png_header_only(d / "bad_depth.png", 10, 10, 7, 0)
    png_header_only(d / "bad_colour.png", 10, 10, 8, 5)
    good = (d / "grey.png").read_bytes()
    (d / "truncated.png").write_bytes(good[: len(good) // 2])
    (d / "header.png").write_bytes(good[:8])
    flipped = bytearray(good)
    flipped[40] ^= 0xFF
    (d / "bad_crc.png").write_bytes(bytes(flipped))
    (d / "empty.png").write_bytes(b"")
    (d / "text.png").write_bytes(b"this is not an image\n" * 100)
    (d / "jpeg_header.jpg").write_bytes(b"\xff\xd8\xff\xe0\x00\x10JFIF\x00" + b"\x00" * 64)
    (d / "gif_huge.gif").write_bytes(b"GIF89a" + struct.pack("<HH", 65535, 65535) + b"\x00" * 32)
    (d / "bmp_huge.bmp").write_bytes(b"BM" + struct.pack("<IHHI", 0, 0, 0, 54)
                                     + struct.pack("<IiiHHIIiiII", 40, 60000, 60000, 1, 24, 0,
                                                   0, 0, 0, 0, 0))
    (d / "zeros.bin").write_bytes(bytes(1 << 20))
    os.mkfifo(d / "fifo.png")
    os.symlink("loop_b.png", d / "loop_a.png")
    os.symlink("loop_a.png", d / "loop_b.png")
    os.symlink("missing.png", d / "dangling.png")


def tileset_variants(d, default_ron):
    d.mkdir()
    text = default_ron.read_text()
    out = {}

    def put(name, body):
        p = d / name
        p.write_bytes(body if isinstance(body, bytes) else body.encode())
        out[name] = p

    put("default.ron", text)
    for frac in (0.0, 0.001, 0.1, 0.3, 0.5, 0.7, 0.9, 0.999):
        put(f"cut_{frac}.ron", text[: int(len(text) * frac)])
    raw = text.encode()
    for k, at in enumerate((10, 200, 5000, len(raw) // 3, len(raw) // 2, len(raw) - 10)):
        b = bytearray(raw)
        b[at] ^= 0x55
        put(f"flip_{k}.ron", bytes(b))
    head = text.index("horizontal_sequences:[") + len("horizontal_sequences:[")
    put("empty_sequences.ron", text[:head] + "[]," * 3_000_000 + text[head:])
    put("nested_deep.ron", "[" * 200_000 + "]" * 200_000)
    put("nested_tiles.ron", text.replace("tiles:[", "tiles:[" + "(" * 50_000, 1))
    seam = text.index("seams:[[") + len("seams:[[")
    for name, v in (("seam_1e30", "(0.5,1e30)"), ("seam_nan", "(0.5,NaN)"),
                    ("seam_neg", "(-0.5,0.5)"), ("seam_inf", "(inf,0.5)")):
        put(f"{name}.ron", text[:seam] + v + "," + text[seam:])
    for field, values in (("colors", ("0", "9", "255")), ("subdivision", ("0", "3", "16", "255")),
                          ("points_per_tile", ("0", "70000", "4294967295")),
                          ("format", ("0", "2", "4294967295"))):
        import re
        m = re.search(field + r":(\d+)", text)
        for v in values:
            put(f"{field}_{v}.ron", text[: m.start(1)] + v + text[m.end(1):])
    put("huge_number.ron", text.replace("seed:", "seed:" + "9" * 100000 + "0", 1))
    put("only_header.ron", "(format:1,colors:2)")
    put("utf16.ron", text[:2000].encode("utf-16"))
    put("binary.ron", bytes(range(256)) * 400)
    put("empty.ron", "")
    put("big.ron", " " * (129 << 20))
    return out


def layer_variants(d):
    d.mkdir()
    good = """(
    tile_size: 4.0, seed: 9, chunk_size: 16.0, load_distance: 48.0, unload_distance: 64.0,
    falloff: (20.0, 60.0),
    classes: [
        (density: Constant(0.4), mesh: Cone(radius: 0.5, height: 2.0), material: Color(0.1, 0.5, 0.1)),
        (density: Noise(seed: 1, frequency: 0.1, octaves: 3, base: 0.5, amplitude: 0.5, scale: 0.2),
         mesh: Sphere(radius: 0.3), material: Color(0.6, 0.2, 0.2), scale: 1.5),
    ],
)"""
    cases = {"good": good}
    for field, value, bad in (("tile_size", "4.0", ["0.0", "-1.0", "NaN", "inf", "1e300", "1e-300"]),
                              ("load_distance", "48.0", ["0.0", "-5.0", "NaN", "1e300", "inf"]),
                              ("unload_distance", "64.0", ["1.0", "NaN", "1e308"]),
                              ("chunk_size", "16.0", ["0.0", "-16.0", "1e-300", "NaN", "1e300"]),
                              ("seed", "9", ["-1", "18446744073709551616", "1.5"])):
        for b in bad:
            cases[f"{field}={b}"] = good.replace(f"{field}: {value}", f"{field}: {b}", 1)
    cases["falloff inverted"] = good.replace("(20.0, 60.0)", "(60.0, 20.0)")
    cases["falloff NaN"] = good.replace("(20.0, 60.0)", "(NaN, 60.0)")
    cases["density 1e308"] = good.replace("Constant(0.4)", "Constant(1e308)")
    cases["density -1"] = good.replace("Constant(0.4)", "Constant(-1.0)")
    cases["density NaN"] = good.replace("Constant(0.4)", "Constant(NaN)")
    cases["noise frequency 1e300"] = good.replace("frequency: 0.1", "frequency: 1e300")
    cases["noise octaves 1000"] = good.replace("octaves: 3", "octaves: 1000")
    cases["mesh radius NaN"] = good.replace("radius: 0.5", "radius: NaN")
    cases["mesh height 1e30"] = good.replace("height: 2.0", "height: 1e30")
    cases["scale -1"] = good.replace("scale: 1.5", "scale: -1.5")
    cases["no classes"] = good[: good.index("classes:")] + "classes: [])"
    cls = "(density: Constant(0.1), mesh: Sphere(radius: 0.3), material: Color(0.6, 0.2, 0.2)),"
    cases["5000 classes"] = good.replace("classes: [", "classes: [" + cls * 5000, 1)
    cases["70000 classes"] = good.replace("classes: [", "classes: [" + "(" * 0 + cls * 70000, 1)
    cases["unknown field"] = good.replace("seed: 9,", "seed: 9, wobble: 3,")
    cases["missing mesh name"] = good.replace("Cone(radius: 0.5, height: 2.0)", "Named(\"nowhere\")")
    cases["image map missing"] = good.replace(
        "Constant(0.4)", "Image(path: \"missing.png\", min: (0.0, 0.0), size: (8.0, 8.0), scale: 1.0)")
    cases["image size NaN"] = good.replace(
        "Constant(0.4)", "Image(path: \"m.png\", min: (0.0, 0.0), size: (NaN, 8.0), scale: 1.0)")
    cases["cut short"] = good[: len(good) // 2]
    cases["deep nesting"] = "(" * 100_000
    cases["empty"] = ""
    cases["binary"] = "\x00\x01\x02" * 1000
    cases["over 1 MiB"] = good + " " * (1 << 20)
    paths = {}
    for k, (name, text) in enumerate(cases.items()):
        p = d / f"case{k}.layer.ron"
        p.write_text(text)
        paths[name] = p
    return paths


def varint(v):
    out = bytearray()
    while v >= 0x80:
        out.append((v & 0x7F) | 0x80)
        v >>= 7
    out.append(v)
    return bytes(out)


def edits_file(stamp, records, count=None, version=1, magic=b"RWTE", tail=b""):
    """An edits file: records are (level, x, y, index, class or None), written as level
    steps (the format's most general record)."""
    seed, fingerprint = stamp
    body = bytearray(magic + bytes([version]) + struct.pack("<QQ", seed, fingerprint))
    body += varint(len(records) if count is None else count)
    zig = lambda v: ((v << 1) ^ (v >> 63)) & 0xFFFFFFFFFFFFFFFF
    for level, x, y, index, cls in records:
        body += varint(3 << 1 | (cls is not None))
        body += varint(level) + varint(zig(x)) + varint(zig(y)) + varint(index)
        if cls is not None:
            body += varint(cls)
    body += tail
    return bytes(body) + struct.pack("<I", zlib.crc32(bytes(body)) & 0xFFFFFFFF)


def edits_variants(d, stamp):
    d.mkdir()
    ok = [(0, i, 0, 3, None) for i in range(100)] + [(2, 5, -7, 9, 4)]
    cases = {
        "good": edits_file(stamp, ok),
        "other seed": edits_file((stamp[0] + 1, stamp[1]), ok),
        "other tile set": edits_file((stamp[0], stamp[1] ^ 1), ok),
        "version 2": edits_file(stamp, ok, version=2),
        "bad magic": edits_file(stamp, ok, magic=b"RWTX"),
        "level 25": edits_file(stamp, [(25, 0, 0, 0, None)]),
        "level 255": edits_file(stamp, [(255, 0, 0, 0, None)]),
        "out of order": edits_file(stamp, [(0, 5, 0, 0, None), (0, 1, 0, 0, None)]),
        "duplicate": edits_file(stamp, [(0, 5, 0, 0, None), (0, 5, 0, 0, None)]),
        "count 33.5 M": edits_file(stamp, ok, count=33_554_432),
        "count 4 M + 1": edits_file(stamp, ok, count=4_000_001),
        "count 2^64-1": edits_file(stamp, ok, count=2**64 - 1),
        "count short": edits_file(stamp, ok, count=50),
        "count long": edits_file(stamp, ok, count=500),
        "trailing bytes": edits_file(stamp, ok, tail=b"\x00\x00"),
        "index 65536": edits_file(stamp, [(0, 0, 0, 65536, None)]),
        "class 70000": edits_file(stamp, [(0, 0, 0, 1, 70000)]),
        "varint of 11 bytes": edits_file(stamp, [], count=0, tail=b"\xff" * 11),
        "empty": b"",
        "magic only": b"RWTE",
        "header only": b"RWTE\x01" + bytes(16),
    }
    good = cases["good"]
    for k in (1, 5, 21, 22, len(good) // 2, len(good) - 4, len(good) - 1):
        cases[f"cut at {k}"] = good[:k]
    for k in (0, 4, 5, 13, 21, 30, len(good) - 2):
        b = bytearray(good)
        b[k] ^= 0x40
        cases[f"flip byte {k}"] = bytes(b)
    # 33.5 million two-byte records within the 64 MiB limit (took 1.9 GB).
    big = bytearray(b"RWTE\x01" + struct.pack("<QQ", *stamp)) + varint(33_554_432)
    big += bytes([3 << 1, 0, 0, 0, 0]) + b"\x00\x01" * 33_554_431
    cases["33.5 M records, 64 MiB"] = bytes(big) + struct.pack("<I", zlib.crc32(big) & 0xFFFFFFFF)
    cases["over 64 MiB"] = bytes((64 << 20) + 1)
    paths = {}
    for k, (name, data) in enumerate(cases.items()):
        p = d / f"case{k}.edits"
        p.write_bytes(data)
        paths[name] = p
    return paths


def save_variants(d, stamp, images, layer_good):
    d.mkdir()
    out = {}

    def save(name, index, files=()):
        s = d / name.replace(" ", "_")
        s.mkdir()
        if index is not None:
            (s / "painted.ron").write_text(index)
        for fname, data in files:
            p = s / fname
            if data == "FIFO":
                os.mkfifo(p)
            elif data == "DIR":
                p.mkdir()
            else:
                p.write_bytes(data)
        out[name] = s

    grey16 = (images / "grey16.png").read_bytes()
    edits = edits_file(stamp, [(0, 1, 2, 3, None)])
    layer = layer_good.read_bytes()
    entry = ('(name: "grass", map: (path: "{p}", min: (0.0, 0.0), size: (64.0, 64.0), '
             'scale: 1.0))')
    index = lambda maps, layers="[]", edits_list="[]": (
        f"(maps: [{', '.join(maps)}], layers: {layers}, edits: {edits_list})")
    good = index([entry.format(p="grass.png")], '["grass.layer.ron"]',
                 '[(layer: "grass", file: "grass.edits")]')
    full = [("grass.png", grey16), ("grass.layer.ron", layer), ("grass.edits", edits)]
    save("good", good, full)
    save("no index", None, full)
    save("empty index", "", full)
    save("index is a folder", None, [("painted.ron", "DIR")])
    save("index is a FIFO", None, [("painted.ron", "FIFO")])
    save("index cut short", good[: len(good) // 2], full)
    save("index over 1 MiB", good + " " * (2 << 20), full)
    save("map outside folder", index([entry.format(p="../grass.png")]), full)
    save("map absolute", index([entry.format(p="/etc/passwd")]), full)
    save("map missing", index([entry.format(p="nothere.png")]), full)
    save("map is a FIFO", index([entry.format(p="pipe.png")]), full + [("pipe.png", "FIFO")])
    save("map truncated", good, [("grass.png", grey16[:60])] + full[1:])
    save("map is text", good, [("grass.png", b"not a png" * 10)] + full[1:])
    save("map claims 65535 squared", good,
         [("grass.png", (images / "claims_65535.png").read_bytes())] + full[1:])
    save("map 20000 squared", good, [("grass.png", (images / "huge.png").read_bytes())] + full[1:])
    save("layer file missing", good, [full[0], full[2]])
    save("layer file broken", good, [full[0], ("grass.layer.ron", b"(classes: ["), full[2]])
    save("layer file outside", index([], '["../x.layer.ron"]'), full)
    save("edits cut short", good, full[:2] + [("grass.edits", edits[:10])])
    save("edits for another seed", good,
         full[:2] + [("grass.edits", edits_file((stamp[0] + 5, stamp[1]), [(0, 1, 2, 3, None)]))])
    save("edits outside", index([], "[]", '[(layer: "grass", file: "../e.edits")]'), full)
    save("10000 maps", index([entry.format(p="grass.png")] * 10000), full)
    save("journal garbage", good, full + [(".rwt-commit.ron", b"garbage")])
    save("journal outside", good,
         full + [(".rwt-commit.ron", b'[(temp: "../../x", name: "painted.ron")]')])
    save("stale temporaries", good, full + [(".grass.png.1-1.rwt-tmp", b"junk" * 1000)])
    return out


# ---------------------------------------------------------------- the cases

def cli_cases(rwt, work, images, sets):
    """(group, name, argv, cwd) of the command line."""
    def points(*extra, rect=("0", "0", "8", "8"), density="const:5"):
        return [rwt, "points", "--rect", *rect, "--density", density, *extra]

    c = []
    sdir = sets["default.ron"].parent
    add = lambda name, argv: c.append(("cli points", name, argv))
    add("no --rect", [rwt, "points", "--density", "const:1"])
    add("no --density", [rwt, "points", "--rect", "0", "0", "1", "1"])
    add("three rect numbers", [rwt, "points", "--rect", "0", "0", "1", "--density", "const:1"])
    for rect in (("NaN", "0", "1", "1"), ("0", "0", "inf", "1"), ("1", "1", "0", "0"),
                 ("0", "0", "0", "0"), ("-1e300", "-1e300", "1e300", "1e300"),
                 ("0", "0", "1e-300", "1e-300"), ("9e11", "0", "900000000000.01", "0.01"),
                 ("1e15", "1e15", "1000000000000001", "1000000000000001"),
                 ("0", "0", "1e6", "1e6"), ("abc", "0", "1", "1"), ("0x10", "0", "1", "1")):
        add("rect " + " ".join(rect), points(rect=rect))
    for d in ("const:-1", "const:NaN", "const:inf", "const:1e308", "const:0", "const:",
              "const:5:garbage", "wobble:3", "", ":", "noise:5:0.1:4.7", "noise:5:0:4",
              "noise:5:1e300:4", "noise:5:0.1:0", "noise:5:0.1:17", "noise:5:0.1:4:-1",
              "noise:5:0.1:4:4294967296", "noise:1e308", "image:", "image:nothere.png",
              f"image:{images}/fifo.png", "image:/dev/zero", f"image:{images}",
              f"image:{images}/loop_a.png", f"image:{images}/dangling.png",
              f"image:{images}/truncated.png", f"image:{images}/header.png",
              f"image:{images}/bad_crc.png", f"image:{images}/empty.png",
              f"image:{images}/text.png", f"image:{images}/jpeg_header.jpg",
              f"image:{images}/gif_huge.gif", f"image:{images}/bmp_huge.bmp",
              f"image:{images}/zeros.bin", f"image:{images}/claims_65535.png",
              f"image:{images}/claims_zero.png", f"image:{images}/claims_1x1e9.png",
              f"image:{images}/bad_depth.png", f"image:{images}/bad_colour.png",
              f"image:{images}/huge.png", f"image:{images}/big_grey.png",
              f"image:{images}/big_rgba.png", f"image:{images}/big_rgba16.png",
              f"image:{images}/mid_rgb.png", f"image:{images}/grey16.png:1e308",
              f"image:{images}/grey_alpha.png:-5", f"dark:{images}/white.png:NaN",
              f"image:{images}/thin_h.png"):
        add(f"density {d.replace(str(images) + '/', '')[:48]}", points(density=d))
    for opt in (("--seed", "-1"), ("--seed", "18446744073709551616"),
                ("--tile-size", "0"), ("--tile-size", "-1"), ("--tile-size", "NaN"),
                ("--tile-size", "1e-300"), ("--tile-size", "1e300"), ("--tile-size", "1.9e185"),
                ("--budget", "0"), ("--budget", "-1"), ("--budget", "18446744073709551615"),
                ("--tileset", "/dev/zero"), ("--tileset", f"{sdir}/cut_0.5.ron"),
                ("--tileset", f"{sdir}/empty_sequences.ron"), ("--tileset", f"{sdir}/seam_1e30.ron"),
                ("--tileset", f"{sdir}/nested_deep.ron"), ("--tileset", str(sdir)),
                ("--out", "/dev/full"), ("--out", "."), ("--out", ""), ("--out", "/"),
                ("--out", "no/such/../dir/x.txt"), ("--out", "p" * 255),
                ("--out", "p" * 256), ("--out", "-dash.txt"), ("--out", "new\nline.txt"),
                ("--out", "/proc/version"), ("--out", "/dev/null")):
        add(f"{opt[0]} {opt[1][:40]!s}", points(*opt))
    add("huge budget, huge rect (killed at 20 s)", points(
        "--budget", "1000000000000", "--out", "/dev/null",
        rect=("-1e5", "-1e5", "1e5", "1e5"), density="const:0.5"))

    add = lambda name, argv: c.append(("cli stipple", name, argv))
    g = f"{images}/grey.png"
    for extra in ((), ("--points", "0"), ("--points", "1"), ("--points", "18446744073709551615"),
                  ("--radius", "0"), ("--radius", "-2"), ("--radius", "NaN"), ("--radius", "1e-9"),
                  ("--radius", "1e300"), ("--radius", "1e-6", "--max-dots", "18446744073709551615"),
                  ("--radius", "0.05", "--max-dots", "18446744073709551615"),
                  ("--scale", "0"), ("--scale", "1e-300"), ("--scale", "0.01"), ("--scale", "1e4"),
                  ("--scale", "1e4", "--max-raster-pixels", "18446744073709551615"),
                  ("--scale", "NaN"), ("--gamma", "0"), ("--gamma", "NaN"), ("--gamma", "1e300"),
                  ("--contrast=-1",), ("--contrast", "inf"), ("--seed", "-3"),
                  ("--max-dots", "0"), ("--max-raster-pixels", "0"), ("--max-image-pixels", "0"),
                  ("--points", "5", "--radius", "2")):
        c.append(("cli stipple", "grey " + " ".join(extra)[:60],
                  [rwt, "stipple", g, "--out", "s.png", *extra]))
    for name in ("black1.png", "thin_h.png", "thin_v.png", "white.png", "big_grey.png",
                 "big_rgba16.png", "huge.png", "truncated.png", "claims_65535.png",
                 "claims_1x1e9.png", "gif_huge.gif", "bmp_huge.bmp", "text.png", "empty.png",
                 "fifo.png", "loop_a.png", "dangling.png", "mid_rgb.png", "grey16.png",
                 "grey_alpha.png"):
        add(f"image {name}", [rwt, "stipple", f"{images}/{name}", "--out", "s.png"])
    add("image /dev/zero", [rwt, "stipple", "/dev/zero", "--out", "s.png"])
    add("big_grey at scale 0.5, radius 5", [rwt, "stipple", f"{images}/big_grey.png", "--out",
                                            "s.png", "--scale", "0.5", "--radius", "5"])
    for out in ("s.jpg", "s", "s.PNG", "s.SVG", "s.svg.txt", "/dev/full", "."):
        add(f"--out {out}", [rwt, "stipple", g, "--out", out])

    add = lambda name, argv: c.append(("cli analyse", name, argv))
    def points_file(name, text):
        p = work / name
        p.write_text(text) if isinstance(text, str) else p.write_bytes(text)
        return str(p)
    grid = "".join(f"{(i * 37) % 100 * 0.1} {(i * 91) % 100 * 0.1}\n" for i in range(1000))
    for name, text in (("empty", ""), ("15 points", grid[:15 * 10]), ("one point x1000",
                       "1 1\n" * 1000), ("line", "".join(f"{i} 0\n" for i in range(1000))),
                       ("tiny extent", "".join(f"{i * 1e-310:e} {(i * 7 % 100) * 1e-310:e}\n"
                                               for i in range(100))),
                       ("vast extent", "".join(f"{(i - 50) * 1e300:e} {((i * 7) % 100 - 50) * 1e300:e}\n"
                                               for i in range(100))),
                       ("far away", "".join(f"{1e15 + i} {1e15 + (i * 7) % 100}\n" for i in range(100))),
                       ("NaN", "NaN 1\n" * 100), ("inf", "inf 1\n" * 100),
                       ("one column", "1\n" * 100), ("words", "hello world\n" * 100),
                       ("CRLF", grid.replace("\n", "\r\n")), ("binary", bytes(range(256)) * 100),
                       ("UTF-16", grid.encode("utf-16")), ("good", grid),
                       ("long line", b"1" * (20 << 20)), ("no newline", grid.rstrip("\n")),
                       ("huge numbers", "1e308 1e308\n-1e308 -1e308\n" * 50)):
        add(name, [rwt, "analyse", points_file(f"pts_{name.replace(' ', '_')}.txt", text)])
    for f in ("/dev/zero", "/dev/null", str(images / "fifo.png"), str(work), "nothere.txt"):
        add(f"file {f}", [rwt, "analyse", f])
    for plot in ("p.svg", "p", "/dev/full", "p.png"):
        add(f"--plot {plot}", [rwt, "analyse", str(work / "pts_good.txt"), "--plot", plot])

    add = lambda name, argv: c.append(("cli tileset", name, argv))
    for name in sorted(sets):
        if name in ("big.ron",):
            continue
        add(f"check {name}", [rwt, "tileset", "check", str(sets[name])])
    for name in ("seam_1e30.ron", "seam_nan.ron", "cut_0.5.ron", "default.ron", "nested_deep.ron"):
        add(f"render {name}", [rwt, "tileset", "render", str(sets[name]), "--out", "r.png"])
    add("render --out r.svg", [rwt, "tileset", "render", str(sets["default.ron"]), "--out", "r.svg"])
    add("check big.ron (129 MiB)", [rwt, "tileset", "check", str(sets["big.ron"])])
    add("check /dev/zero", [rwt, "tileset", "check", "/dev/zero"])
    add("check FIFO", [rwt, "tileset", "check", str(images / "fifo.png")])
    add("check --min-rho NaN", [rwt, "tileset", "check", str(sets["default.ron"]), "--min-rho", "NaN"])
    for extra in (("--colors", "0"), ("--colors", "9"), ("--colors", "256"), ("--points", "0"),
                  ("--points", "4294967296"), ("--subdivision", "0"), ("--subdivision", "3"),
                  ("--subdivision", "16")):
        add("build " + " ".join(extra), [rwt, "tileset", "build", "--out", "b.ron", *extra])
    add("build --out /dev/full", [rwt, "tileset", "build", "--out", "/dev/full", "--points", "16",
                                  "--colors", "1"])
    return c


def python_cases(py):
    """(group, name, code) of the Python package; the code raises or prints."""
    c = []
    add = lambda group, name, code: c.append((group, name, code))
    s = "import numpy as np, rwt\n"
    for name, call in (
            ("rect NaN", "rwt.sample((float('nan'), 0, 1, 1), 1.0)"),
            ("rect inverted", "rwt.sample((1, 1, 0, 0), 1.0)"),
            ("rect strings", "rwt.sample(('a', 0, 1, 1), 1.0)"),
            ("rect of 3", "rwt.sample((0, 1, 1), 1.0)"),
            ("density -1", "rwt.sample((0, 0, 1, 1), -1.0)"),
            ("density NaN", "rwt.sample((0, 0, 1, 1), float('nan'))"),
            ("density 1e308", "rwt.sample((0, 0, 1, 1), 1e308)"),
            ("density True", "rwt.sample((0, 0, 1, 1), True)"),
            ("density string", "rwt.sample((0, 0, 1, 1), 'dense')"),
            ("array with NaN", "rwt.sample((0, 0, 1, 1), np.array([[1.0, np.nan]]))"),
            ("array negative", "rwt.sample((0, 0, 1, 1), -np.ones((4, 4)))"),
            ("array 3-D", "rwt.sample((0, 0, 1, 1), np.ones((2, 2, 2)))"),
            ("array empty", "rwt.sample((0, 0, 1, 1), np.ones((0, 4)))"),
            ("array object", "rwt.sample((0, 0, 1, 1), np.array([[None]]))"),
            ("array complex", "rwt.sample((0, 0, 1, 1), np.ones((2, 2), complex))"),
            ("array 1 x 40000", "rwt.sample((0, 0, 1, 1), np.ones((1, 40000)))"),
            ("broadcast 20000^2 float64", "rwt.sample((0, 0, 1, 1), np.broadcast_to(1.0, (20000, 20000)))"),
            ("broadcast 8192^2 uint8", "rwt.sample((0, 0, 1, 1), np.broadcast_to(np.uint8(1), (8192, 8192)))"),
            ("array 4096^2 uint8", "print(len(rwt.sample((0, 0, 10, 10), np.ones((4096, 4096), np.uint8))))"),
            ("array 1e308", "rwt.sample((0, 0, 1, 1), np.full((2, 2), 1e308))"),
            ("budget 0", "rwt.sample((0, 0, 10, 10), 5.0, budget=0)"),
            ("budget -1", "rwt.sample((0, 0, 10, 10), 5.0, budget=-1)"),
            ("budget 2^64", "rwt.sample((0, 0, 10, 10), 5.0, budget=2**64)"),
            ("over budget", "rwt.sample((0, 0, 1e6, 1e6), 100.0)"),
            ("tile_size 0", "rwt.sample((0, 0, 1, 1), 1.0, tile_size=0)"),
            ("tile_size NaN", "rwt.sample((0, 0, 1, 1), 1.0, tile_size=float('nan'))"),
            ("tile_size 1e-300", "rwt.sample((0, 0, 1, 1), 1.0, tile_size=1e-300)"),
            ("seed -1", "rwt.sample((0, 0, 1, 1), 1.0, seed=-1)"),
            ("seed 2^64", "rwt.sample((0, 0, 1, 1), 1.0, seed=2**64)"),
            ("seed float", "rwt.sample((0, 0, 1, 1), 1.0, seed=1.5)"),
            ("tileset /dev/zero", "rwt.sample((0, 0, 1, 1), 1.0, tileset='/dev/zero')"),
            ("tileset missing", "rwt.sample((0, 0, 1, 1), 1.0, tileset='nothere.ron')"),
            ("callable raising", "rwt.sample((0, 0, 4, 4), lambda x, y: 1 / 0, max_density=5)"),
            ("callable NaN", "rwt.sample((0, 0, 4, 4), lambda x, y: x * np.nan, max_density=5)"),
            ("callable wrong shape", "rwt.sample((0, 0, 4, 4), lambda x, y: np.ones(3), max_density=5)"),
            ("callable over its max", "rwt.sample((0, 0, 4, 4), lambda x, y: x * 0 + 50, max_density=5)"),
            ("callable max NaN", "rwt.sample((0, 0, 4, 4), lambda x, y: x * 0 + 1, max_density=float('nan'))"),
            ("far precision", "rwt.sample((9e11, 0, 9e11 + 0.01, 0.01), 1e9)"),
    ):
        add("python sample", name, s + call)
    for name, call in (
            ("dots 0", "rwt.stipple(np.full((48, 64), 0.4), dots=0)"),
            ("dots -1", "rwt.stipple(np.full((48, 64), 0.4), dots=-1)"),
            ("radius 0", "rwt.stipple(np.full((48, 64), 0.4), radius=0)"),
            ("radius NaN", "rwt.stipple(np.full((48, 64), 0.4), radius=float('nan'))"),
            ("radius 1e-6, max_dots 2^64-1", "rwt.stipple(np.full((48, 64), 0.4), radius=1e-6, max_dots=2**64 - 1)"),
            ("radius 0.05, max_dots 2^64-1", "rwt.stipple(np.full((48, 64), 0.4), radius=0.05, max_dots=2**64 - 1)"),
            ("scale 1e-300", "rwt.stipple(np.full((48, 64), 0.4), scale=1e-300)"),
            ("scale 1e4 render", "rwt.stipple(np.full((48, 64), 0.4), scale=1e4, render=True)"),
            ("scale 1e4, raster 2^64-1", "rwt.stipple(np.full((48, 64), 0.4), scale=1e4, render=True, max_raster_pixels=2**64 - 1)"),
            ("gamma NaN", "rwt.stipple(np.full((48, 64), 0.4), gamma=float('nan'))"),
            ("contrast -1", "rwt.stipple(np.full((48, 64), 0.4), contrast=-1)"),
            ("image NaN", "rwt.stipple(np.full((48, 64), np.nan))"),
            ("image inf", "rwt.stipple(np.full((48, 64), np.inf))"),
            ("image white", "rwt.stipple(np.ones((48, 64)))"),
            ("image 1x1 black", "print(len(rwt.stipple(np.zeros((1, 1))).points))"),
            ("image 1x20000 black", "print(len(rwt.stipple(np.zeros((1, 20000))).points))"),
            ("image bool", "print(len(rwt.stipple(np.zeros((30, 30), bool)).points))"),
            ("image int64", "rwt.stipple(np.zeros((30, 30), np.int64))"),
            ("image 3-D", "rwt.stipple(np.zeros((30, 30, 3)))"),
            ("image empty", "rwt.stipple(np.zeros((0, 30)))"),
            ("broadcast 20000^2", "rwt.stipple(np.broadcast_to(np.uint8(0), (20000, 20000)))"),
            ("8192^2 black", "rwt.stipple(np.zeros((8192, 8192), np.uint8))"),
            ("max_image_pixels 2^64", "rwt.stipple(np.zeros((30, 30)), max_image_pixels=2**64)"),
            ("tileset broken", "rwt.stipple(np.zeros((30, 30)), tileset='/dev/null')"),
    ):
        add("python stipple", name, s + call)
    for name, call in (
            ("window degenerate", "rwt.analyse(np.random.rand(100, 2), (0, 0, 0, 1))"),
            ("window tiny", "rwt.analyse(np.random.rand(100, 2) * 1e-310, (0, 0, 1e-308, 1e-308))"),
            ("window vast", "rwt.analyse((np.random.rand(100, 2) - 0.5) * 2e300, (-1e300, -1e300, 1e300, 1e300))"),
            ("window far", "rwt.analyse(1e15 + np.random.rand(100, 2), (1e15, 1e15, 1e15 + 1, 1e15 + 1))"),
            ("window NaN", "rwt.analyse(np.random.rand(100, 2), (0, 0, float('nan'), 1))"),
            ("points (N, 3)", "rwt.analyse(np.random.rand(100, 3), (0, 0, 1, 1))"),
            ("points NaN", "print(rwt.analyse(np.full((100, 2), np.nan), (0, 0, 1, 1)).rho)"),
            ("points empty", "rwt.analyse(np.zeros((0, 2)), (0, 0, 1, 1))"),
            ("points coincident", "print(rwt.analyse(np.full((1000, 2), 0.5), (0, 0, 1, 1)).rho)"),
            ("size 0", "rwt.analyse(np.random.rand(100, 2), (0, 0, 1, 1), size=0)"),
            ("size 1e6", "rwt.analyse(np.random.rand(100, 2), (0, 0, 1, 1), size=10**6)"),
            ("clumps radius -1", "rwt.Clumps(seed=1, clumps=1.0, per_clump=5.0, radius=-1.0)"),
            ("clumps NaN", "rwt.Clumps(seed=1, clumps=float('nan'), per_clump=5.0, radius=1.0)"),
            ("clumps 1e300 per unit area", "rwt.sample((0, 0, 10, 10), rwt.Clumps(seed=1, clumps=1e300, per_clump=5.0, radius=1.0))"),
    ):
        add("python analyse, clumps", name, s + call)
    interrupted = ("import os, signal, threading, time\n" + s +
                   "threading.Timer({d}, lambda: os.kill(os.getpid(), signal.SIGINT)).start()\n"
                   "t = time.monotonic()\n"
                   "try:\n    {call}\n    print('finished')\n"
                   "except KeyboardInterrupt:\n"
                   "    import sys; print(f'KeyboardInterrupt after {{time.monotonic() - t - {d}:.2f}} s', file=sys.stderr)\n")
    for d in (0.05, 0.3, 1.0):
        for name, call in (("sample", "rwt.sample((0, 0, 3000, 3000), 0.5, budget=10**9, tile_size=1)"),
                           ("map", "rwt.sample((0, 0, 3000, 3000), np.full((64, 64), 0.5), budget=10**9, tile_size=1)"),
                           ("stipple", "rwt.stipple(np.zeros((2048, 2048)), render=True)"),
                           ("analyse", "rwt.analyse(np.random.rand(4_000_000, 2), (0, 0, 1, 1), size=512)")):
            add("python Ctrl-C", f"SIGINT at {d} s in first call: {name}",
                interrupted.format(d=d, call=call))
    return c


def signal_cases(rwt, work):
    """(name, argv, signal, delay s): a write interrupted, its temporary file must go and
    the previous output stay."""
    big = [rwt, "points", "--rect", "0", "0", "3000", "3000", "--density", "const:2",
           "--out", "out.txt"]
    stip = [rwt, "stipple", "IMAGE", "--out", "out.png"]
    cases = []
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGKILL):
        for delay in (0.05, 0.5, 2.0):
            cases.append((f"points --out, SIG{sig.name[3:]} at {delay} s", big, sig, delay))
    for sig in (signal.SIGINT, signal.SIGTERM):
        cases.append((f"stipple --out, SIG{sig.name[3:]} at 1 s", stip, sig, 1.0))
    cases.append(("tileset build, SIGINT at 1 s",
                  [rwt, "tileset", "build", "--out", "out.ron"], signal.SIGINT, 1.0))
    return cases


# ---------------------------------------------------------------- the pass

def pass_cases(args, work):
    results = []
    images = work / "images"
    make_images(images)
    sets = tileset_variants(work / "sets", ROOT / "crates/rwt_core/tilesets/default.ron")
    layers = layer_variants(work / "layers")
    stamp_out = subprocess.run([args.probe, "stamp"], capture_output=True, text=True, check=True)
    stamp = tuple(int(v) for v in stamp_out.stdout.split())
    edits = edits_variants(work / "edits", stamp)
    saves = save_variants(work / "saves", stamp, images, layers["good"])
    run_dir = work / "run"
    run_dir.mkdir()

    def note(r):
        results.append(r)
        mark = " ".join(r.flags) or "ok"
        print(f"{len(results):4} {r.group:16} {r.name[:50]:50} {r.code:4} {r.peak_mb:7.1f} MB "
              f"{r.seconds:6.2f} s  {mark}", file=sys.stderr)

    for group, name, argv in cli_cases(args.rwt, work, images, sets):
        for p in run_dir.iterdir():
            shutil.rmtree(p) if p.is_dir() and not p.is_symlink() else p.unlink()
        timeout = 20.0 if "killed at 20 s" in name else LIMIT_S
        outcome = run(argv, run_dir, timeout=timeout)
        flags = []
        if "killed at 20 s" in name and outcome[5]:
            outcome = outcome[:5] + (False,)
            flags.append("(stopped as planned)")
        note(judge(group, name, outcome, run_dir, flags))
    for kind, paths in (("layer file", layers), ("edits file", edits)):
        for name, path in paths.items():
            argv = [args.probe, "layer", str(path)] if kind == "layer file" else \
                [args.probe, "edits", str(path), str(stamp[0])]
            note(judge(kind, name, run(argv, run_dir)))
    for name in ("/dev/zero", str(images / "fifo.png"), str(work)):
        note(judge("layer file", name, run([args.probe, "layer", name], run_dir)))
        note(judge("edits file", name, run([args.probe, "edits", name, "0"], run_dir)))
    for name, path in saves.items():
        note(judge("brush save", name, run([args.probe, "save", str(path)], run_dir)))
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    for group, name, code in python_cases(args.python):
        wrapped = ("import sys\ntry:\n" + "".join("    " + line + "\n" for line in code.splitlines())
                   + "except Exception as e:\n    print(f'{type(e).__name__}: {e}'.splitlines()[0],"
                   " file=sys.stderr)\n    sys.exit(2)\n")
        note(judge(group, name, run([args.python, "-c", wrapped], run_dir, env=env)))
    for name, argv, sig, delay in signal_cases(args.rwt, work):
        argv = [str(images / "dark_2048.png") if a == "IMAGE" else a for a in argv]
        for p in run_dir.iterdir():
            p.unlink()
        previous = b"previous output\n"
        target = run_dir / argv[argv.index("--out") + 1]
        target.write_bytes(previous)

        def send(pid, sig=sig, delay=delay):
            time.sleep(delay)
            try:
                os.kill(pid, sig)
            except ProcessLookupError:
                flags.append("(ended before the signal)")

        flags = []

        outcome = run(argv, run_dir, on_start=send)
        if target.read_bytes() != previous:
            flags.append("OUTPUT CHANGED")
        left = [p for p in run_dir.iterdir() if p.name.endswith(".rwt-tmp")]
        if sig == signal.SIGKILL and left:
            # Not catchable: the next write to the same target removes it.
            again = run([args.rwt, "points", "--rect", "0", "0", "1", "1", "--density", "const:2",
                         "--out", target.name], run_dir)
            left = [p for p in run_dir.iterdir() if p.name.endswith(".rwt-tmp")]
            flags.append("(temp removed by the next write)" if not left and again[0] == 0
                         else "TEMP LEFT")
            outcome = (outcome[0], outcome[1], "killed; next write: " + first_line(again[2]),
                       *outcome[3:])
        r = judge("signals", name, outcome, None, flags)
        if left and sig != signal.SIGKILL:
            r.flags.append("TEMP LEFT")
        note(r)
    return results


def scrub(text, tmp):
    """The text without this machine's paths: the run's folder as $TMP, the checkout as `.`."""
    return text.replace(str(tmp), "$TMP").replace(str(ROOT), ".")


def table(results, tmp):
    bad = [r for r in results if any(f.isupper() and not f.startswith("(") for f in r.flags)]
    lines = [
        f"{len(results)} cases, {len(bad)} flagged; peak memory at most "
        f"{max(r.peak_mb for r in results):.0f} MB, longest {max(r.seconds for r in results):.1f} s.",
        "",
        "| # | group | case | exit | first line of stderr | peak MB | s | flags |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for k, r in enumerate(results, 1):
        text = scrub(r.first, tmp).replace("|", "\\|").replace("`", "'")
        if len(text) > 110:
            text = text[:107] + "..."
        name = r.name.replace("|", "\\|").replace("`", "'")
        lines.append(f"| {k} | {r.group} | {name} | {r.code} | {text} | {r.peak_mb:.0f} | "
                     f"{r.seconds:.1f} | {' '.join(r.flags)} |")
    return "\n".join(lines), bad


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rwt", default=str(ROOT / "target/debug/rwt"))
    ap.add_argument("--probe", default=str(ROOT / "target/debug/examples/read_file"))
    ap.add_argument("--python", default=str(ROOT / "target/py-venv/bin/python"))
    ap.add_argument("--no-build", action="store_true")
    ap.add_argument("--update", help="rewrite the table between the markers in this file")
    args = ap.parse_args()
    if not args.no_build:
        subprocess.run(["cargo", "build", "-p", "rwt_cli", "-p", "bevy_rwt", "--example",
                        "read_file", "--bin", "rwt"], cwd=ROOT, check=True)
    with tempfile.TemporaryDirectory(prefix="rwt-hostile-") as tmp:
        results = pass_cases(args, pathlib.Path(tmp))
    text, bad = table(results, tmp)
    print(text)
    if args.update:
        path = pathlib.Path(args.update)
        doc = path.read_text()
        start, end = doc.index(BEGIN) + len(BEGIN), doc.index(END)
        path.write_text(doc[:start] + "\n" + text + "\n" + doc[end:])
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

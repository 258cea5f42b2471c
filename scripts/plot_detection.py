#!/usr/bin/env python3
"""Draws a synthetic scan's depth image with its truth and a run's detection, as a PNG.

    plot_detection.py --truth SCAN.pcd [--result OUTDIR] -o PICTURE.png [--margin PX | --full]
        [--scale N]

Colours: depth in grey (near = light), no return = dark blue; truth groove only = green,
detected only = red, both = yellow; the true root line (in view) = cyan; the trajectory's
waypoints and the path through them = magenta. Points are in the camera frame and projected
with the intrinsics of SCAN.truth.json (see docs/synthetic-scans.md).

Standard library only (no numpy), so it runs wherever the CLI runs.
"""

import argparse
import csv
import json
import math
import os
import struct
import sys
import zlib

PCD_TYPES = {("F", 4): "f", ("F", 8): "d", ("U", 1): "B", ("U", 2): "H", ("U", 4): "I",
             ("I", 1): "b", ("I", 2): "h", ("I", 4): "i"}


def read_pcd(path, wanted):
    """Returns (width, height, {field: list}) for the wanted fields of a binary or ascii PCD."""
    with open(path, "rb") as f:
        data = f.read()
    header, pos = {}, 0
    while True:
        end = data.index(b"\n", pos)
        line = data[pos:end].decode("ascii", "replace").strip()
        pos = end + 1
        if not line or line.startswith("#"):
            continue
        key, _, value = line.partition(" ")
        header[key] = value.split()
        if key == "DATA":
            break
    fields, sizes, types = header["FIELDS"], header["SIZE"], header["TYPE"]
    counts = header.get("COUNT", ["1"] * len(fields))
    width, height = int(header["WIDTH"][0]), int(header["HEIGHT"][0])
    n = width * height
    columns, fmt = [], "<"
    for name, size, kind, count in zip(fields, sizes, types, counts):
        code = PCD_TYPES[(kind, int(size))]
        fmt += code * int(count)
        columns += [name] * int(count)
    out = {name: [] for name in wanted}
    index = {name: columns.index(name) for name in wanted}
    kind = header["DATA"][0]
    if kind == "binary":
        record = struct.calcsize(fmt)
        for values in struct.iter_unpack(fmt, data[pos:pos + n * record]):
            for name, i in index.items():
                out[name].append(values[i])
    elif kind == "ascii":
        for line in data[pos:].decode("ascii").splitlines():
            words = line.split()
            if words:
                for name, i in index.items():
                    out[name].append(float(words[i]))
    else:
        sys.exit(f"plot_detection: {path}: DATA {kind} is not supported")
    if any(len(v) != n for v in out.values()):
        sys.exit(f"plot_detection: {path} is truncated")
    return width, height, out


def write_png(path, width, height, rgb):
    """rgb: bytearray of width*height*3."""
    raw = bytearray()
    stride = width * 3
    for y in range(height):
        raw.append(0)
        raw += rgb[y * stride:(y + 1) * stride]

    def chunk(tag, body):
        return (struct.pack(">I", len(body)) + tag + body +
                struct.pack(">I", zlib.crc32(tag + body) & 0xFFFFFFFF))

    png = (b"\x89PNG\r\n\x1a\n" +
           chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
           chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b""))
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(png)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--truth", required=True, help="synthetic scan SCAN.pcd")
    ap.add_argument("--result", help="groovetrace run output directory")
    ap.add_argument("-o", "--output", required=True, help="PNG to write")
    ap.add_argument("--margin", type=int, default=60,
                    help="crop to the truth groove plus this many pixels (default 60)")
    ap.add_argument("--full", action="store_true", help="do not crop")
    ap.add_argument("--scale", type=int, default=1, help="enlarge by this factor (default 1)")
    args = ap.parse_args()

    stem = args.truth[:-4] if args.truth.endswith(".pcd") else args.truth
    with open(stem + ".truth.json") as f:
        truth = json.load(f)
    cam = truth["camera"]
    width, height, scan = read_pcd(args.truth, ["z"])
    _, _, labels = read_pcd(os.path.join(os.path.dirname(stem + ".truth.json"),
                                         truth["files"]["labels"]), ["label"])
    detected = [0] * (width * height)
    poses = []
    if args.result:
        w2, h2, ann = read_pcd(os.path.join(args.result, "annotated.pcd"), ["groove"])
        if (w2, h2) != (width, height):
            sys.exit("plot_detection: annotated.pcd and the scan differ in size")
        detected = ann["groove"]
        path = os.path.join(args.result, "trajectory.csv")
        if os.path.exists(path):
            with open(path) as f:
                poses = [(float(r["x_m"]), float(r["y_m"]), float(r["z_m"]))
                         for r in csv.DictReader(f)]

    z = scan["z"]
    finite = sorted(v for v in z if math.isfinite(v))
    if not finite:
        sys.exit("plot_detection: the scan has no valid point")
    near, far = finite[len(finite) // 50], finite[-1 - len(finite) // 50]
    span = max(far - near, 1e-6)

    rgb = bytearray(width * height * 3)
    for i, depth in enumerate(z):
        if not math.isfinite(depth):
            rgb[3 * i:3 * i + 3] = b"\x10\x18\x40"
            continue
        g = int(235 - 190 * min(max((depth - near) / span, 0.0), 1.0))
        t, d = labels["label"][i], detected[i]
        if t and d:
            px = (min(255, g + 120), min(255, g + 120), g // 3)
        elif t:
            px = (g // 3, min(255, g + 100), g // 3)
        elif d:
            px = (min(255, g + 120), g // 3, g // 3)
        else:
            px = (g, g, g)
        rgb[3 * i:3 * i + 3] = bytes(px)

    def project(p):
        x, y, zz = p
        if zz <= 0:
            return None
        return (cam["fx"] * x / zz + cam["cx"], cam["fy"] * y / zz + cam["cy"])

    def dot(u, v, colour):
        u, v = int(round(u)), int(round(v))
        if 0 <= u < width and 0 <= v < height:
            rgb[3 * (v * width + u):3 * (v * width + u) + 3] = colour

    def line(a, b, colour, thick=1):
        steps = int(max(abs(b[0] - a[0]), abs(b[1] - a[1]))) + 1
        for k in range(steps + 1):
            u = a[0] + (b[0] - a[0]) * k / steps
            v = a[1] + (b[1] - a[1]) * k / steps
            for du in range(-thick + 1, thick):
                for dv in range(-thick + 1, thick):
                    dot(u + du, v + dv, colour)

    cyan, magenta = b"\x00\xe0\xff", b"\xff\x00\xff"
    for seam in truth["seams"]:
        pts, view = seam["root"], seam["in_view"]
        for k in range(len(pts) - 1):
            if view[k] and view[k + 1]:
                a, b = project(pts[k]), project(pts[k + 1])
                if a and b:
                    line(a, b, cyan)
    projected = [q for q in (project(p) for p in poses) if q]
    for a, b in zip(projected, projected[1:]):
        line(a, b, magenta)
    for u, v in projected:
        line((u - 4, v), (u + 4, v), magenta, 2)
        line((u, v - 4), (u, v + 4), magenta, 2)

    # Crop around the truth groove (and the detection), so that the groove is visible.
    x0, y0, x1, y1 = 0, 0, width, height
    if not args.full:
        cols = [i % width for i, t in enumerate(labels["label"]) if t]
        rows = [i // width for i, t in enumerate(labels["label"]) if t]
        if cols:
            m = args.margin
            x0, x1 = max(0, min(cols) - m), min(width, max(cols) + m + 1)
            y0, y1 = max(0, min(rows) - m), min(height, max(rows) + m + 1)
    s = max(1, args.scale)
    crop = bytearray()
    for y in range(y0, y1):
        row = rgb[3 * (y * width + x0):3 * (y * width + x1)]
        if s > 1:
            row = b"".join(row[3 * k:3 * k + 3] * s for k in range(x1 - x0))
        crop += row * s
    write_png(args.output, (x1 - x0) * s, (y1 - y0) * s, crop)
    print(f"wrote {args.output} ({(x1 - x0) * s}x{(y1 - y0) * s})")


if __name__ == "__main__":
    main()

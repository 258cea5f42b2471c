#!/usr/bin/python3
"""The robust method's sweep on synthetic D415 scans (issue 4): accuracy and robustness.

    scripts/robust_sweep.py [--bin build/groovetrace] [--out out/robust_sweep]
        [--results docs/results-robust.md] [--methods robust,paper] [--quick]

Renders 42 scans - every shape (straight, curve, box, cylinder, pipe-long, lshape, multi) at
640x480 and 1280x720, three poses each (distance 0.30-0.55 m, tilt -20..20 deg, own seed) -
runs each method with its defaults (`--max-seams 2` for robust on `multi`, whose two seams
are both the truth), scores every run with `groovetrace eval`, and checks the trajectories:
no NaN, no jump over 3 x the step, no tool axis pointing away from the workpiece (towards
the sensor). Then the same scans at 640x480 once more as unorganized clouds (flattened,
shuffled) and in a robot base frame with --viewpoint, and one scan with its groove cut out,
which must exit with code 4. Writes the tables to --results.

Standard library only; run with Debian's /usr/bin/python3.
"""

import argparse
import json
import math
import os
import random
import shlex
import struct
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHAPES = ["straight", "curve", "box", "cylinder", "pipe-long", "lshape", "multi"]
RESOLUTIONS = ["640x480", "1280x720"]
# (distance m, tilt deg) per pose; each shape and resolution gets three of them, rotating
# through the list so that every distance and tilt appears for every shape.
POSES = [(0.30, 10), (0.40, 0), (0.55, 15), (0.45, -20), (0.35, 20), (0.50, -10), (0.40, 5)]
STEP_M = 0.002  # the default --step: waypoints are at most this far apart


def log(msg):
    print(msg, flush=True)


def run(argv):
    t0 = time.monotonic()
    p = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr, time.monotonic() - t0


def sweep_scans():
    """(shape, resolution, distance, tilt, seed) of the 42 scans."""
    scans = []
    k = 0
    for res in RESOLUTIONS:
        for si, shape in enumerate(SHAPES):
            for j in range(3):
                d, t = POSES[(si + 2 * j + (3 if res != RESOLUTIONS[0] else 0)) % len(POSES)]
                scans.append((shape, res, d, t, 101 + k))
                k += 1
    return scans


# --- PCD ----------------------------------------------------------------------------------

def read_pcd(path):
    """(header dict, fields, rows as lists) of a binary or ascii PCD."""
    with open(path, "rb") as f:
        data = f.read()
    header, pos = {}, 0
    while True:
        end = data.index(b"\n", pos)
        line = data[pos:end].decode().strip()
        pos = end + 1
        if not line or line.startswith("#"):
            continue
        key, _, value = line.partition(" ")
        header[key] = value.split()
        if key == "DATA":
            break
    fields = header["FIELDS"]
    sizes = [int(s) for s in header["SIZE"]]
    types = header["TYPE"]
    counts = [int(c) for c in header.get("COUNT", ["1"] * len(fields))]
    n = int(header["POINTS"][0])
    codes = {("F", 4): "f", ("F", 8): "d", ("U", 1): "B", ("U", 2): "H", ("U", 4): "I",
             ("I", 1): "b", ("I", 2): "h", ("I", 4): "i"}
    fmt = "<" + "".join(codes[(t, s)] * c for t, s, c in zip(types, sizes, counts))
    rows = []
    if header["DATA"][0] == "binary":
        rec = struct.calcsize(fmt)
        for i in range(n):
            rows.append(list(struct.unpack_from(fmt, data, pos + i * rec)))
    else:
        for line in data[pos:].decode().splitlines()[:n]:
            rows.append([float(v) for v in line.split()])
    return header, fields, rows


def write_pcd_ascii(path, fields, rows, width, height, viewpoint=(0.0, 0.0, 0.0)):
    types = "".join(" U" if f == "groove" else " F" for f in fields)
    sizes = "".join(" 1" if f == "groove" else " 4" for f in fields)
    head = ("# .PCD v0.7\nVERSION 0.7\nFIELDS " + " ".join(fields) + "\nSIZE" + sizes +
            "\nTYPE" + types + "\nCOUNT" + " 1" * len(fields) + f"\nWIDTH {width}\nHEIGHT {height}"
            f"\nVIEWPOINT {viewpoint[0]} {viewpoint[1]} {viewpoint[2]} 1 0 0 0"
            f"\nPOINTS {len(rows)}\nDATA ascii\n")
    with open(path, "w") as f:
        f.write(head)
        for r in rows:
            f.write(" ".join("nan" if isinstance(v, float) and math.isnan(v) else
                             (str(int(v)) if fields[k] == "groove" else f"{v:.7g}")
                             for k, v in enumerate(r)) + "\n")


# --- rigid transforms (quaternions x, y, z, w) ---------------------------------------------

def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def qrot(q, v):
    x, y, z, w = qmul(qmul(q, (v[0], v[1], v[2], 0.0)), (-q[0], -q[1], -q[2], q[3]))
    return (x, y, z)


# A robot base frame: rotated 150 deg about an oblique axis and shifted, like a camera on a
# flange looking down at a table in front of the robot.
_AXIS = (0.3, -0.5, 0.8)
_N = math.sqrt(sum(a * a for a in _AXIS))
Q_BASE_CAMERA = tuple([math.sin(math.radians(75)) * a / _N for a in _AXIS] +
                      [math.cos(math.radians(75))])
T_BASE_CAMERA = (0.45, -0.20, 0.65)


def to_base(p):
    r = qrot(Q_BASE_CAMERA, p)
    return tuple(r[k] + T_BASE_CAMERA[k] for k in range(3))


def from_base(p):
    inv = (-Q_BASE_CAMERA[0], -Q_BASE_CAMERA[1], -Q_BASE_CAMERA[2], Q_BASE_CAMERA[3])
    return qrot(inv, tuple(p[k] - T_BASE_CAMERA[k] for k in range(3)))


# --- trajectories ----------------------------------------------------------------------------

def read_csv(path):
    with open(path) as f:
        lines = f.read().splitlines()
    head = lines[0].split(",")
    return head, [[float(v) for v in line.split(",")] for line in lines[1:] if line]


def write_csv(path, head, rows):
    with open(path, "w") as f:
        f.write(",".join(head) + "\n")
        for r in rows:
            f.write(",".join(str(int(v)) if k == 0 else f"{v:.9g}" for k, v in enumerate(r)) + "\n")


def check_trajectory(path, eye=(0.0, 0.0, 0.0)):
    """Problems of a trajectory.csv: NaN, a jump over 3 steps, a tool axis towards the eye."""
    head, rows = read_csv(path)
    ix, iq = head.index("x_m"), head.index("qx")
    problems = []
    prev = None
    for r in rows:
        vals = r[1:]
        if any(math.isnan(v) or math.isinf(v) for v in vals):
            problems.append("NaN")
            break
        p = tuple(r[ix:ix + 3])
        q = tuple(r[iq:iq + 4])
        z = qrot(q, (0.0, 0.0, 1.0))
        ray = tuple(p[k] - eye[k] for k in range(3))
        if sum(z[k] * ray[k] for k in range(3)) <= 0:
            problems.append("tool axis towards the sensor")
            break
        if prev is not None and math.dist(p, prev) > 3 * STEP_M + 1e-9:
            problems.append(f"jump {math.dist(p, prev) * 1000:.1f} mm")
            break
        prev = p
    return problems, len(rows)


# --- one run ---------------------------------------------------------------------------------

def evaluate(binary, scan, out):
    rc, so, se, _ = run([binary, "eval", "--truth", scan, "--result", out, "-o",
                         os.path.join(out, "metrics.json")])
    if rc != 0:
        return None
    with open(os.path.join(out, "metrics.json")) as f:
        m = json.load(f)
    # metrics.json nests the detection and trajectory metrics; one flat dict here.
    return {**m.get("detection", {}), **m.get("trajectory", {})}


def union_coverage(truth_path, csvs):
    """Share (%) of the in-view root length within 6 mm of any of the trajectories."""
    with open(truth_path) as f:
        truth = json.load(f)
    paths = []
    for c in csvs:
        head, rows = read_csv(c)
        ix = head.index("x_m")
        paths.append([tuple(r[ix:ix + 3]) for r in rows])
    total = hit = 0.0
    for seam in truth["seams"]:
        root, view = seam["root"], seam["in_view"]
        for k in range(len(root) - 1):
            if not (view[k] and view[k + 1]):
                continue
            a, b = root[k], root[k + 1]
            seg = math.dist(a, b)
            n = max(1, int(seg / 0.0005))
            for j in range(n):
                t = (j + 0.5) / n
                x = tuple(a[i] + t * (b[i] - a[i]) for i in range(3))
                total += seg / n
                covered = False
                for path in paths:
                    for w in range(len(path) - 1):
                        p, q = path[w], path[w + 1]
                        d = tuple(q[i] - p[i] for i in range(3))
                        dd = sum(v * v for v in d) or 1e-18
                        u = max(0.0, min(1.0, sum((x[i] - p[i]) * d[i] for i in range(3)) / dd))
                        if math.dist(x, tuple(p[i] + u * d[i] for i in range(3))) < 0.006:
                            covered = True
                            break
                    if covered:
                        break
                if covered:
                    hit += seg / n
    return 100.0 * hit / total if total > 0 else float("nan")


def one_run(binary, method, scan, out, shape, extra=()):
    argv = [binary, "run", scan, "-o", out, "-q", "--method", method] + list(extra)
    if method == "robust" and shape == "multi":
        argv += ["--max-seams", "2"]
    rc, so, se, wall = run(argv)
    result = {"rc": rc, "wall_s": wall, "stderr": se.strip().splitlines()[-1:] if se else [],
              "cmd": " ".join(shlex.quote(a) for a in argv)}
    return result


# --- main --------------------------------------------------------------------------------------

def fmt(v, digits=2):
    return "-" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.{digits}f}"


def mean(xs):
    xs = [x for x in xs if x is not None and not math.isnan(x)]
    return sum(xs) / len(xs) if xs else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default="build/groovetrace")
    ap.add_argument("--out", default="out/robust_sweep")
    ap.add_argument("--results", default="docs/results-robust.md")
    ap.add_argument("--methods", default="robust,paper")
    ap.add_argument("--quick", action="store_true", help="one pose per shape, 640x480 only")
    ap.add_argument("--report-only", action="store_true",
                    help="rewrite --results from --out/summary.json without running anything")
    ap.add_argument("--invocation", default="scripts/robust_sweep.py")
    args = ap.parse_args()
    binary = os.path.join(ROOT, args.bin) if not os.path.isabs(args.bin) else args.bin
    out_root = os.path.join(ROOT, args.out)
    os.makedirs(out_root, exist_ok=True)
    methods = args.methods.split(",")
    if args.report_only:
        with open(os.path.join(out_root, "summary.json")) as f:
            records = json.load(f)
        write_results(args, records, methods)
        log(f"wrote {args.results}")
        return 0
    scans = sweep_scans()
    if args.quick:
        scans = [s for s in scans if s[1] == RESOLUTIONS[0]][::3]

    records = []
    for shape, res, dist, tilt, seed in scans:
        name = f"{shape}-{res}-d{dist:.2f}-t{tilt:+d}-s{seed}"
        scan = os.path.join(out_root, "scans", name + ".pcd")
        if not os.path.exists(scan):
            os.makedirs(os.path.dirname(scan), exist_ok=True)
            rc, so, se, _ = run([binary, "synth", "--shape", shape, "--resolution", res,
                                 "--distance", str(dist), "--tilt", str(tilt), "--seed", str(seed),
                                 "-o", scan])
            if rc != 0:
                log(f"synth failed for {name}: {se.strip()}")
                continue
        for method in methods:
            out = os.path.join(out_root, method, name)
            r = one_run(binary, method, scan, out, shape)
            rec = {"scan": name, "shape": shape, "res": res, "distance": dist, "tilt": tilt,
                   "seed": seed, "method": method, "variant": "organized", **r}
            if r["rc"] == 0:
                rec["metrics"] = evaluate(binary, scan, out)
                csvs = [os.path.join(out, "trajectory.csv")]
                if os.path.exists(os.path.join(out, "trajectory_1.csv")):
                    csvs.append(os.path.join(out, "trajectory_1.csv"))
                rec["problems"] = []
                for c in csvs:
                    problems, n = check_trajectory(c)
                    rec["problems"] += problems
                if len(csvs) > 1:
                    rec["coverage_union"] = union_coverage(scan[:-4] + ".truth.json", csvs)
            records.append(rec)
            m = rec.get("metrics") or {}
            log(f"{name:38s} {method:7s} rc {r['rc']} IoU {fmt(m.get('iou_percent'))} "
                f"lat {fmt((m.get('lateral_mean_m') or float('nan')) * 1e3)} "
                f"tool {fmt(m.get('tool_axis_mean_deg'))} cov {fmt(m.get('coverage_percent'), 1)}"
                f" {' '.join(rec.get('problems', []))} [{r['wall_s']:.1f} s]")

    # Variants of the 640x480 scans for the robust method: unorganized, and base frame.
    variant_scans = [s for s in scans if s[1] == RESOLUTIONS[0]]
    variant_scans = variant_scans[::3] if not args.quick else variant_scans
    if "robust" in methods:
        for shape, res, dist, tilt, seed in variant_scans:
            name = f"{shape}-{res}-d{dist:.2f}-t{tilt:+d}-s{seed}"
            scan = os.path.join(out_root, "scans", name + ".pcd")
            header, fields, rows = read_pcd(scan)
            w, h = int(header["WIDTH"][0]), int(header["HEIGHT"][0])
            valid = [i for i, r in enumerate(rows) if not math.isnan(r[0])]
            order = valid[:]
            random.Random(seed).shuffle(order)
            for variant in ("unorganized", "base_frame"):
                vdir = os.path.join(out_root, "variants", variant)
                os.makedirs(vdir, exist_ok=True)
                vscan = os.path.join(vdir, name + ".pcd")
                if variant == "unorganized":
                    write_pcd_ascii(vscan, ["x", "y", "z"], [rows[i][:3] for i in order],
                                    len(order), 1)
                    extra = []
                    eye = (0.0, 0.0, 0.0)
                else:
                    write_pcd_ascii(vscan, ["x", "y", "z"], [to_base(rows[i][:3]) for i in order],
                                    len(order), 1)
                    eye = T_BASE_CAMERA
                    extra = ["--viewpoint", ",".join(f"{v:.9g}" for v in T_BASE_CAMERA)]
                out = os.path.join(out_root, "robust-" + variant, name)
                r = one_run(binary, "robust", vscan, out, shape, extra)
                rec = {"scan": name, "shape": shape, "res": res, "distance": dist, "tilt": tilt,
                       "seed": seed, "method": "robust", "variant": variant, **r}
                if r["rc"] == 0:
                    csvs = [os.path.join(out, "trajectory.csv")]
                    if os.path.exists(os.path.join(out, "trajectory_1.csv")):
                        csvs.append(os.path.join(out, "trajectory_1.csv"))
                    rec["problems"] = []
                    for c in csvs:
                        rec["problems"] += check_trajectory(c, eye)[0]
                    # Back into the scan's order and camera frame for `groovetrace eval`.
                    _, afields, arows = read_pcd(os.path.join(out, "annotated.pcd"))
                    g = afields.index("groove")
                    groove = [0] * len(rows)
                    for k, i in enumerate(order):
                        groove[i] = int(arows[k][g])
                    edir = os.path.join(out, "camera_frame")
                    os.makedirs(edir, exist_ok=True)
                    write_pcd_ascii(os.path.join(edir, "annotated.pcd"), ["x", "y", "z", "groove"],
                                    [rows[i][:3] + [groove[i]] for i in range(len(rows))], w, h)
                    for c in csvs:
                        head, trows = read_csv(c)
                        if variant == "base_frame":
                            ix, iq = head.index("x_m"), head.index("qx")
                            inv = (-Q_BASE_CAMERA[0], -Q_BASE_CAMERA[1], -Q_BASE_CAMERA[2],
                                   Q_BASE_CAMERA[3])
                            for t in trows:
                                t[ix:ix + 3] = list(from_base(tuple(t[ix:ix + 3])))
                                t[iq:iq + 4] = list(qmul(inv, tuple(t[iq:iq + 4])))
                        write_csv(os.path.join(edir, os.path.basename(c)), head, trows)
                    rec["metrics"] = evaluate(binary, scan, edir)
                    if len(csvs) > 1:
                        rec["coverage_union"] = union_coverage(
                            scan[:-4] + ".truth.json",
                            [os.path.join(edir, os.path.basename(c)) for c in csvs])
                records.append(rec)
                m = rec.get("metrics") or {}
                log(f"{name:38s} {variant:11s} rc {r['rc']} IoU {fmt(m.get('iou_percent'))} "
                    f"lat {fmt((m.get('lateral_mean_m') or float('nan')) * 1e3)} "
                    f"{' '.join(rec.get('problems', []))}")

        # No groove: the first straight 640x480 scan with its groove band cut out.
        base = [s for s in scans if s[0] == "straight" and s[1] == RESOLUTIONS[0]][0]
        name = f"{base[0]}-{base[1]}-d{base[2]:.2f}-t{base[3]:+d}-s{base[4]}"
        scan = os.path.join(out_root, "scans", name + ".pcd")
        header, fields, rows = read_pcd(scan)
        with open(scan[:-4] + ".truth.json") as f:
            truth = json.load(f)
        root = truth["seams"][0]["root"]
        cut = []
        for r in rows:
            p = r[:3]
            near = not math.isnan(p[0]) and min(
                math.dist(p, q) for q in root[::4]) < 0.02
            cut.append([float("nan")] * 3 if near else p)
        nscan = os.path.join(out_root, "variants", "no_groove.pcd")
        write_pcd_ascii(nscan, ["x", "y", "z"], cut, int(header["WIDTH"][0]),
                        int(header["HEIGHT"][0]))
        r = one_run(binary, "robust", nscan, os.path.join(out_root, "robust-no-groove"), "none")
        records.append({"scan": name + " groove cut out", "method": "robust",
                        "variant": "no_groove", "shape": "none", **r})
        log(f"no groove: rc {r['rc']} {' '.join(r['stderr'])}")

    with open(os.path.join(out_root, "summary.json"), "w") as f:
        json.dump(records, f, indent=1)
    write_results(args, records, methods)
    log(f"wrote {args.results}")


def write_results(args, records, methods):
    L = []
    L.append("# Results: the robust method on the synthetic D415 sweep")
    L.append("")
    L.append(f"Written by `{args.invocation}` - do not edit by hand; re-run the script. "
             f"Generated {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.")
    L.append("")
    L.append("Scans: `groovetrace synth` with every D415 effect on (docs/synthetic-scans.md), "
             "table in view; every shape at 640x480 and 1280x720, three poses each: distance "
             "0.30-0.55 m, tilt -20..20 deg across the seam, a seed per scan. One default "
             "configuration (`groovetrace run --method M`, only `--max-seams 2` for `multi`, "
             "whose two seams are both the truth). Metrics from `groovetrace eval` "
             "(docs/design.md, \"Metrics\"); coverage of `multi` with two seams is over the union of "
             "both trajectories. Method: docs/method-robust.md.")
    L.append("")
    L.append("Targets (issue 4): IoU >= 90 % at 1280x720 and >= 84 % at 640x480; lateral mean "
             "<= 0.5 mm, max <= 1.5 mm; depth mean <= 0.8 mm; tool axis mean <= 3 deg; "
             "coverage >= 95 %.")
    L.append("")
    organized = [r for r in records if r.get("variant") == "organized"]
    for res in RESOLUTIONS:
        rows = [r for r in organized if r.get("res") == res]
        if not rows:
            continue
        L.append(f"## {res}: per shape (mean over its scans; max = worst scan)")
        L.append("")
        L.append("| shape | method | scans | found | IoU mean % | IoU min % | lateral mean mm | "
                 "lateral max mm | depth mean mm | depth max mm | tool axis mean deg | "
                 "coverage mean % | coverage min % |")
        L.append("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for shape in SHAPES:
            for method in methods:
                rs = [r for r in rows if r["shape"] == shape and r["method"] == method]
                if not rs:
                    continue
                ms = [r.get("metrics") or {} for r in rs]
                found = sum(1 for r in rs if r["rc"] == 0)

                def col(key, scale=1.0, agg=mean):
                    vals = [m.get(key) * scale if m.get(key) is not None else float("nan")
                            for m in ms]
                    vals = [v if r["rc"] == 0 else float("nan") for v, r in zip(vals, rs)]
                    return agg(vals)

                cov = [r.get("coverage_union", (r.get("metrics") or {}).get("coverage_percent"))
                       if r["rc"] == 0 else 0.0 for r in rs]
                iou = [(m.get("iou_percent") if r["rc"] == 0 else 0.0) for m, r in zip(ms, rs)]
                mx = lambda v: max([x for x in v if not math.isnan(x)], default=float("nan"))
                L.append(f"| {shape} | {method} | {len(rs)} | {found} | {fmt(mean(iou))} | "
                         f"{fmt(min([x for x in iou if x is not None], default=float('nan')))} | "
                         f"{fmt(col('lateral_mean_m', 1e3))} | "
                         f"{fmt(col('lateral_max_m', 1e3, mx))} | {fmt(col('depth_mean_m', 1e3))} | "
                         f"{fmt(col('depth_max_m', 1e3, mx))} | {fmt(col('tool_axis_mean_deg'))} | "
                         f"{fmt(mean(cov), 1)} | {fmt(min(cov), 1)} |")
        L.append("")
    L.append("## Against the targets (robust, organized clouds)")
    L.append("")
    L.append("Per resolution, over all its scans: the share of scans meeting each target, and "
             "the mean and worst value.")
    L.append("")
    L.append("| resolution | metric | target | scans meeting it | mean | worst |")
    L.append("|---|---|---|---:|---:|---:|")
    for res in RESOLUTIONS:
        rs = [r for r in organized if r.get("res") == res and r["method"] == "robust"]
        if not rs:
            continue
        iou_target = 90.0 if res == "1280x720" else 84.0
        checks = [
            ("IoU %", f">= {iou_target:.0f}", lambda m, r: m.get("iou_percent"), iou_target, 1),
            ("lateral mean mm", "<= 0.5", lambda m, r: m.get("lateral_mean_m", 0) * 1e3, 0.5, -1),
            ("lateral max mm", "<= 1.5", lambda m, r: m.get("lateral_max_m", 0) * 1e3, 1.5, -1),
            ("depth mean mm", "<= 0.8", lambda m, r: m.get("depth_mean_m", 0) * 1e3, 0.8, -1),
            ("tool axis mean deg", "<= 3", lambda m, r: m.get("tool_axis_mean_deg"), 3.0, -1),
            ("coverage %", ">= 95", lambda m, r: r.get("coverage_union", m.get("coverage_percent")),
             95.0, 1),
        ]
        for label, target, get, limit, sense in checks:
            vals = []
            for r in rs:
                m = r.get("metrics") or {}
                v = get(m, r) if r["rc"] == 0 and m else None
                vals.append(float("nan") if v is None else v)
            ok = sum(1 for v in vals if not math.isnan(v) and (v >= limit if sense > 0 else v <= limit))
            finite = [v for v in vals if not math.isnan(v)]
            worst = (min(finite) if sense > 0 else max(finite)) if finite else float("nan")
            L.append(f"| {res} | {label} | {target} | {ok}/{len(rs)} | {fmt(mean(vals))} | "
                     f"{fmt(worst)} |")
    L.append("")
    L.append("## Every scan")
    L.append("")
    L.append("| scan | method | variant | exit | IoU % | lateral mean/max mm | depth mean/max mm "
             "| tool axis mean deg | coverage % | trajectory checks | time s |")
    L.append("|---|---|---|---:|---:|---:|---:|---:|---:|---|---:|")
    for r in records:
        m = r.get("metrics") or {}
        cov = r.get("coverage_union", m.get("coverage_percent"))
        lat = f"{fmt((m.get('lateral_mean_m') or float('nan')) * 1e3)}/" \
              f"{fmt((m.get('lateral_max_m') or float('nan')) * 1e3)}"
        dep = f"{fmt((m.get('depth_mean_m') or float('nan')) * 1e3)}/" \
              f"{fmt((m.get('depth_max_m') or float('nan')) * 1e3)}"
        checks = ", ".join(r.get("problems", [])) or ("ok" if r["rc"] == 0 else
                                                     " ".join(r.get("stderr", [])))
        L.append(f"| {r['scan']} | {r['method']} | {r['variant']} | {r['rc']} | "
                 f"{fmt(m.get('iou_percent'))} | {lat} | {dep} | {fmt(m.get('tool_axis_mean_deg'))}"
                 f" | {fmt(cov, 1)} | {checks} | {r['wall_s']:.1f} |")
    L.append("")
    robust = [r for r in records if r["method"] == "robust" and r.get("variant") != "no_groove"]
    crashes = [r for r in robust if r["rc"] not in (0, 4)]
    missed = [r for r in robust if r["rc"] == 4]
    bad = [r for r in robust if r.get("problems")]
    nog = [r for r in records if r.get("variant") == "no_groove"]
    L.append("## Robustness (robust method, every run above)")
    L.append("")
    L.append(f"- runs: {len(robust)}; crashes or errors (exit not 0/4): {len(crashes)}; "
             f"no groove found (exit 4) on a scan that has one: {len(missed)}")
    L.append(f"- trajectories with NaN, a jump over 3 x {STEP_M * 1000:.0f} mm or a tool axis "
             f"towards the sensor: {len(bad)}" +
             ("" if not bad else " (" + "; ".join(f"{r['scan']} {r['variant']}: "
                                                  f"{', '.join(r['problems'])}" for r in bad) + ")"))
    if nog:
        L.append(f"- a scan with its groove cut out: exit {nog[0]['rc']} "
                 f"(expected 4): {' '.join(nog[0].get('stderr', []))}")
    L.append("")
    L.append("Commands: `" + args.invocation + "`; per run `" +
             (records[0]["cmd"] if records else "") + "` and `groovetrace eval --truth SCAN "
             "--result OUT` (summary.json under --out has every command).")
    L.append("")
    with open(os.path.join(ROOT, args.results), "w") as f:
        f.write("\n".join(L))


if __name__ == "__main__":
    sys.exit(main())

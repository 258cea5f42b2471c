#!/usr/bin/python3
"""The robust method's sweep on synthetic D415 scans (issues 4 and 12): accuracy and robustness.

    scripts/robust_sweep.py [--bin build/groovetrace] [--out out/robust_sweep]
        [--results docs/results-robust.md] [--methods robust,paper] [--set shapes|joints|all]
        [--quick] [--only PATTERN] [--report-only]

--set shapes (the default; issue 4): renders 42 scans - every shape (straight, curve, box,
cylinder, pipe-long, lshape, multi) at 640x480 and 1280x720, three poses each (distance
0.30-0.55 m, tilt -20..20 deg, own seed) - runs each method with its defaults (`--max-seams 2`
for robust on `multi`, whose two seams are both the truth), scores every run with
`groovetrace eval`, and checks the trajectories: no NaN, no jump over 3 x the step, no tool
axis pointing away from the workpiece (towards the sensor). Then the same scans at 640x480
once more as unorganized clouds (flattened, shuffled) and in a robot base frame with
--viewpoint, and one scan with its groove cut out, which must exit with code 4. Writes the
tables to --results.

--set joints (issue 12): about 65 scans of the shop joints and conditions in families -
single bevels, fillet and lap joints, V grooves 4-100 mm wide at 50-170 deg, girth and long
seams on 60-200 mm pipes, a 2 mm root opening, tack welds, high-low, clamps and a bar, a
camera at 35 deg, the far case - several seeds and poses each, the robust method only; plus
scenes without a joint that must exit 4. Scores each family against issue 12's targets and
writes its own section (between marker comments) into --results, leaving the shapes tables
there as they are (and --set shapes leaves the joints section). --set all runs both.

--quick: fewer scans (shapes: one pose per shape at 640x480; joints: one scan per family);
--only PATTERN: only the scans whose name matches the glob (a plain word: names containing
it), e.g. --only bevel45 or --only '*-640x480-*'.

Standard library only; run with Debian's /usr/bin/python3.
"""

import argparse
import fnmatch
import json
import math
import os
import random
import shlex
import shutil
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
    return {**m.get("detection", {}), **m.get("trajectory", {}),
            **{k: m.get(k) for k in ("joint_expected", "joint_found", "joint_match", "tacks")}}


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
    # A run replaces OUTDIR whole and refuses one holding files it does not write (the
    # camera_frame/ copy below): each run starts from an empty directory.
    shutil.rmtree(out, ignore_errors=True)
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


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default="build/groovetrace")
    ap.add_argument("--out", default="out/robust_sweep")
    ap.add_argument("--results", default="docs/results-robust.md")
    ap.add_argument("--methods", default="robust,paper",
                    help="methods for --set shapes (the joints set runs robust only)")
    ap.add_argument("--set", dest="scan_set", default="shapes", choices=["shapes", "joints", "all"],
                    help="shapes: the 42 scans of issue 4 (default); joints: issue 12's joints "
                         "and conditions; all: both")
    ap.add_argument("--quick", action="store_true",
                    help="shapes: one pose per shape, 640x480 only; joints: one scan per family")
    ap.add_argument("--only", default="",
                    help="run only the scans whose name matches this glob (a plain word: contains)")
    ap.add_argument("--report-only", action="store_true",
                    help="rewrite --results from --out/summary*.json without running anything")
    ap.add_argument("--invocation", default="scripts/robust_sweep.py")
    return ap.parse_args()


def name_filter(pattern):
    """A predicate on scan names: --only as a glob, or a substring when it has no wildcard."""
    if not pattern:
        return lambda name: True
    glob = pattern if any(c in pattern for c in "*?[") else f"*{pattern}*"
    return lambda name: fnmatch.fnmatchcase(name, glob)


def main():
    args = parse_args()
    binary = os.path.join(ROOT, args.bin) if not os.path.isabs(args.bin) else args.bin
    out_root = os.path.join(ROOT, args.out)
    os.makedirs(out_root, exist_ok=True)
    methods = args.methods.split(",")
    sets = ["shapes", "joints"] if args.scan_set == "all" else [args.scan_set]
    for which in sets:
        summary = os.path.join(out_root, "summary.json" if which == "shapes" else
                               "summary-joints.json")
        if args.report_only:
            with open(summary) as f:
                records = json.load(f)
        elif which == "shapes":
            records = run_shapes(args, binary, out_root, methods)
        else:
            records = run_joints(args, binary, out_root)
        if not args.report_only:
            with open(summary, "w") as f:
                json.dump(records, f, indent=1)
        if which == "shapes":
            write_results(args, records, methods)
        else:
            write_joint_results(args, records)
        log(f"wrote {args.results} ({which})")
    return 0


def scan_name(shape, res, dist, tilt, seed):
    return f"{shape}-{res}-d{dist:.2f}-t{tilt:+d}-s{seed}"


def render(binary, out_root, name, flags):
    """The scan `name` under out_root/scans, rendered with `synth flags` unless it exists."""
    scan = os.path.join(out_root, "scans", name + ".pcd")
    if not os.path.exists(scan):
        os.makedirs(os.path.dirname(scan), exist_ok=True)
        rc, so, se, _ = run([binary, "synth"] + flags + ["-o", scan])
        if rc != 0:
            log(f"synth failed for {name}: {se.strip()}")
            return None
    return scan


def run_shapes(args, binary, out_root, methods):
    scans = sweep_scans()
    if args.quick:
        scans = [s for s in scans if s[1] == RESOLUTIONS[0]][::3]
    keep = name_filter(args.only)
    scans = [s for s in scans if keep(scan_name(*s))]
    records = []
    for shape, res, dist, tilt, seed in scans:
        name = scan_name(shape, res, dist, tilt, seed)
        scan = render(binary, out_root, name, ["--shape", shape, "--resolution", res, "--distance",
                                               str(dist), "--tilt", str(tilt), "--seed", str(seed)])
        if scan is None:
            continue
        for method in methods:
            records.append(organized_run(binary, out_root, method, scan, name,
                                         (shape, res, dist, tilt, seed)))
    # Variants of the 640x480 scans for the robust method: unorganized, and base frame.
    variant_scans = [s for s in scans if s[1] == RESOLUTIONS[0]]
    variant_scans = variant_scans[::3] if not args.quick else variant_scans
    if "robust" in methods:
        for s in variant_scans:
            for variant in ("unorganized", "base_frame"):
                records.append(variant_run(binary, out_root, s, variant))
        straight = [s for s in scans if s[0] == "straight" and s[1] == RESOLUTIONS[0]]
        if straight:
            records.append(no_groove_run(binary, out_root, straight[0]))
    return records


def trajectory_csvs(out):
    csvs = [os.path.join(out, "trajectory.csv")]
    if os.path.exists(os.path.join(out, "trajectory_1.csv")):
        csvs.append(os.path.join(out, "trajectory_1.csv"))
    return csvs


def organized_run(binary, out_root, method, scan, name, spec):
    shape, res, dist, tilt, seed = spec
    out = os.path.join(out_root, method, name)
    r = one_run(binary, method, scan, out, shape)
    rec = {"scan": name, "shape": shape, "res": res, "distance": dist, "tilt": tilt,
           "seed": seed, "method": method, "variant": "organized", **r}
    if r["rc"] == 0:
        rec["metrics"] = evaluate(binary, scan, out)
        csvs = trajectory_csvs(out)
        rec["problems"] = []
        for c in csvs:
            problems, n = check_trajectory(c)
            rec["problems"] += problems
        if len(csvs) > 1:
            rec["coverage_union"] = union_coverage(scan[:-4] + ".truth.json", csvs)
    m = rec.get("metrics") or {}
    log(f"{name:38s} {method:7s} rc {r['rc']} IoU {fmt(m.get('iou_percent'))} "
        f"lat {fmt((m.get('lateral_mean_m') or float('nan')) * 1e3)} "
        f"tool {fmt(m.get('tool_axis_mean_deg'))} cov {fmt(m.get('coverage_percent'), 1)}"
        f" {' '.join(rec.get('problems', []))} [{r['wall_s']:.1f} s]")
    return rec


def variant_cloud(scan, seed, variant, vscan):
    """Writes the scan's valid points, shuffled, as an unorganized cloud (in the robot base
    frame for base_frame); returns (rows, width, height, order, run extra, eye)."""
    header, fields, rows = read_pcd(scan)
    w, h = int(header["WIDTH"][0]), int(header["HEIGHT"][0])
    order = [i for i, r in enumerate(rows) if not math.isnan(r[0])]
    random.Random(seed).shuffle(order)
    if variant == "unorganized":
        write_pcd_ascii(vscan, ["x", "y", "z"], [rows[i][:3] for i in order], len(order), 1)
        return rows, w, h, order, [], (0.0, 0.0, 0.0)
    write_pcd_ascii(vscan, ["x", "y", "z"], [to_base(rows[i][:3]) for i in order], len(order), 1)
    extra = ["--viewpoint", ",".join(f"{v:.9g}" for v in T_BASE_CAMERA)]
    return rows, w, h, order, extra, T_BASE_CAMERA


def to_camera_frame(out, edir, csvs, rows, w, h, order, variant):
    """The run's annotated cloud and trajectories back in the scan's order and camera frame,
    under edir, for `groovetrace eval`."""
    _, afields, arows = read_pcd(os.path.join(out, "annotated.pcd"))
    g = afields.index("groove")
    groove = [0] * len(rows)
    for k, i in enumerate(order):
        groove[i] = int(arows[k][g])
    os.makedirs(edir, exist_ok=True)
    write_pcd_ascii(os.path.join(edir, "annotated.pcd"), ["x", "y", "z", "groove"],
                    [rows[i][:3] + [groove[i]] for i in range(len(rows))], w, h)
    inv = (-Q_BASE_CAMERA[0], -Q_BASE_CAMERA[1], -Q_BASE_CAMERA[2], Q_BASE_CAMERA[3])
    for c in csvs:
        head, trows = read_csv(c)
        if variant == "base_frame":
            ix, iq = head.index("x_m"), head.index("qx")
            for t in trows:
                t[ix:ix + 3] = list(from_base(tuple(t[ix:ix + 3])))
                t[iq:iq + 4] = list(qmul(inv, tuple(t[iq:iq + 4])))
        write_csv(os.path.join(edir, os.path.basename(c)), head, trows)


def variant_run(binary, out_root, spec, variant):
    shape, res, dist, tilt, seed = spec
    name = scan_name(*spec)
    scan = os.path.join(out_root, "scans", name + ".pcd")
    vdir = os.path.join(out_root, "variants", variant)
    os.makedirs(vdir, exist_ok=True)
    vscan = os.path.join(vdir, name + ".pcd")
    rows, w, h, order, extra, eye = variant_cloud(scan, seed, variant, vscan)
    out = os.path.join(out_root, "robust-" + variant, name)
    r = one_run(binary, "robust", vscan, out, shape, extra)
    rec = {"scan": name, "shape": shape, "res": res, "distance": dist, "tilt": tilt,
           "seed": seed, "method": "robust", "variant": variant, **r}
    if r["rc"] == 0:
        csvs = trajectory_csvs(out)
        rec["problems"] = []
        for c in csvs:
            rec["problems"] += check_trajectory(c, eye)[0]
        edir = os.path.join(out, "camera_frame")
        to_camera_frame(out, edir, csvs, rows, w, h, order, variant)
        rec["metrics"] = evaluate(binary, scan, edir)
        if len(csvs) > 1:
            rec["coverage_union"] = union_coverage(
                scan[:-4] + ".truth.json", [os.path.join(edir, os.path.basename(c)) for c in csvs])
    m = rec.get("metrics") or {}
    log(f"{name:38s} {variant:11s} rc {r['rc']} IoU {fmt(m.get('iou_percent'))} "
        f"lat {fmt((m.get('lateral_mean_m') or float('nan')) * 1e3)} "
        f"{' '.join(rec.get('problems', []))}")
    return rec


def no_groove_run(binary, out_root, spec):
    """No groove: a scan with its groove band (20 mm around the root) cut out; must exit 4."""
    name = scan_name(*spec)
    scan = os.path.join(out_root, "scans", name + ".pcd")
    header, fields, rows = read_pcd(scan)
    with open(scan[:-4] + ".truth.json") as f:
        truth = json.load(f)
    root = truth["seams"][0]["root"]
    cut = []
    for r in rows:
        p = r[:3]
        near = not math.isnan(p[0]) and min(math.dist(p, q) for q in root[::4]) < 0.02
        cut.append([float("nan")] * 3 if near else p)
    nscan = os.path.join(out_root, "variants", "no_groove.pcd")
    os.makedirs(os.path.dirname(nscan), exist_ok=True)
    write_pcd_ascii(nscan, ["x", "y", "z"], cut, int(header["WIDTH"][0]), int(header["HEIGHT"][0]))
    r = one_run(binary, "robust", nscan, os.path.join(out_root, "robust-no-groove"), "none")
    log(f"no groove: rc {r['rc']} {' '.join(r['stderr'])}")
    return {"scan": name + " groove cut out", "method": "robust", "variant": "no_groove",
            "shape": "none", **r}


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
    L += shape_rows(organized, methods)
    L += shape_target_rows(organized)
    L += shape_scan_rows(records)
    L += shape_robustness_rows(args, records)
    splice_results(os.path.join(ROOT, args.results), "\n".join(L), False)


def shape_rows(organized, methods):
    """Per resolution and shape: the means and worst values."""
    L = []
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
    return L


def shape_target_rows(organized):
    """The shapes set against issue 4's targets, per resolution."""
    L = []
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
    return L


def shape_scan_rows(records):
    """The shapes set: every run."""
    L = []
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
    return L


def shape_robustness_rows(args, records):
    """The shapes set: crashes, misses, trajectory checks, commands."""
    L = []
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
    return L


# --- issue 12: shop joints and conditions (--set joints) ----------------------------------------

# Poses (resolution, distance m, tilt deg) that families take in turn (three consecutive ones
# from an offset), so that every distance 0.30-0.55 m and tilt -20..35 deg and both
# resolutions come up. Fillet and lap scenes are seen down the corner's bisector at tilt 0
# (docs/synthetic-scans.md, "Joints"): their tilt adds to that 45 deg, so they keep to -20..15.
POSES_PLATE = [("640x480", 0.30, 10), ("1280x720", 0.40, 0), ("640x480", 0.55, -20),
               ("1280x720", 0.45, 25), ("640x480", 0.35, 35), ("1280x720", 0.50, -10),
               ("640x480", 0.40, 20), ("1280x720", 0.35, -15), ("1280x720", 0.55, 30),
               ("640x480", 0.45, 5)]
POSES_CORNER = [("640x480", 0.35, 0), ("1280x720", 0.45, -20), ("1280x720", 0.30, 10),
                ("640x480", 0.50, 15), ("1280x720", 0.55, -10), ("640x480", 0.40, 5)]
POSES_TILT35 = [("640x480", 0.40, 35), ("1280x720", 0.30, 35), ("1280x720", 0.55, 35)]
POSES_FAR = [("640x480", 0.70, 0), ("640x480", 0.70, 15), ("640x480", 0.70, -10)]
PIPE_DIAMETERS = [0.06, 0.079, 0.10, 0.20]
SHALLOW = ["--groove-width", "0.012", "--groove-angle", "140", "--pipe-diameter", "0.079"]

# The targets per family; the far case gets 1.0 mm for lateral and depth.
TARGETS = {"iou": 90.0, "lateral_mm": 0.5, "depth_mm": 0.5, "tool_deg": 2.0, "coverage": 98.0}
FAR_MM = 1.0
TARGET_LABELS = {"iou": ("IoU mean", "%", ">="), "lateral_mm": ("lateral mean", "mm", "<="),
                 "depth_mm": ("depth mean", "mm", "<="), "tool_deg": ("tool axis mean", "deg", "<="),
                 "coverage": ("coverage mean", "%", ">=")}


def v_groove(width_mm, angle):
    return ["--groove-width", f"{width_mm / 1000:g}", "--groove-angle", str(angle)]


def joint_families():
    """(family, what it is, shape, synth flags, poses) of the joints set, in report order."""
    plate = lambda k, n=3: [POSES_PLATE[(k + j) % len(POSES_PLATE)] for j in range(n)]
    corner = lambda k: [POSES_CORNER[(k + j) % len(POSES_CORNER)] for j in range(3)]
    fams = [
        ("bevel45", "single bevel 45 deg, 8 mm deep", "straight",
         ["--joint", "bevel", "--groove-angle", "45", "--groove-width", "0.0085"], plate(0)),
        ("bevel30", "single bevel 30 deg, 8 mm deep", "straight",
         ["--joint", "bevel", "--groove-angle", "30", "--groove-width", "0.0051"], plate(3)),
        ("fillet", "fillet (T-joint), 10 mm weld face", "straight", ["--joint", "fillet"],
         corner(0)),
        ("lap", "lap joint, 10 mm weld face", "straight", ["--joint", "lap"], corner(3)),
    ]
    sizes = [(4, 60), (6, 50), (16, 90), (25, 120), (40, 120), (60, 160), (100, 150), (100, 170)]
    for k, (w, a) in enumerate(sizes):
        fams.append((f"v{w}-{a}", f"V {w} mm wide, {a} deg", "straight", v_groove(w, a),
                     plate(6 + 3 * k)))
    fams += pipe_families(plate)
    fams += [
        ("root-gap2", "V 12 mm, 2 mm root opening", "straight",
         ["--root-gap", "0.002", "--groove-width", "0.012"], plate(1)),
        ("tacks", "V, 3 tack welds to 70 % of the depth", "straight",
         ["--tacks", "3", "--tack-height", "0.7"], plate(4)),
        ("high-low", "V, 1.5 mm high-low", "straight", ["--misalignment", "0.0015"], plate(7)),
        ("clamps-bar", "V, 2 clamps and a loose bar", "straight",
         ["--clamps", "2", "--clutter", "1"], plate(2)),
        ("tilt35", "V, camera at 35 deg", "straight", [], POSES_TILT35),
        ("far", "V at 0.70 m, 640x480", "straight", [], POSES_FAR),
    ]
    return fams


def pipe_families(plate):
    """Girth (cylinder) and long seams (pipe-long): one pose per diameter, then the shallow
    wide groove (12 mm, 140 deg) on the 79 mm pipe at both resolutions."""
    fams = []
    for k, (family, shape) in enumerate([("girth", "cylinder"), ("pipe-long", "pipe-long")]):
        poses = plate(5 + 4 * k, 4)
        fams.append((family, f"{shape}, V 10 mm 60 deg, diameter 60/79/100/200 mm", shape,
                     [[str(d)] for d in PIPE_DIAMETERS], poses))
        fams.append((family + "-shallow", f"{shape} 79 mm, V 12 mm 140 deg (2.1 mm deep)", shape,
                     SHALLOW, [("640x480", 0.35, 0), ("1280x720", 0.45, 20 if k else -15)]))
    return fams


def joint_scans():
    """Every scan of the joints set: dicts with family, name, shape, synth flags, pose, seed.
    A family whose flags are a list of lists gives each scan its own --pipe-diameter."""
    scans, seed = [], 301
    for family, what, shape, flags, poses in joint_families():
        for j, (res, dist, tilt) in enumerate(poses):
            f, tag = flags, ""
            if flags and isinstance(flags[0], list):
                f, tag = ["--pipe-diameter"] + flags[j], f"-D{float(flags[j][0]) * 1000:.0f}"
            name = f"{family}{tag}-{res}-d{dist:.2f}-t{tilt:+d}-s{seed}"
            synth = ["--shape", shape] + f + ["--resolution", res, "--distance", str(dist),
                                              "--tilt", str(tilt), "--seed", str(seed)]
            scans.append({"family": family, "what": what, "scan": name, "shape": shape,
                          "res": res, "distance": dist, "tilt": tilt, "seed": seed,
                          "flags": f, "synth": synth, "expect": "joint"})
            seed += 1
    return scans


def seam_report(out):
    """report.json robust.seams entry of the exported seam (file trajectory.csv), or {}."""
    try:
        with open(os.path.join(out, "report.json")) as f:
            seams = json.load(f).get("robust", {}).get("seams", [])
    except (OSError, ValueError):
        return {}
    return next((s for s in seams if s.get("file") == "trajectory.csv"), {})


def joint_run(binary, out_root, spec):
    """Renders, runs (robust, defaults), evaluates and checks one scan of the joints set."""
    rec = dict(spec)
    rec["synth_cmd"] = "groovetrace synth " + " ".join(shlex.quote(a) for a in spec["synth"])
    scan = render(binary, out_root, spec["scan"], spec["synth"])
    if scan is None:
        rec.update(rc=-1, wall_s=0.0, stderr=["synth failed"], cmd="")
        return rec
    out = os.path.join(out_root, "robust-joints", spec["scan"])
    rec.update(one_run(binary, "robust", scan, out, spec["shape"]))
    rec["method"], rec["variant"] = "robust", "joints"
    if rec["rc"] == 0:
        rec["metrics"] = evaluate(binary, scan, out)
        csvs = trajectory_csvs(out)  # a seam's stretch past a clamp is exported beside it
        rec["problems"] = [p for c in csvs for p in check_trajectory(c)[0]]
        if len(csvs) > 1:
            rec["coverage_union"] = union_coverage(scan[:-4] + ".truth.json", csvs)
        rec["scale_m"] = seam_report(out).get("scale_m")
    with open(scan[:-4] + ".truth.json") as f:
        truth = json.load(f)
    rec["joint_expected"] = truth["seams"][0].get("joint", "V")
    rec["tacks_expected"] = sum(len(s.get("tacks", [])) for s in truth["seams"])
    m = rec.get("metrics") or {}
    log(f"{spec['scan']:44s} rc {rec['rc']} IoU {fmt(m.get('iou_percent'))} "
        f"lat {fmt((m.get('lateral_mean_m') or float('nan')) * 1e3)} "
        f"dep {fmt((m.get('depth_mean_m') or float('nan')) * 1e3)} "
        f"tool {fmt(m.get('tool_axis_mean_deg'))} cov {fmt(m.get('coverage_percent'), 1)} "
        f"joint {rec['joint_expected']}/{m.get('joint_found')} "
        f"{' '.join(rec.get('problems', []))} [{rec['wall_s']:.1f} s]")
    return rec


def fill_joint(scan, filled, seed):
    """Writes `filled`: the scan with every pixel labelled as joint (labels.pcd) replaced by
    the part's top plane z_workpiece = thickness along the pixel's ray, with the D415's
    per-pixel depth noise (SensorModel subpixel), depth quantisation, the left band and
    min-z: a plate with no groove, its clamps and bars kept. synth cannot render a part
    without a joint, so this stands in for one."""
    header, _, rows = read_pcd(scan)
    _, lfields, labels = read_pcd(scan[:-4] + ".labels.pcd")
    with open(scan[:-4] + ".truth.json") as f:
        truth = json.load(f)
    cam, T = truth["camera"], truth["T_workpiece_camera"]
    T = [v for row in T for v in row] if isinstance(T[0], list) else T  # 4x4, row-major
    sensor, unit = truth["params"]["sensor"], truth["params"]["depth_unit_m"]
    top = truth["groove"]["thickness_m"]
    w = int(header["WIDTH"][0])
    il = lfields.index("label")
    rng = random.Random(seed)
    out = []
    for i, r in enumerate(rows):
        if not labels[i][il]:
            out.append(r[:3])
            continue
        u, v = i % w, i // w
        ray = ((u - cam["cx"]) / cam["fx"], (v - cam["cy"]) / cam["fy"], 1.0)
        den = sum(T[8 + k] * ray[k] for k in range(3))
        z = (top - T[11]) / den if den else -1.0
        disparity = cam["fx"] * cam["baseline_m"] / z if z > 0 else 0.0
        if z < sensor["min_z_m"] or u < disparity:
            out.append([float("nan")] * 3)
            continue
        z = cam["fx"] * cam["baseline_m"] / (disparity + rng.gauss(0.0, sensor["subpixel_px"]))
        z = round(z / unit) * unit
        out.append([ray[0] * z, ray[1] * z, z])
    write_pcd_ascii(filled, ["x", "y", "z"], out, w, int(header["HEIGHT"][0]))


def no_joint_scans():
    """The scenes that must exit 4: the shapes set's groove-cut-out scene, and plates with
    clamps and a loose bar whose joint is filled in (fill_joint)."""
    plates = [("640x480", 0.40, 10, 401), ("1280x720", 0.35, -15, 402)]
    scans = []
    for res, dist, tilt, seed in plates:
        name = f"nojoint-clamps-bar-{res}-d{dist:.2f}-t{tilt:+d}-s{seed}"
        synth = ["--shape", "straight", "--clamps", "2", "--clutter", "1", "--resolution", res,
                 "--distance", str(dist), "--tilt", str(tilt), "--seed", str(seed)]
        scans.append({"family": "no-joint", "what": "plate, 2 clamps, a loose bar, joint filled "
                      "in", "scan": name, "shape": "straight", "res": res, "distance": dist,
                      "tilt": tilt, "seed": seed, "flags": ["--clamps", "2", "--clutter", "1"],
                      "synth": synth, "expect": "none"})
    return scans


def no_joint_run(binary, out_root, spec):
    rec = dict(spec, method="robust", variant="no_joint")
    rec["synth_cmd"] = ("groovetrace synth " + " ".join(shlex.quote(a) for a in spec["synth"]) +
                        "; joint filled in by fill_joint")
    scan = render(binary, out_root, spec["scan"], spec["synth"])
    if scan is None:  # render logged why (a full disk ended a sweep here in a traceback)
        rec.update(rc=-1, wall_s=0.0, stderr=["synth failed"], cmd="")
        return rec
    filled = os.path.join(out_root, "variants", "no_joint", spec["scan"] + ".pcd")
    os.makedirs(os.path.dirname(filled), exist_ok=True)
    fill_joint(scan, filled, spec["seed"])
    out = os.path.join(out_root, "robust-no-joint", spec["scan"])
    rec.update(one_run(binary, "robust", filled, out, "none"))
    if rec["rc"] == 0:
        s = seam_report(out)
        rec["found"] = {k: s.get(k) for k in ("joint", "length_m", "width_m", "depth_m",
                                              "score", "scale_m")}
    log(f"{spec['scan']:44s} rc {rec['rc']} (expected 4) {' '.join(rec['stderr'])}")
    return rec


def run_joints(args, binary, out_root):
    scans = joint_scans()
    if args.quick:
        seen = set()
        scans = [s for s in scans if not (s["family"] in seen or seen.add(s["family"]))]
    keep = name_filter(args.only)
    records = [joint_run(binary, out_root, s) for s in scans if keep(s["scan"])]
    base = [s for s in sweep_scans() if s[0] == "straight" and s[1] == RESOLUTIONS[0]][0]
    if keep(scan_name(*base) + " groove cut out"):
        render(binary, out_root, scan_name(*base),
               ["--shape", base[0], "--resolution", base[1], "--distance", str(base[2]),
                "--tilt", str(base[3]), "--seed", str(base[4])])
        rec = no_groove_run(binary, out_root, base)
        records.append(dict(rec, family="no-joint", what="V plate, groove band cut out "
                            "(the shapes set's scene)", expect="none"))
    for s in no_joint_scans():
        if keep(s["scan"]) and (not args.quick or s["res"] == "640x480"):
            records.append(no_joint_run(binary, out_root, s))
    return records


# --- the joints set's tables -------------------------------------------------------------------

JOINTS_BEGIN = "<!-- robust_sweep.py --set joints: begin -->"
JOINTS_END = "<!-- robust_sweep.py --set joints: end -->"


def splice_results(path, text, joints):
    """Writes the shapes tables (joints False) or the joints section (True) into path, keeping
    the other part if the file has it; the joints section sits between JOINTS_BEGIN/END."""
    old = ""
    if os.path.exists(path):
        with open(path) as f:
            old = f.read()
    b, e = old.find(JOINTS_BEGIN), old.find(JOINTS_END)
    section = old[b:e + len(JOINTS_END)] + "\n" if b >= 0 and e > b else ""
    if joints:
        block = JOINTS_BEGIN + "\n" + text + JOINTS_END + "\n"
        if section:
            new = old.replace(section, block)
        else:
            new = old + ("\n" if old and not old.endswith("\n\n") else "") + block
    else:
        new = text + ("\n" + section if section else "")
    with open(path, "w") as f:
        f.write(new)


def scan_values(r):
    """Per-scan values for the tables: IoU and coverage 0 when no joint was found (exit not
    0), lateral, depth (mm) and tool axis only from runs that found one."""
    m = r.get("metrics") or {}
    found = r["rc"] == 0 and bool(m)
    mm = lambda k: m.get(k) * 1e3 if found and m.get(k) is not None else float("nan")
    num = lambda k, miss: (m.get(k) if m.get(k) is not None else float("nan")) if found else miss
    coverage = r["coverage_union"] if found and "coverage_union" in r else \
        num("coverage_percent", 0.0)
    return {"found": found, "iou": num("iou_percent", 0.0), "lateral_mm": mm("lateral_mean_m"),
            "depth_mm": mm("depth_mean_m"), "tool_deg": num("tool_axis_mean_deg", float("nan")),
            "coverage": coverage, "joint_found": m.get("joint_found"),
            "joint_match": m.get("joint_match") if found else None}


def family_checks(rs):
    """{target: (mean, min, max, scans meeting it, pass)} of a family; pass = the family's
    mean meets the target (scans without a finite value count as not meeting it)."""
    far = rs[0]["family"] == "far"
    vals = [scan_values(r) for r in rs]
    out = {}
    for key, limit in TARGETS.items():
        if far and key in ("lateral_mm", "depth_mm"):
            limit = FAR_MM
        xs = [v[key] for v in vals]
        finite = [x for x in xs if not math.isnan(x)]
        up = key in ("iou", "coverage")
        meets = sum(1 for x in finite if (x >= limit if up else x <= limit))
        avg = mean(xs)
        ok = not math.isnan(avg) and (avg >= limit if up else avg <= limit)
        out[key] = (avg, min(finite, default=float("nan")), max(finite, default=float("nan")),
                    meets, ok, limit)
    reported = [v for v in vals if v["joint_found"] is not None]
    matched = sum(1 for v in reported if v["joint_match"])
    out["joint"] = (matched, len(reported), len(reported) > 0 and matched == len(reported))
    return out


def joint_families_in(records):
    order = [f[0] for f in joint_families()]
    fams = sorted({r["family"] for r in records if r.get("expect") == "joint"},
                  key=lambda f: order.index(f) if f in order else len(order))
    return [(f, [r for r in records if r.get("family") == f and r.get("expect") == "joint"])
            for f in fams]


def family_value_rows(records):
    L = ["| family | joint | scans | found | IoU % | lateral mean mm | depth mean mm | "
         "tool axis mean deg | coverage % | joint found (matches/reported) | scale mm |",
         "|---|---|---:|---:|---:|---:|---:|---:|---:|---|---|"]
    for fam, rs in joint_families_in(records):
        c = family_checks(rs)
        cell = lambda k, d=2: ("-" if math.isnan(c[k][1]) else
                               f"{fmt(c[k][0], d)} ({fmt(c[k][1], d)}-{fmt(c[k][2], d)})")
        found = sorted({str(scan_values(r)["joint_found"]) for r in rs if r["rc"] == 0})
        joint = f"{'/'.join(found)} ({c['joint'][0]}/{c['joint'][1]})" if found else "-"
        scales = [fmt(x * 1e3, 0) for x in sorted({r["scale_m"] for r in rs
                                                   if r["rc"] == 0 and r.get("scale_m")})]
        L.append(f"| {fam} | {rs[0].get('joint_expected', '-')} | {len(rs)} | "
                 f"{sum(1 for r in rs if scan_values(r)['found'])} | {cell('iou')} | "
                 f"{cell('lateral_mm')} | {cell('depth_mm')} | {cell('tool_deg')} | "
                 f"{cell('coverage', 1)} | {joint} | {', '.join(scales) or '-'} |")
    return L


def family_target_rows(records):
    """The targets table and the failing families (family: the targets it misses)."""
    L = ["| family | what | IoU >= 90 % | lateral mean <= 0.5 mm | depth mean <= 0.5 mm | "
         "tool axis mean <= 2 deg | coverage >= 98 % | joint type matches | all |",
         "|---|---|---|---|---|---|---|---|---|"]
    failing = []
    for fam, rs in joint_families_in(records):
        c = family_checks(rs)
        cells, missed = [], []
        for key in TARGETS:
            avg, lo, hi, meets, ok, limit = c[key]
            cells.append(f"{'pass' if ok else '**FAIL**'} {meets}/{len(rs)}")
            if not ok:
                label, unit, sense = TARGET_LABELS[key]
                value = "- (no scan found the joint)" if math.isnan(avg) else f"{fmt(avg)} {unit}"
                missed.append(f"{label} {value} (target {sense} {limit:g})")
        m, n, ok = c["joint"]
        cells.append("-" if n == 0 else f"{'pass' if ok else '**FAIL**'} {m}/{n}")
        if n and not ok:
            found = {str(scan_values(r)["joint_found"]) for r in rs if r["rc"] == 0}
            missed.append(f"joint type {m}/{n} ({'/'.join(sorted(found))} found for "
                          f"{rs[0].get('joint_expected')})")
        if missed:
            failing.append(f"- {fam}: " + "; ".join(missed))
        L.append(f"| {fam} | {rs[0]['what']} | " + " | ".join(cells) +
                 f" | {'pass' if not missed else '**FAIL**'} |")
    return L, failing


def scan_rows(records):
    L = ["| scan | family | synth flags | exit | IoU % | lateral mean/max mm | depth mean/max mm | "
         "tool axis mean/max deg | coverage % | joint expected/found | scale mm | checks | "
         "time s |", "|---|---|---|---:|---:|---:|---:|---:|---:|---|---:|---|---:|"]
    for r in records:
        if r.get("expect") != "joint":
            continue
        m, v = r.get("metrics") or {}, scan_values(r)
        pair = lambda a, b, s=1e3: (f"{fmt((m.get(a) or float('nan')) * s)}/"
                                    f"{fmt((m.get(b) or float('nan')) * s)}")
        checks = ", ".join(r.get("problems", [])) or ("ok" if r["rc"] == 0 else
                                                     " ".join(r.get("stderr", [])))
        flags = f"`{' '.join(r['flags'])}`" if r["flags"] else "(defaults)"
        L.append(f"| {r['scan']} | {r['family']} | {flags} | {r['rc']} | "
                 f"{fmt(v['iou'])} | {pair('lateral_mean_m', 'lateral_max_m')} | "
                 f"{pair('depth_mean_m', 'depth_max_m')} | "
                 f"{pair('tool_axis_mean_deg', 'tool_axis_max_deg', 1)} | "
                 f"{fmt(v['coverage'], 1)} | "
                 f"{r.get('joint_expected', '-')}/{v['joint_found'] or '-'} | "
                 f"{fmt((r.get('scale_m') or float('nan')) * 1e3, 0)} | {checks} | "
                 f"{r['wall_s']:.1f} |")
    return L


def tack_rows(records):
    """Every scan whose truth has tacks: what metrics.json's `tacks` block says."""
    L = ["| scan | found / expected | extra | position error mean/max mm | length bias mm |",
         "|---|---:|---:|---:|---:|"]
    for r in records:
        t = (r.get("metrics") or {}).get("tacks") or {}
        if r.get("expect") != "joint" or not r.get("tacks_expected"):
            continue
        if r["rc"] != 0 or not t.get("reported"):
            L.append(f"| {r['scan']} | - / {r['tacks_expected']} | - | - | - |")
            continue
        mm = lambda k: fmt((t.get(k) if t.get(k) is not None else float("nan")) * 1e3, 1)
        L.append(f"| {r['scan']} | {t['found']} / {t['expected']} | {t['extra']} | "
                 f"{mm('position_error_mean_m')}/{mm('position_error_max_m')} | "
                 f"{mm('length_bias_m')} |")
    return L


def no_joint_rows(records):
    L = ["| scene | exit (expected 4) | result |", "|---|---:|---|"]
    for r in records:
        if r.get("expect") != "none":
            continue
        if r["rc"] == 4:
            what = "pass: " + " ".join(r.get("stderr", []))
        elif r["rc"] == 0:
            f = r.get("found") or {}
            length, width = (f.get("length_m") or 0) * 1e3, (f.get("width_m") or 0) * 1e3
            what = (f"**FAIL**: found a {f.get('joint')} seam, {fmt(length, 0)} mm long, "
                    f"{fmt(width, 1)} mm wide, {fmt((f.get('depth_m') or 0) * 1e3, 1)} mm deep "
                    f"(scale {fmt((f.get('scale_m') or 0) * 1e3, 0)} mm)")
        else:
            what = "**FAIL**: " + " ".join(r.get("stderr", []))
        L.append(f"| {r['scan']}: {r['what']} | {r['rc']} | {what} |")
    return L


def joint_header(args, records):
    fams = len(joint_families_in(records))
    runs = [r for r in records if r.get("expect") == "joint"]
    total = sum(r.get("wall_s", 0.0) for r in records)
    return [
        "# Results: shop joints and conditions (issue 12)", "",
        f"Written by `{args.invocation}` (`--set joints`) - do not edit by hand; re-run the "
        f"script. Generated {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.", "",
        f"Scans: {len(runs)} `groovetrace synth` scans in {fams} families (every D415 effect on; "
        "each scan its own seed, distance 0.30-0.55 m - the far case 0.70 m - tilt -20..35 deg, "
        "640x480 and 1280x720; synth flags per scan below), and "
        f"{sum(1 for r in records if r.get('expect') == 'none')} scenes without a joint. One "
        "default configuration: `groovetrace run --method robust`. Metrics from `groovetrace "
        "eval`; the tool axis is scored against the truth's own bisector of each joint "
        "(docs/synthetic-scans.md, \"Joints\"). "
        f"Run time of the robust runs: {total:.0f} s in all.", "",
        "Targets (issue 12), per family: IoU >= 90 %, lateral and depth error mean <= 0.5 mm "
        f"(far case: <= {FAR_MM:g} mm), tool axis mean <= 2 deg, coverage >= 98 %, joint type "
        "matches (metrics.json `joint_match`) where the run reports one. A family passes a "
        "target when its mean over its scans meets it; k/n = scans meeting it on their own. A "
        "scan that exits 4 (no groove found) although it has a joint counts as found = no, IoU "
        "0 % and coverage 0 %; its lateral, depth and tool axis are left out (no trajectory). "
        "Where a stretch past a clamp is exported beside the seam (trajectory_1.csv), coverage "
        "is over the union of both trajectories. "
        "found = exit 0: the exported seam may still be another one than the joint (IoU near 0, "
        "errors of centimetres: see every scan). "
        "The detector reports `V`, `bevel`, `fillet` or `lap` per seam.", ""]


def write_joint_results(args, records):
    L = joint_header(args, records)
    L += ["## Joints: per family (mean (min-max) over its scans)", ""]
    L += family_value_rows(records) + [""]
    targets, failing = family_target_rows(records)
    L += ["## Joints: against the targets", ""] + targets + [""]
    L += ["## Joints: failing families", ""] + (failing or ["- none"]) + [""]
    L += ["## Joints: no-joint scenes", "",
          "`groovetrace synth` cannot render a part without a joint; the plates with clamps "
          "and a bar are rendered with a V and their joint pixels (labels.pcd) replaced by the "
          "top plane with D415 depth noise (`fill_joint` in the script).", ""]
    L += no_joint_rows(records) + [""]
    L += ["## Joints: tack welds", "",
          "The tacks report.json lists for the exported seam against the renderer's (metrics.json "
          "`tacks`, docs/synthetic-scans.md): matched where their extents along the root overlap; "
          "length bias = reported minus true length.", ""]
    L += tack_rows(records) + [""]
    L += ["## Joints: every scan", ""] + scan_rows(records) + [""]
    runs = [r for r in records if r.get("expect") == "joint"]
    crashes = [r for r in records if r["rc"] not in (0, 4)]
    missed = [r for r in runs if r["rc"] == 4]
    bad = [r for r in runs if r.get("problems")]
    L += ["## Joints: robustness", "",
          f"- runs: {len(records)}; crashes or errors (exit not 0/4): {len(crashes)}"
          + ("" if not crashes else " (" + ", ".join(r["scan"] for r in crashes) + ")"),
          f"- no groove found (exit 4) on a scan that has one: {len(missed)}"
          + ("" if not missed else " (" + ", ".join(r["scan"] for r in missed) + ")"),
          f"- trajectories with NaN, a jump over 3 x {STEP_M * 1000:.0f} mm or a tool axis "
          f"towards the sensor: {len(bad)}" + ("" if not bad else " (" + "; ".join(
              f"{r['scan']}: {', '.join(r['problems'])}" for r in bad) + ")"), ""]
    L += ["Commands: `" + args.invocation + "`; per scan `groovetrace synth --shape S FLAGS "
          "--resolution R --distance D --tilt T --seed N -o SCAN`, `" +
          (runs[0]["cmd"] if runs else "groovetrace run SCAN -o OUT -q --method robust") +
          "` and `groovetrace eval --truth SCAN --result OUT` (summary-joints.json under --out "
          "has every command).", ""]
    splice_results(os.path.join(ROOT, args.results), "\n".join(L), True)


if __name__ == "__main__":
    sys.exit(main())

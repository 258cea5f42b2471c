#!/usr/bin/python3
"""Reproduces the paper's Tables I and II on synthetic D415 scans and writes docs/results.md.

    scripts/paper_tables.py [--quick] [--bin build/groovetrace] [--out out/paper_tables]
        [--backend cpu|opencl|auto] [--results FILE.md] [--figures DIR]

For each of straight, curve, box and cylinder it renders five scans (seeds 1-5) at the
paper's scale (its Table I point counts), runs every detection method `groovetrace run --help`
offers (the default one without --method, the others with it), scores each run with
`groovetrace eval`, and writes the tables (with the paper's numbers beside), the trajectory
errors, the commands, the machine and a picture per shape and method.
Scans and run outputs go to --out (git-ignored); the results file and the pictures to docs/.
--quick: one seed per shape, and (unless --results/--figures are given) the results file and
pictures go under --out, so the committed docs/results.md is left alone.

Standard library only; run with Debian's /usr/bin/python3.
"""

import argparse
import datetime
import json
import math
import os
import re
import shlex
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# The paper's published numbers (groove-detection-paper.tex, Tables I and II).
PAPER = {
    "straight": {"name": "Straight-line", "points": 265800, "t_mean": 14.09,
                 "lambda": [92.74, 93.01, 92.81, 92.49, 91.35], "lambda_mean": 92.48},
    "curve": {"name": "Curve-line", "points": 266497, "t_mean": 14.08,
              "lambda": [81.24, 82.58, 82.13, 81.87, 82.29], "lambda_mean": 82.02},
    "box": {"name": "Box", "points": 127031, "t_mean": 7.51,
            "lambda": [81.48, 82.65, 82.02, 80.49, 81.97], "lambda_mean": 81.72},
    "cylinder": {"name": "Cylinder", "points": 121429, "t_mean": 6.05,
                 "lambda": [63.27, 61.79, 64.69, 67.57, 65.75], "lambda_mean": 64.61},
}
SHAPES = ["straight", "curve", "box", "cylinder"]

# Frames chosen so that the valid (finite) points come close to the paper's P_num. The D415's
# 640x480 mode gives ~272.6k valid points for the plates (the paper's 265.8k / 266.5k look like
# 640x480 frames with ~87% returns); box and cylinder use smaller 4:3 frames with the same
# field of view (fx scales with the width), sized so the valid count lands on the paper's.
FRAMES = {"straight": (640, 480), "curve": (640, 480), "box": (434, 326), "cylinder": (424, 318)}
SEEDS = [1, 2, 3, 4, 5]
STOP_WORDS = {"or", "and", "the", "default", "is", "method", "methods", "detection"}


def log(msg):
    print(msg, flush=True)


def rel(path):
    """path relative to the repository root when inside it, else absolute."""
    r = os.path.relpath(path, ROOT)
    return path if r.startswith("..") else r


def run_cmd(argv, log_path=None):
    """Runs argv from the repository root; returns (rc, stdout, stderr, wall seconds)."""
    t0 = time.monotonic()
    p = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True)
    wall = time.monotonic() - t0
    if log_path:
        with open(log_path, "w") as f:
            f.write("$ " + " ".join(shlex.quote(a) for a in argv) + "\n")
            f.write(p.stdout)
            f.write(p.stderr)
            f.write(f"exit {p.returncode}, {wall:.3f} s wall\n")
    return p.returncode, p.stdout, p.stderr, wall


def methods_from_help(text):
    """Candidate method names in the --method option's description of `run --help`."""
    desc, inside = "", False
    for line in text.splitlines():
        s = line.strip()
        if re.match(r"^(-\w,)?--method\b", s):
            inside = True
            desc = re.sub(r"^(-\w,)?--method(\s+TEXT)?", "", s)
            continue
        if inside:
            if not s or s.startswith("-"):
                break
            desc += " " + s
    if not inside:
        return []
    desc = desc.split(":", 1)[1] if ":" in desc else desc
    desc = re.sub(r"\([^)]*\)", " ", desc)  # drop "(as published)" and the like
    candidates = []
    for word in re.findall(r"[A-Za-z][A-Za-z0-9_-]*", desc):
        w = word.lower()
        if w not in STOP_WORDS and w not in candidates:
            candidates.append(w)
    return candidates


def detect_methods(binary):
    """Method names offered by `run --help`, each checked by asking the CLI to accept it
    (usage errors exit 2 before any input is read)."""
    rc, out, err, _ = run_cmd([binary, "run", "--help"])
    if rc != 0:
        sys.exit(f"paper_tables: {binary} run --help failed (exit {rc}): {err.strip()}")
    methods = []
    for m in methods_from_help(out):
        rc, _, _, _ = run_cmd([binary, "run", os.path.join(ROOT, "out", "nonexistent.pcd"),
                               "-o", os.path.join(ROOT, "out", "nonexistent-run"),
                               "--method", m])
        if rc != 2:
            methods.append(m)
    return methods


def read_json(path):
    with open(path) as f:
        return json.load(f)


def machine_info(binary, backend_seen):
    cpu = "unknown"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    version = run_cmd([binary, "--version"])[1].strip()
    rc, head, _, _ = run_cmd(["git", "rev-parse", "--short", "HEAD"])
    commit = head.strip() if rc == 0 else "unknown"
    rc, dirty, _, _ = run_cmd(["git", "status", "--porcelain", "--untracked-files=no"])
    if rc == 0 and dirty.strip():
        commit += " (with uncommitted changes in the working tree)"
    return {"nproc": os.cpu_count(), "cpu": cpu, "version": version, "commit": commit,
            "backend": backend_seen, "omp": os.environ.get("OMP_NUM_THREADS", "unset"),
            "load": " ".join(f"{x:.2f}" for x in os.getloadavg()),
            "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")}


def fmt(v, digits=2, scale=1.0):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "n/a"
    return f"{v * scale:.{digits}f}"


def mean(values):
    values = [v for v in values if v is not None and not math.isnan(v)]
    return sum(values) / len(values) if values else None


def vmin(values):
    values = [v for v in values if v is not None and not math.isnan(v)]
    return min(values) if values else None


def vmax(values):
    values = [v for v in values if v is not None and not math.isnan(v)]
    return max(values) if values else None


def descriptor_medians(scan, rdir):
    """Median descriptor D (deg^2) over the truth groove points and over the other valid
    points, from annotated.pcd and the scan's labels; (None, None) if unreadable."""
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    try:
        from plot_detection import read_pcd
        _, _, ann = read_pcd(os.path.join(rdir, "annotated.pcd"), ["descriptor"])
        _, _, lab = read_pcd(scan[:-4] + ".labels.pcd", ["label", "valid"])
    except (OSError, KeyError, ValueError, SystemExit):
        return (None, None)
    finally:
        sys.path.pop(0)
    groove, other = [], []
    for d, t, v in zip(ann["descriptor"], lab["label"], lab["valid"]):
        if v and math.isfinite(d):
            (groove if t else other).append(d)

    def median(xs):
        xs.sort()
        return xs[len(xs) // 2] if xs else None
    return (median(groove), median(other))


def run_one(binary, backend, scan, truth, seed, out, shape, method):
    """Runs one method (None: the CLI's default) on one scan and evaluates it.
    Returns (method name as reported, entry)."""
    tag = method or "default"
    rdir = os.path.join(out, "runs", f"{shape}-{seed}", tag)
    # The run replaces rdir whole and refuses one holding files it does not write (the logs
    # below): each run starts from an empty directory.
    shutil.rmtree(rdir, ignore_errors=True)
    os.makedirs(rdir)
    cmd = [binary, "run", scan, "-o", rdir, "--backend", backend, "-q"]
    if method is not None:
        cmd += ["--method", method]
    rc, _, se, wall = run_cmd(cmd, os.path.join(rdir, "run.log"))
    rep_path = os.path.join(rdir, "report.json")
    report = read_json(rep_path) if os.path.exists(rep_path) else {}
    name = report.get("method") or method or "default"
    entry = {"seed": seed, "valid": truth["counts"]["valid"],
             "truth_groove": truth["counts"]["groove_valid"], "rc": rc, "wall_s": wall,
             "total_s": report.get("timings_ms", {}).get("total", float("nan")) / 1000.0,
             "dir": rdir, "metrics": None, "note": ""}
    det = report.get("detection", {})
    entry["threshold"] = (det.get("threshold_deg2"), det.get("threshold_mode"))
    if report.get("backend"):
        entry["backend"] = report["backend"] + (f" ({report['device']})" if report.get("device") else "")
    if os.path.exists(os.path.join(rdir, "annotated.pcd")):
        mpath = os.path.join(rdir, "metrics.json")
        erc, _, ese, _ = run_cmd([binary, "eval", "--truth", scan, "--result", rdir, "-o", mpath],
                                 os.path.join(rdir, "eval.log"))
        if erc == 0:
            entry["metrics"] = read_json(mpath)
        else:
            entry["note"] = f"eval failed (exit {erc}): {ese.strip()}"
        entry["descriptor"] = descriptor_medians(scan, rdir)
    elif rc == 4:
        entry["note"] = "no groove found (exit 4): lambda counted as 0"
    else:
        entry["note"] = f"run failed (exit {rc}): {se.strip()}"
    return name, entry


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one seed per shape (development)")
    ap.add_argument("--bin", default="build/groovetrace", help="the CLI (default build/groovetrace)")
    ap.add_argument("--out", default="out/paper_tables", help="scratch dir for scans and runs")
    ap.add_argument("--backend", default="cpu", choices=["cpu", "opencl", "auto"],
                    help="feature backend for every run (default cpu, the reference)")
    ap.add_argument("--results", help="results file (default docs/results.md; --quick: OUT/results.md)")
    ap.add_argument("--figures", help="picture dir (default docs/figures; --quick: OUT/figures)")
    ap.add_argument("--invocation", help=argparse.SUPPRESS)  # the wrapper's command line
    args = ap.parse_args()

    binary = os.path.abspath(os.path.join(ROOT, args.bin))
    out = os.path.abspath(os.path.join(ROOT, args.out))
    if not os.access(binary, os.X_OK):
        sys.exit(f"paper_tables: no executable {binary}; build it first (scripts/build.sh) or pass --bin")
    results = os.path.abspath(args.results or (os.path.join(out, "results.md") if args.quick
                                               else os.path.join(ROOT, "docs", "results.md")))
    figures = os.path.abspath(args.figures or (os.path.join(out, "figures") if args.quick
                                               else os.path.join(ROOT, "docs", "figures")))
    seeds = SEEDS[:1] if args.quick else SEEDS
    os.makedirs(out, exist_ok=True)
    os.makedirs(figures, exist_ok=True)
    os.makedirs(os.path.dirname(results), exist_ok=True)

    listed = detect_methods(binary)
    log(f"paper_tables: {rel(binary)}; methods offered by run --help: "
        f"{', '.join(listed) if listed else '(no --method option)'}; backend {args.backend}; "
        f"{len(seeds)} seed(s) per shape; scratch {rel(out)}")

    t_start = time.monotonic()
    rows = {}  # (shape, method) -> list of per-seed dicts
    default_method = None
    backend_seen = set()
    failures = []
    total = len(SHAPES) * len(seeds)
    k = 0
    for shape in SHAPES:
        w, h = FRAMES[shape]
        for seed in seeds:
            k += 1
            scan_dir = os.path.join(out, "scans")
            os.makedirs(scan_dir, exist_ok=True)
            scan = os.path.join(scan_dir, f"{shape}-{seed}.pcd")
            synth = [binary, "synth", "--shape", shape, "--seed", str(seed),
                     "--width", str(w), "--height", str(h), "-o", scan]
            rc, so, se, t_synth = run_cmd(synth, scan[:-4] + ".synth.log")
            if rc != 0:
                sys.exit(f"paper_tables: synth failed (exit {rc}): {se.strip()}")
            truth = read_json(scan[:-4] + ".truth.json")
            valid = truth["counts"]["valid"]
            # The default method first (no --method: whatever the CLI defaults to), then the
            # other listed methods.
            line = f"[{k:2d}/{total}] {shape:8s} seed {seed}: {valid} valid points"
            m = None
            ran = []
            while True:
                name, entry = run_one(binary, args.backend, scan, truth, seed, out, shape, m)
                if m is None:
                    if default_method is None:
                        default_method = name
                    elif name != default_method:
                        failures.append(f"{shape} seed {seed}: the default run used {name}, "
                                        f"earlier ones {default_method}")
                ran.append(name)
                if entry.get("backend"):
                    backend_seen.add(entry["backend"])
                if entry["note"]:
                    failures.append(f"{shape} seed {seed} {name}: {entry['note']}")
                rows.setdefault((shape, name), []).append(entry)
                line += f"; {name}: lambda {fmt(iou_of(entry))} %, {fmt(entry['total_s'])} s"
                rest = [x for x in listed if x not in ran]
                if not rest:
                    break
                m = rest[0]
            log(line)

    methods = [default_method] + [m for m in listed if m != default_method]
    methods = [m for m in methods if m is not None]

    # Pictures: seed 1 of each shape, one per method.
    fig_files = {}
    for shape in SHAPES:
        for m in methods:
            tag = "default" if m == default_method else m
            rdir = os.path.join(out, "runs", f"{shape}-{seeds[0]}", tag)
            if not os.path.exists(os.path.join(rdir, "annotated.pcd")):
                continue
            png = os.path.join(figures, f"{shape}-{m}.png")
            rc, _, se, _ = run_cmd(["/usr/bin/python3", os.path.join(ROOT, "scripts", "plot_detection.py"),
                                    "--truth", os.path.join(out, "scans", f"{shape}-{seeds[0]}.pcd"),
                                    "--result", rdir, "-o", png, "--scale", "2"])
            if rc != 0:
                failures.append(f"picture {shape} {m}: {se.strip()}")
            else:
                fig_files[(shape, m)] = png
    log(f"paper_tables: {len(fig_files)} picture(s) in {rel(figures)}")

    elapsed = time.monotonic() - t_start
    info = machine_info(binary, ", ".join(sorted(backend_seen)) or args.backend)
    summary = {"methods": methods, "default_method": default_method, "seeds": seeds,
               "frames": FRAMES, "machine": info, "elapsed_s": elapsed,
               "runs": {f"{s}/{m}": v for (s, m), v in rows.items()}}
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)

    text = render(args, info, methods, default_method, seeds, rows, fig_files, results,
                  failures, elapsed, binary, out)
    tmp = results + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, results)
    log(f"paper_tables: wrote {rel(results)} in {elapsed:.0f} s"
        + (f"; {len(failures)} problem(s):" if failures else ""))
    for msg in failures:
        log("  " + msg)
    return 1 if failures else 0


def label(m, default_method):
    return f"`{m}` (default)" if m == default_method else f"`{m}`"


def render(args, info, methods, default_method, seeds, rows, fig_files, results, failures,
           elapsed, binary, out):
    L = []
    add = L.append
    n = len(seeds)
    invocation = args.invocation or ("scripts/paper_tables.py " + " ".join(
        shlex.quote(a) for a in sys.argv[1:])).strip()
    add("# Results: the paper's tables on synthetic D415 scans")
    add("")
    add("Written by `scripts/paper_tables.sh` - do not edit by hand; re-run the script. "
        f"Generated {info['date']} by `{invocation}`.")
    add("")
    add(f"Methods (from `groovetrace run --help`): {', '.join(label(m, default_method) for m in methods)}. "
        "The default is what `groovetrace run` does without `--method`; `paper` is the paper's "
        "method as written (fixed descriptor threshold 4.5 deg^2, PCA slicing, geometric median). "
        f"{n} scan{'s' if n > 1 else ''} per shape (seed{'s' if n > 1 else ''} "
        f"{', '.join(map(str, seeds))}); the seed changes only the "
        "sensor noise (docs/synthetic-scans.md), not the workpiece or the pose. Ground truth is "
        "the renderer's per-point groove label; the paper's was hand-labelled on real scans, so "
        "the comparison is of magnitudes, not of identical data.")
    add("")
    if n < 5:
        add(f"**Quick run ({n} seed per shape): not the full tables.**")
        add("")

    # Table I.
    add("## Table I: points and runtime")
    add("")
    add("P_num: valid (finite) points of a scan, mean over the seeds. t_mean: mean end-to-end "
        "time of `groovetrace run` (report.json `total`: load, smoothing, normals, descriptor, "
        "detection, trajectory; like the paper's clock() from the raw cloud to the trajectory), "
        "in seconds; t_min: the fastest of the seeds, less disturbed by other jobs on the "
        "machine. (summary.json also has each run's wall-clock time, writing the outputs "
        "included.)")
    add("")
    head = "| Type | frame | P_num published | P_num ours | t_mean published (s) |"
    sep = "|---|---|---:|---:|---:|"
    for m in methods:
        head += f" t_mean {label(m, default_method)} (s) | t_min {label(m, default_method)} (s) |"
        sep += "---:|---:|"
    add(head)
    add(sep)
    for shape in SHAPES:
        p = PAPER[shape]
        w, h = FRAMES[shape]
        first = rows.get((shape, methods[0]), [])
        pts = mean([e["valid"] for e in first])
        r = f"| {p['name']} | {w}x{h} | {p['points']:,} | {fmt(pts, 0) if pts is None else f'{pts:,.0f}'} | {p['t_mean']:.2f} |"
        for m in methods:
            es = rows.get((shape, m), [])
            r += f" {fmt(mean([e['total_s'] for e in es]))} | {fmt(vmin([e['total_s'] for e in es]))} |"
        add(r)
    add("")
    add(f"Published: the paper's Intel i5 laptop with PCL, each workpiece run ten times. Ours: {info['cpu']}, "
        f"{info['nproc']} cores shared with other jobs (load average {info['load']} at the end "
        f"of the run), backend {info['backend']}; timings vary from run to run.")
    add("")

    # Table II.
    add("## Table II: groove detection accuracy (3-D overlapping rate lambda, %)")
    add("")
    add("lambda = n_overlap / (n_d + n_gt - n_overlap) over the valid points "
        "(`groovetrace eval`, `iou_percent`). The paper's lambda_1..lambda_5 are five tests "
        "of one real workpiece each; ours are seeds 1-5.")
    add("")
    cols = " | ".join(f"lambda_{i + 1}" for i in range(5))
    add(f"| Type | source | {cols} | lambda_mean |")
    add("|---|---|" + "---:|" * 6)
    for shape in SHAPES:
        p = PAPER[shape]
        add(f"| {p['name']} | published | " + " | ".join(f"{v:.2f}" for v in p["lambda"]) +
            f" | {p['lambda_mean']:.2f} |")
        for m in methods:
            es = rows.get((shape, m), [])
            vals = [iou_of(e) for e in es]
            cells = [fmt(v) for v in vals] + [""] * (5 - len(vals))
            add(f"| {p['name']} | ours, {label(m, default_method)} | " + " | ".join(cells) +
                f" | {fmt(mean(vals))} |")
    add("")
    add("Detection detail (means over the seeds): the descriptor threshold the run used "
        "(report.json), the median descriptor D over the truth groove points and over the other "
        "valid points (annotated.pcd), truth groove points (n_gt), points marked groove (n_d) "
        "and their share of the valid points, precision and recall.")
    add("")
    add("| Type | method | threshold (deg^2) | median D groove (deg^2) | median D elsewhere "
        "(deg^2) | n_gt | n_d | n_d / valid % | precision % | recall % |")
    add("|---|---|---|---:|---:|---:|---:|---:|---:|---:|")
    flooded = {}
    for shape in SHAPES:
        for m in methods:
            es = [e for e in rows.get((shape, m), []) if e["metrics"]]
            d = [e["metrics"]["detection"] for e in es]
            ts = [e.get("threshold", (None, None)) for e in es]
            tv = mean([t[0] for t in ts if t[0] is not None])
            modes = sorted({t[1] for t in ts if t[1]})
            tcell = "n/a" if tv is None else f"{tv:.3g} ({', '.join(modes)})"
            share = mean([100.0 * x["detected_points"] / x["valid_points"] for x in d
                          if x["valid_points"]])
            if share is not None and share > 50.0:
                flooded.setdefault(m, []).append((PAPER[shape]["name"], share))
            dm = [e.get("descriptor", (None, None)) for e in es]
            add(f"| {PAPER[shape]['name']} | {label(m, default_method)} | {tcell} | "
                f"{fmt(mean([x[0] for x in dm]), 1)} | {fmt(mean([x[1] for x in dm]), 1)} | "
                f"{fmt(mean([x['truth_points'] for x in d]), 0)} | "
                f"{fmt(mean([x['detected_points'] for x in d]), 0)} | {fmt(share, 1)} | "
                f"{fmt(mean([x['precision_percent'] for x in d]))} | "
                f"{fmt(mean([x['recall_percent'] for x in d]))} |")
    add("")
    for m, hits in flooded.items():
        add(f"Note: {label(m, default_method)} marks most of each scan as groove ("
            + ", ".join(f"{name} {v:.0f}%" for name, v in hits)
            + " of the valid points): its descriptor exceeds the threshold on nearly every "
            "point of these noisy scans, so lambda is about n_gt / n_d and the trajectory "
            "follows the middle of the whole part, not the seam.")
        add("")

    # Trajectory errors.
    add("## Trajectory errors")
    add("")
    add("Against the true root line (`groovetrace eval`; docs/synthetic-scans.md): per waypoint "
        "the distance to the nearest root point, split into lateral (across the seam, in the "
        "surface's tangent plane) and depth (along the surface normal; bias > 0 = above the "
        "root); tool axis = angle between the tool z axis and the groove's -bisector; travel "
        "axis = tool x against the root tangent; coverage = share of the in-view root line "
        "within 6 mm of the path. Means are the mean over the seeds of each scan's mean; maxima "
        "are the maximum over all seeds. The paper published no trajectory error (it judged "
        "the weld).")
    add("")
    add("| Type | method | waypoints | lateral mean (mm) | lateral max (mm) | depth mean (mm) | "
        "depth max (mm) | depth bias (mm) | tool axis mean (deg) | tool axis max (deg) | "
        "travel axis mean (deg) | coverage (%) |")
    add("|---|---|" + "---:|" * 10)
    for shape in SHAPES:
        for m in methods:
            es = [e for e in rows.get((shape, m), []) if e["metrics"]]
            t = [e["metrics"]["trajectory"] for e in es]

            def g(key):
                return [x.get(key) for x in t]
            add(f"| {PAPER[shape]['name']} | {label(m, default_method)} | "
                f"{fmt(mean(g('waypoints')), 0)} | "
                f"{fmt(mean(g('lateral_mean_m')), 2, 1e3)} | {fmt(vmax(g('lateral_max_m')), 2, 1e3)} | "
                f"{fmt(mean(g('depth_mean_m')), 2, 1e3)} | {fmt(vmax(g('depth_max_m')), 2, 1e3)} | "
                f"{fmt(mean(g('depth_bias_m')), 2, 1e3)} | "
                f"{fmt(mean(g('tool_axis_mean_deg')))} | {fmt(vmax(g('tool_axis_max_deg')))} | "
                f"{fmt(mean(g('travel_axis_mean_deg')))} | {fmt(mean(g('coverage_percent')), 1)} |")
    add("")

    # Pictures.
    add("## Pictures")
    add("")
    add(f"Seed {seeds[0]} of each shape, cropped to the truth groove plus 60 pixels, enlarged 2x "
        "(`scripts/plot_detection.py`). Grey: depth (near = light); dark blue: no return; green: "
        "truth groove only; red: detected only; yellow: both; cyan: the true root line in view; "
        "magenta: the waypoints and the path through them.")
    add("")
    for shape in SHAPES:
        for m in methods:
            png = fig_files.get((shape, m))
            if png:
                add(f"**{PAPER[shape]['name']}, {label(m, default_method)}**")
                add("")
                add(f"![{shape}, {m}]({os.path.relpath(png, os.path.dirname(results))})")
                add("")

    # How.
    add("## How these numbers were made")
    add("")
    def pts_diff(shape):
        es = rows.get((shape, methods[0]), [])
        v = mean([e["valid"] for e in es])
        return "n/a" if v is None else f"{100.0 * (v / PAPER[shape]['points'] - 1.0):+.2f}%"
    add("Scans: `groovetrace synth` with its defaults (camera 0.40 m from the seam's top "
        "centre, looking straight down, no roll; 10 mm wide 60 deg V, 0.5 mm root gap; every "
        "D415 sensor effect on; 1 mm depth unit). Frames: 640x480, a D415 depth mode, for the "
        "two plates (the paper's 265,800 and 266,497 points look like 640x480 frames with about "
        "87% returns; ours have about 89%): valid points "
        f"{pts_diff('straight')} (straight) and {pts_diff('curve')} (curve) against the paper. "
        "Box and cylinder: the paper's counts are about half a frame, so they get custom 4:3 "
        "frames of 434x326 and 424x318 pixels with the same field of view (fx = 0.5 W / "
        "tan(32.5 deg): coarser pixels and, by the D415 formula, proportionally more depth "
        f"noise than at 640x480), sized so the valid counts land on the paper's: "
        f"{pts_diff('box')} (box), {pts_diff('cylinder')} (cylinder).")
    add("")
    add("Commands, from the repository root (`SHAPE`, `W`x`H` as in Table I, `SEED` 1-5, "
        f"`GT={rel(binary)}`, `OUT={rel(out)}`):")
    add("")
    add("```")
    add(invocation)
    add("# per scan:")
    add("$GT synth --shape SHAPE --seed SEED --width W --height H -o $OUT/scans/SHAPE-SEED.pcd")
    add(f"$GT run $OUT/scans/SHAPE-SEED.pcd -o $OUT/runs/SHAPE-SEED/default --backend {args.backend} -q")
    for m in methods:
        if m != default_method:
            add(f"$GT run $OUT/scans/SHAPE-SEED.pcd -o $OUT/runs/SHAPE-SEED/{m} "
                f"--backend {args.backend} -q --method {m}")
    add("$GT eval --truth $OUT/scans/SHAPE-SEED.pcd --result $OUT/runs/SHAPE-SEED/RUN "
        "-o $OUT/runs/SHAPE-SEED/RUN/metrics.json")
    add("```")
    add("")
    add("Each run directory keeps the CLI's outputs and a `run.log`; "
        f"`{rel(out)}/summary.json` has every per-scan number. Scans, runs and metrics are "
        "deterministic (fixed seeds; the renderer and the CPU backend give the same bytes on "
        "every run), so a re-run with `--backend cpu` reproduces every number here except the "
        "timings, the date, the load and the script time.")
    add("")
    add("| | |")
    add("|---|---|")
    add(f"| date | {info['date']} |")
    add(f"| machine | {info['cpu']}, nproc {info['nproc']}, OMP_NUM_THREADS {info['omp']} |")
    add(f"| backend | {info['backend']}; `--backend {args.backend}` |")
    add(f"| groovetrace | {info['version']}, commit {info['commit']} |")
    add(f"| script time | {elapsed:.0f} s for {len(SHAPES) * n} scans |")
    add("")
    if failures:
        add("## Problems in this run")
        add("")
        for msg in failures:
            add(f"- {msg}")
        add("")
    return "\n".join(L)


def iou_of(e):
    if e["metrics"]:
        v = e["metrics"]["detection"]["iou_percent"]
        return float("nan") if v is None else v
    return 0.0 if e["rc"] == 4 else float("nan")


if __name__ == "__main__":
    sys.exit(main())

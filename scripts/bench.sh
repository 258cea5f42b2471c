#!/usr/bin/env bash
# Runs the benchmark programs (Google Benchmark, JSON) and the CLI end to end, and writes
# docs/benchmarks.md: points per second, the OpenCL backend's ratios to the CPU backend and
# the PCL peers, the floating-point work per point against the machine's peak, and the
# scaling of unorganized clouds.
#   scripts/bench.sh [BUILD_DIR]      (default: build, configured with -DBUILD_BENCHMARKS=ON:
#                                     scripts/build.sh -DBUILD_BENCHMARKS=ON)
# Other compiles or runs on the machine disturb the timings: run it on a quiet machine (the
# load average before and after goes into the report).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
OUT="$BUILD/bench-results"
mkdir -p "$OUT"
export GT_BENCH_DIR="$OUT/files"
# A partial rerun keeps the load figures of the full run it completes.
[ "${BENCH_REPORT_ONLY:-0}" = 1 ] || [ -n "${BENCH_ONLY:-}" ] || uptime >"$OUT/load-before.txt"

run() {  # program json-name [extra benchmark flags]
  local prog=$1 name=$2
  shift 2
  echo "bench: $prog $*" >&2
  "$BUILD/benches/$prog" --benchmark_out="$OUT/$name.json" --benchmark_out_format=json "$@" >&2
}

# BENCH_ONLY="normals smooth ..." reruns some programs; BENCH_REPORT_ONLY=1 only rewrites the
# report from the results already in $OUT.
only=${BENCH_ONLY:-walk normals smooth descriptor crease pipeline scaling cli batch}
[ "${BENCH_REPORT_ONLY:-0}" = 1 ] && only=""
# The organized walk's candidate counts (for the flop counts; not a timing).
case " $only " in *" walk "*) run bench_normals walk --benchmark_filter=OrganizedWalk ;; esac
for prog in normals smooth descriptor crease pipeline; do
  case " $only " in
    *" $prog "*) run "bench_$prog" "$prog" --benchmark_filter='^BM_(OpenCl|Cpu|Pcl|Run)' ;;
  esac
done
case " $only " in *" scaling "*)
  # Each scaling case in its own process, so that its memory use is its own.
  i=0
  for name in $("$BUILD/benches/bench_scaling" --benchmark_list_tests); do
    # Three repetitions, the median reported: a single 16M-point iteration is one sample.
    run bench_scaling "scaling-$i" --benchmark_filter="^${name}\$" --benchmark_repetitions=3 \
      --benchmark_report_aggregates_only=true
    i=$((i + 1))
  done ;;
esac

# The CLI end to end, process start to exit, on the 1280x720 frame bench_pipeline wrote.
if [ -x "$BUILD/groovetrace" ] && [[ " $only " == *" cli "* ]]; then
  /usr/bin/python3 - "$BUILD/groovetrace" "$GT_BENCH_DIR/frame1280.pcd" "$OUT" <<'EOF'
import json, subprocess, sys, time
cli, scan, out = sys.argv[1:4]
result = {}
# The paper method (the issue's end-to-end target), then the default run (--method robust).
for method, backend in (("paper", "opencl"), ("paper", "cpu"), ("robust", "opencl"),
                        ("robust", "cpu")):
    key = backend if method == "paper" else f"{method}-{backend}"
    cmd = [cli, "run", scan, "-o", f"{out}/cli-{key}", "--method", method, "--backend",
           backend]
    subprocess.run(cmd, check=True, capture_output=True)  # warm-up: PoCL's cache, file cache
    times, written = [], []
    for _ in range(5 if backend == "opencl" else 2):
        t0 = time.perf_counter()
        run = subprocess.run(cmd, check=True, capture_output=True, text=True)
        times.append(time.perf_counter() - t0)
        # Load to written outputs, inside the process: report.json's total (from the start of
        # `run` to the start of writing) plus the write stage the CLI prints.
        total = json.load(open(f"{out}/cli-{key}/report.json"))["timings_ms"]["total"]
        write = [float(line.split()[2]) for line in run.stdout.splitlines()
                 if line.startswith("groovetrace: write")]
        written.append((total + write[0]) / 1000 if write else None)
    report = json.load(open(f"{out}/cli-{key}/report.json"))
    result[key] = {"times_s": times, "written_s": written, "device": report.get("device", ""),
                   "method": method, "backend": backend,
                   "timings_ms": report.get("timings_ms", report.get("timings", {}))}
json.dump(result, open(f"{out}/cli.json", "w"), indent=1)
EOF
fi
# The batch issue's measure: batch against one run process per scan (scripts/bench_batch.py).
case " $only " in *" batch "*) /usr/bin/python3 scripts/bench_batch.py "$BUILD" "$OUT" ;; esac
[ "${BENCH_REPORT_ONLY:-0}" = 1 ] || [ -n "${BENCH_ONLY:-}" ] || uptime >"$OUT/load-after.txt"

/usr/bin/python3 - "$OUT" >docs/benchmarks.md <<'EOF'
import glob, json, os, platform, statistics, subprocess, sys, time

out = sys.argv[1]
runs = {}
context = {}
for path in sorted(glob.glob(f"{out}/*.json")):
    if path.endswith("cli.json") or path.endswith("batch.json"):
        continue
    data = json.load(open(path))
    context = data.get("context", context)
    for b in data["benchmarks"]:
        if b.get("error_occurred"):
            continue
        # Repeated runs report aggregates only: the median stands for the run.
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        runs[b["run_name"].split("/min_time")[0].split("/iterations")[0]] = b

def ms(name):
    b = runs.get(name)
    if b is None:
        return None
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
    return b["real_time"] * scale

def fmt(v, digits=0):
    return "n/a" if v is None else f"{v:,.{digits}f}"

def ratio(a, b):
    return None if a is None or b is None or a == 0 else b / a

def lscpu(key):
    try:
        for line in subprocess.run(["lscpu"], capture_output=True, text=True).stdout.splitlines():
            if line.startswith(key):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "?"

cli = json.load(open(f"{out}/cli.json")) if os.path.exists(f"{out}/cli.json") else {}
device = cli.get("opencl", {}).get("device", "the default OpenCL device")
load_before = open(f"{out}/load-before.txt").read().strip()
load_after = open(f"{out}/load-after.txt").read().strip()

# Peak: 2 cores x 2.6 GHz x 64 single-precision flops per cycle (two 512-bit FMA pipes, Zen 5).
cores = os.cpu_count() or 2
ghz = 2.6
peak = cores * ghz * 64

p = print
p("# Benchmarks")
p()
started = load_before.split()[0] if load_before else "?"
p(f"Written by `scripts/bench.sh` on {time.strftime('%Y-%m-%d')}, from the run started at "
  f"{started}. Machine: {lscpu('Model name')}, {cores} cores, {lscpu('L3 cache')} L3; OpenCL "
  f"device: {device}. Load average before: "
  f"`{load_before.split('load average:')[-1].strip()}`, after: "
  f"`{load_after.split('load average:')[-1].strip()}`: other work on the machine slows every "
  "column, not all by the same factor, so ratios from a loaded machine are rough.")
p()
p("Input: the rendered V-groove frame of `benches/bench_common.hpp` (1280x720, D415-like "
  "depth noise, 0.4 m, 12 deg tilt), r = 3 mm. Times are wall clock (Google Benchmark real "
  "time), each stage from host arrays to host arrays (upload, search set-up, kernels, "
  "download). PCL peers use 2 threads. Normals and descriptor run on the frame after "
  "smoothing, as in the pipeline; OpenCL kernels had run once before timing (PoCL compiles "
  "a kernel's work-group function on first launch and keeps it in its disk cache).")
p()

p("## Stages, 1280x720")
p()
p("| stage | implementation | time (ms) | points/s | OpenCL is faster by | target |")
p("|---|---|---:|---:|---:|---|")
W = 1280
rows = [
    ("smoothing (MLS, quadric)", "BM_OpenClSmooth", [
        ("OpenCL", "BM_OpenClSmooth", ""),
        ("OpenCL, plane only (order 1)", "BM_OpenClSmoothPlane", ""),
        ("OpenCL, same points unorganized", "BM_OpenClSmoothUnorganized", ""),
        ("CPU backend (OpenMP)", "BM_CpuSmooth", ""),
        ("PCL MovingLeastSquares (kd-tree, order 2)", "BM_PclMls", ">= 30x")]),
    ("normals", "BM_OpenClNormals", [
        ("OpenCL", "BM_OpenClNormals", ""),
        ("OpenCL, same points unorganized", "BM_OpenClNormalsUnorganized", ""),
        ("CPU backend (OpenMP)", "BM_CpuNormals", ""),
        ("PCL NormalEstimationOMP, kd-tree", "BM_PclNormalsKdTree", ">= 25x"),
        ("PCL NormalEstimationOMP, OrganizedNeighbor", "BM_PclNormalsOrganized", ">= 4x")]),
    ("descriptor (GFH)", "BM_OpenClDescriptor", [
        ("OpenCL", "BM_OpenClDescriptor", ""),
        ("OpenCL, same points unorganized", "BM_OpenClDescriptorUnorganized", ""),
        ("OpenCL, fused normals + u_b + descriptor", "BM_OpenClFeatures", ""),
        ("CPU backend (OpenMP)", "BM_CpuDescriptor", ""),
        ("same GFH over PCL kd-tree radiusSearch", "BM_PclGfhKdTree", ">= 20x")]),
    ("crease measure (robust method; its 1 mm voxels, r = 10 mm)", "BM_OpenClCrease", [
        ("OpenCL", "BM_OpenClCrease", ""),
        ("CPU backend (OpenMP)", "BM_CpuCrease", ""),
        ("same measure over PCL kd-tree radiusSearch", "BM_PclCreaseKdTree", "")]),
]
targets = []
for stage, base, impls in rows:
    base_ms = ms(f"{base}/{W}")
    first = True
    for label, name, target in impls:
        t = ms(f"{name}/{W}")
        b = runs.get(f"{name}/{W}", {})
        r = ratio(base_ms, t)
        p(f"| {stage if first else ''} | {label} | {fmt(t, 1)} | "
          f"{fmt(b.get('points_per_s'), 0)} | {'' if name == base else fmt(r, 1) + 'x'} | "
          f"{target} |")
        first = False
        if target:
            targets.append((f"{stage}: OpenCL vs {label}", float(target.strip(">= x")), r))
p()

p("## End to end")
p()
p("`groovetrace run --method paper` as a library call (`benches/bench_pipeline.cpp`): read the "
  "PCD, smooth, "
  "normals, descriptor, detection, trajectory, render and write the five output files. The "
  "PCL column builds the same pipeline from PCL's loadPCDFile, MovingLeastSquares, "
  "NormalEstimationOMP and the GFH over its kd-tree, then groovetrace's detection, "
  "trajectory and outputs (PCL has none).")
p()
p("| frame | OpenCL (ms) | CPU backend (ms) | PCL pipeline (ms) | OpenCL vs PCL | OpenCL vs CPU |")
p("|---|---:|---:|---:|---:|---:|")
for w in (640, 1280):
    o, c, pc = ms(f"BM_RunOpenCl/{w}"), ms(f"BM_RunCpu/{w}"), ms(f"BM_RunPcl/{w}")
    p(f"| {w}x{480 if w == 640 else 720} | {fmt(o)} | {fmt(c)} | {fmt(pc)} | "
      f"{fmt(ratio(o, pc), 1)}x | {fmt(ratio(o, c), 1)}x |")
    if w == 1280:
        targets.append(("end to end vs the PCL pipeline", 30.0, ratio(o, pc)))
p()
if cli:
    p("The CLI on the 1280x720 frame (`groovetrace run FRAME.pcd -o DIR --method M --backend "
      "B`, after one warm-up run). *Load to written* is the issue's measure: from the start of "
      "`run` (before the scan is read and the OpenCL device is set up) to the outputs written, "
      "in the process (report.json's total plus the write stage). *Process* adds the process's "
      "start (loading PCL, VTK and the OpenCL driver's libraries) and exit. `--method robust` "
      "is the default run; its per-point stage (the crease measure) is the backend's, its seam "
      "fits run on the CPU either way:")
    p()
    p("| method | backend | load to written (s) | median | process (s) | median | stages (ms, from report.json) |")
    p("|---|---|---|---:|---|---:|---|")
    for key, r in cli.items():
        stages = ", ".join(f"{k} {v:.0f}" for k, v in r["timings_ms"].items()) \
            if isinstance(r["timings_ms"], dict) else ""
        w = [t for t in r.get("written_s", []) if t is not None]
        p(f"| {r.get('method', 'paper')} | {r.get('backend', key)} | "
          f"{', '.join(f'{t:.2f}' for t in w)} | "
          f"{statistics.median(w) if w else float('nan'):.2f} | "
          f"{', '.join(f'{t:.2f}' for t in r['times_s'])} | "
          f"{statistics.median(r['times_s']):.2f} | {stages} |")
    p()
    w = [t for t in cli.get("opencl", {}).get("written_s", []) if t is not None]
    targets.append(("CLI end to end, --method paper, 1280x720, load to written outputs (s, at "
                    "most)", 0.6, statistics.median(w) if w else None))
    if "opencl" in cli:
        targets.append(("the same, process start to exit (s, at most)", 0.6,
                        statistics.median(cli["opencl"]["times_s"])))

p("## Targets")
p()
p("| target | goal | measured | |")
p("|---|---:|---:|---|")
for name, goal, got in targets:
    if name.startswith("CLI") or name.startswith("the same, process"):
        ok = got is not None and got <= goal
        p(f"| {name} | <= {goal:g} s | {fmt(got, 2)} s | {'met' if ok else 'NOT met'} |")
    else:
        ok = got is not None and got >= goal
        p(f"| {name} | >= {goal:g}x | {fmt(got, 1)}x | {'met' if ok else 'NOT met'} |")
p()

p("## Floating-point work")
p()
walk = runs.get(f"BM_OrganizedWalk/{W}", {})
raw_walk = runs.get(f"BM_OrganizedWalkRaw/{W}", {})
cand = walk.get("candidates_per_point")
cand_raw = raw_walk.get("candidates_per_point", cand)
nb = walk.get("neighbours_per_point")
active = walk.get("active_fraction", 1.0)
active_raw = raw_walk.get("active_fraction", active)
p(f"Counted from the kernel source (`kernels/*.cl`): additions, subtractions, "
  "multiplications, square roots, an FMA as 2; comparisons and selects not counted. The "
  "arc cosine and the Gaussian weight are the kernels' own polynomials (22 and 15 flops; "
  "PoCL's built-in acos runs lane by lane through scalar code). The descriptor and smoothing "
  "skip all but the distance test (8 flops) at window positions where no lane has a "
  f"neighbour: they keep {fmt(100 * active if active else None, 0)}% of the positions on the "
  f"smoothed frame, {fmt(100 * active_raw if active_raw else None, 0)}% on the raw one. "
  f"The organized walk tests {fmt(cand, 0)} candidates per point on the smoothed frame "
  f"({fmt(cand_raw, 0)} on the raw one, whose points sit exactly on their pixel rays), "
  f"{fmt(nb, 0)} of them within r (`BM_OrganizedWalk` replays the kernels' window walk). "
  f"Peak: {cores} cores x {ghz} GHz x 64 flops/cycle (two 512-bit FMA pipes) = {peak:.0f} "
  "GFLOP/s single precision. Achieved = flops per point x points/s of the whole stage "
  "(upload, search set-up and download included), a lower bound for the kernels alone.")
p()
p("| kernel | flops per candidate | candidates per point | kept | per-point finish | flops per point | GFLOP/s | of peak |")
p("|---|---:|---:|---:|---:|---:|---:|---:|")
kernels = [
    # name, flops per candidate, candidates per point, kept fraction, finish flops, benchmark;
    # smoothing walks its candidates twice (8 flops of distance test in each pass).
    ("mls (order 2: plane pass 46 + quadric pass 85)", 46 + 85, cand_raw, active_raw, 500,
     "BM_OpenClSmooth", 16),
    ("normals (covariance; eigen-solver per point)", 24, cand, 1.0, 300, "BM_OpenClNormals", 8),
    ("descriptor (+ global_angles per point)", 45, cand, active, 50, "BM_OpenClDescriptor", 8),
    # crease: plane walk 28 (distance 8, covariance 16, own ball 4), then 4 bracketing walks
    # of 22 (distance 8, height 5, 9 threshold counts); the finish is the eigen-solver and the
    # brackets' bookkeeping. Its candidates come from the grid walk's counter.
    ("crease (1 plane walk + 4 bracketing walks, grid search)", 28 + 4 * 22,
     runs.get(f"BM_OpenClCrease/{W}", {}).get("candidates_per_point"), 1.0, 420,
     "BM_OpenClCrease", 0),
]
for name, per, c, kept, finish, bench, test in kernels:
    b = runs.get(f"{bench}/{W}", {})
    if c is None or kept is None or "points_per_s" not in b:
        p(f"| {name} | {per} | n/a | n/a | {finish} | n/a | n/a | n/a |")
        continue
    fpp = c * (test + kept * (per - test)) + finish
    gf = fpp * b["points_per_s"] / 1e9
    p(f"| {name} | {per} | {c:.0f} | {100 * kept:.0f}% | {finish} | {fpp:,.0f} | {gf:.1f} | "
      f"{100 * gf / peak:.1f}% |")
p()

p("## Unorganized clouds: scaling")
p()
p("A wavy plate at the frame's density (6 points per mm^2), r = 3 mm, OpenCL grid search. "
  "Scan order = as a scanner writes points; shuffled = random order (the worst case for "
  "memory locality). bytes/point = the most OpenCL buffer memory held at once during the call "
  "(counted by the backend; host memory under PoCL) plus the result arrays, per point: the "
  "memory beyond the input. Each case runs in its own process. On a CPU device the backend "
  "keeps the memory of released buffers for the next call (up to 2 GiB), so repeated calls "
  "on large clouds do not page-fault fresh memory each time.")
p()
p("| stage | order | 1M: ns/point | 4M: ns/point | 16M: ns/point | spread | bytes/point (1M, 4M, 16M) |")
p("|---|---|---:|---:|---:|---:|---|")
for stage, key in (("normals + u_b + descriptor", "Features"), ("smoothing", "Smooth")):
    for order in ("Scan", "Shuffled"):
        ns, mem = [], []
        for n in (1 << 20, 1 << 22, 1 << 24):
            b = runs.get(f"BM_OpenClScaling{key}{order}/{n}")
            t = ms(f"BM_OpenClScaling{key}{order}/{n}")
            ns.append(None if t is None else t * 1e6 / n)
            mem.append(None if b is None else b.get("bytes_per_point"))
        ok = [v for v in ns if v is not None]
        spread = f"{100 * (max(ok) / min(ok) - 1):.0f}%" if len(ok) == 3 else "n/a"
        p(f"| {stage} | {order.lower()} | " + " | ".join(fmt(v, 0) for v in ns) +
          f" | {spread} | " + ", ".join(fmt(v, 0) for v in mem) + " |")
p()
p("Targets: time per point within 15% across the three sizes; memory under 100 bytes per "
  "point beyond the input.")
p()

p("## 640x480")
p()
p("| benchmark | time (ms) | points/s |")
p("|---|---:|---:|")
for name in sorted(runs):
    if name.endswith("/640") and not name.startswith("BM_OrganizedWalk"):
        p(f"| {name[:-4]} | {fmt(ms(name), 1)} | {fmt(runs[name].get('points_per_s'), 0)} |")

if os.path.exists(f"{out}/batch.json"):
    bj = json.load(open(f"{out}/batch.json"))
    p()
    p("## Batch")
    p()
    p(f"`groovetrace batch` (default workers) against `xargs -P 2 -n 1 groovetrace run` (one "
      f"process per scan, two at a time) on the same {bj['scans']} synthetic scans "
      "(scripts/bench_batch.py: five shapes, default method and backend). Targets: batch at "
      "least 1.5x the loop's frames per second, and at least 5 frames/s at 640x480.")
    p()
    p("| resolution | batch: frames/s | xargs -P 2: frames/s | ratio |")
    p("|---|---:|---:|---:|")
    for res in ("640x480", "1280x720"):
        r = bj.get(res)
        if r:
            p(f"| {res} | {r['batch_fps']:.2f} | {r['xargs_fps']:.2f} | "
              f"{r['batch_fps'] / r['xargs_fps']:.2f}x |")
EOF
echo "bench: wrote docs/benchmarks.md" >&2

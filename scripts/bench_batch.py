#!/usr/bin/python3
"""The batch issue's measure: `groovetrace batch` against what a user does without it, one
`groovetrace run` process per scan run two at a time (`xargs -P 2 -n 1`), on the same 20
synthetic scans at 640x480 and at 1280x720. Frames per second = scans / wall seconds. Writes
OUT/batch.json for scripts/bench.sh's report.

    /usr/bin/python3 scripts/bench_batch.py BUILD_DIR OUT_DIR
"""
import json
import os
import shutil
import subprocess
import sys
import time

SHAPES = ["straight", "curve", "lshape", "box", "cylinder"]
SCANS = 20


def render(cli, folder, resolution):
    os.makedirs(folder, exist_ok=True)
    for k in range(SCANS):
        path = os.path.join(folder, f"{SHAPES[k % 5]}-{k}.pcd")
        if not os.path.exists(path):
            subprocess.run([cli, "synth", "--shape", SHAPES[k % 5], "--seed", str(k + 1),
                            "--resolution", resolution, "-o", path], check=True,
                           capture_output=True)
    return sorted(os.path.join(folder, f) for f in os.listdir(folder)
                  if f.endswith(".pcd") and not f.endswith(".labels.pcd"))


def timed(cmd, **kw):
    t0 = time.perf_counter()
    subprocess.run(cmd, check=False, capture_output=True, **kw)
    return time.perf_counter() - t0


def xargs_seconds(cli, scans, out):
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    script = f'exec "{cli}" run "$0" -o "{out}/$(basename "$0" .pcd)" -q'
    return timed(["xargs", "-P", "2", "-n", "1", "sh", "-c", script],
                 input="\n".join(scans).encode())


def batch_seconds(cli, folder, out):
    shutil.rmtree(out, ignore_errors=True)
    return timed([cli, "batch", folder, "-o", out, "--progress", "none"])


def main():
    build, out = sys.argv[1:3]
    cli = os.path.join(build, "groovetrace")
    result = {"scans": SCANS, "workers": 2}
    for res in ("640x480", "1280x720"):
        folder = os.path.join(out, "batch-scans", res)
        scans = render(cli, folder, res)
        subprocess.run([cli, "run", scans[0], "-o", os.path.join(out, "batch-warmup"), "-q"],
                       check=True, capture_output=True)  # PoCL's kernel cache, the file cache
        x = xargs_seconds(cli, scans, os.path.join(out, "batch-xargs"))
        b = batch_seconds(cli, folder, os.path.join(out, "batch-out"))
        result[res] = {"xargs_s": x, "batch_s": b, "xargs_fps": len(scans) / x,
                       "batch_fps": len(scans) / b, "scans": len(scans)}
        print(f"bench_batch: {res}: batch {len(scans) / b:.2f} frames/s, xargs -P 2 "
              f"{len(scans) / x:.2f} frames/s", file=sys.stderr)
    with open(os.path.join(out, "batch.json"), "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Compares two output trees of scripts/robust_sweep.sh file by file, for a change that must not
change results (a refactor): every file byte for byte, except what legitimately differs between
two runs: report.json's timings and input path, metrics.json's paths and runtime. Exits 1 and
lists the files that differ, are missing or are extra.

    scripts/robust_sweep.sh --bin OLD/groovetrace --out out/sweep-old --results /tmp/old.md
    scripts/robust_sweep.sh --bin NEW/groovetrace --out out/sweep-new --results /tmp/new.md
    /usr/bin/python3 scripts/compare_sweeps.py out/sweep-old out/sweep-new [--ignore FILE]...

--ignore NAME: files of that name present only in the new tree are not counted as extra (a new
output); --ignore-key NAME: a top-level JSON key left out of trajectory*.json (a changed text).
"""
import argparse
import json
import os
import sys


def load(path):
    with open(path, "rb") as f:
        return f.read()


def normalized(name, path, ignore_keys):
    if name == "report.json":
        j = json.loads(load(path))
        j.pop("timings_ms", None)
        j.pop("input", None)
        return j
    if name == "metrics.json":
        j = json.loads(load(path))
        for k in ("result", "truth", "runtime"):
            j.pop(k, None)
        return j
    if name.startswith("trajectory") and name.endswith(".json") and ignore_keys:
        j = json.loads(load(path))
        for k in ignore_keys:
            j.pop(k, None)
        return j
    return load(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--ignore", action="append", default=[])
    ap.add_argument("--ignore-key", action="append", default=[])
    a = ap.parse_args()
    compared, bad = 0, []
    for root, _, files in os.walk(a.old):
        for name in files:
            if name == "summary.json":
                continue  # the sweep's own timings
            old = os.path.join(root, name)
            new = os.path.join(a.new, os.path.relpath(old, a.old))
            compared += 1
            if not os.path.exists(new):
                bad.append("missing " + new)
            elif normalized(name, old, a.ignore_key) != normalized(name, new, a.ignore_key):
                bad.append("differs " + os.path.relpath(old, a.old))
    for root, _, files in os.walk(a.new):
        for name in files:
            new = os.path.join(root, name)
            if name not in a.ignore and not os.path.exists(
                    os.path.join(a.old, os.path.relpath(new, a.new))):
                bad.append("extra " + new)
    for line in bad:
        print(line)
    print(f"{compared} files compared, {len(bad)} differ")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

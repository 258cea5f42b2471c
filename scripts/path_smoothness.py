#!/usr/bin/python3
"""How smooth the robust method's torch paths are (issue 12), from a sweep's output tree.

    scripts/path_smoothness.py OUT [--before BASE] [--markdown FILE]

OUT (and BASE) are --out directories of scripts/robust_sweep.sh; every run under OUT/robust/*
is read (trajectory.csv, trajectory_1.csv, ...). Per trajectory:

- straight seams (shapes straight, multi, box, pipe-long): the waypoints' deviation from their
  least-squares line, peak to peak (mm), in depth (along the trajectory's mean tool z: the
  plate normal, up and down) and across (normal to the line and to tool z). "all" over every
  waypoint, "inner" without the first and last 10 mm of arc length (the ends are decided by
  tracking and trimming, the issue is about the seam's run);
- every trajectory: the largest rotation between consecutive waypoints divided by their
  distance (deg/mm), its tilt part (the angle between the two tool z axes), the arc length where
  it happens (m, the pair's midpoint) and what is there: "end" within 10 mm of either end,
  "corner" where the path's heading turns by more than 30 deg between the chords 10 mm before
  and after, else "run".

With --before, every number is printed as BEFORE -> AFTER, for the runs both trees have, and
a last table compares each run's accuracy (metrics.json of `groovetrace eval`: IoU, lateral and
depth mean, tool-axis mean) and flags a run that lost more than 0.5 IoU points, 0.05 mm of
lateral or depth mean error or 0.5 deg of tool-axis error (issue 12's rule).
Standard library only; run with Debian's /usr/bin/python3.
"""

import argparse
import glob
import json
import math
import os
import sys

STRAIGHT = ("straight", "multi", "box", "pipe-long")
END_M = 0.010  # "inner" leaves out this much at each end; "end" lies within it
CORNER_CHORD_M = 0.010
CORNER_DEG = 30.0


def read_csv(path):
    with open(path) as f:
        lines = f.read().splitlines()
    head = lines[0].split(",")
    ix, iq = head.index("x_m"), head.index("qx")
    pos, quat = [], []
    for line in lines[1:]:
        if not line:
            continue
        v = [float(x) for x in line.split(",")]
        pos.append(tuple(v[ix:ix + 3]))
        quat.append(tuple(v[iq:iq + 4]))
    return pos, quat


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def unit(a):
    n = math.sqrt(dot(a, a))
    return tuple(x / n for x in a) if n > 0 else a


def qrot(q, v):
    """v rotated by the unit quaternion q = (x, y, z, w)."""
    u, w = q[:3], q[3]
    t = tuple(2 * c for c in cross(u, v))
    c = cross(u, t)
    return tuple(v[k] + w * t[k] + c[k] for k in range(3))


def qangle_deg(a, b):
    """The angle (deg) of the rotation from a to b."""
    d = min(1.0, abs(dot(a, b)))
    return math.degrees(2 * math.acos(d))


def principal_axis(pts):
    """Centroid and first principal axis (power iteration on the 3x3 covariance)."""
    n = len(pts)
    c = tuple(sum(p[k] for p in pts) / n for k in range(3))
    cov = [[sum((p[i] - c[i]) * (p[j] - c[j]) for p in pts) for j in range(3)] for i in range(3)]
    v = unit(sub(pts[-1], pts[0])) if pts[-1] != pts[0] else (1.0, 0.0, 0.0)
    for _ in range(100):
        v = unit(tuple(sum(cov[i][j] * v[j] for j in range(3)) for i in range(3)))
    return c, v


def arc_lengths(pos):
    s = [0.0]
    for k in range(1, len(pos)):
        s.append(s[-1] + math.dist(pos[k], pos[k - 1]))
    return s


def line_deviation(pos, quat):
    """Peak to peak (mm) of the deviation from the fitted line: depth and across over every
    waypoint, then the same over the inner ones."""
    c, d = principal_axis(pos)
    z = unit(tuple(sum(qrot(q, (0.0, 0.0, 1.0))[k] for q in quat) for k in range(3)))
    z = unit(sub(z, tuple(dot(z, d) * x for x in d)))
    a = cross(d, z)
    s = arc_lengths(pos)
    out = []
    for keep in (lambda x: True, lambda x: END_M <= x <= s[-1] - END_M):
        dz = [dot(sub(p, c), z) for p, x in zip(pos, s) if keep(x)]
        da = [dot(sub(p, c), a) for p, x in zip(pos, s) if keep(x)]
        out += [1e3 * (max(dz) - min(dz)) if dz else float("nan"),
                1e3 * (max(da) - min(da)) if da else float("nan")]
    return tuple(out)


def heading_turn_deg(pos, s, at):
    """The turn (deg) between the chords CORNER_CHORD_M before and after arc length `at`."""
    def point(x):
        x = min(max(x, 0.0), s[-1])
        k = max(1, next((i for i, v in enumerate(s) if v >= x), len(s) - 1))
        f = (x - s[k - 1]) / (s[k] - s[k - 1]) if s[k] > s[k - 1] else 0.0
        return tuple(pos[k - 1][i] + f * (pos[k][i] - pos[k - 1][i]) for i in range(3))
    here = point(at)
    u, v = sub(here, point(at - CORNER_CHORD_M)), sub(point(at + CORNER_CHORD_M), here)
    if dot(u, u) == 0 or dot(v, v) == 0:
        return 0.0
    return math.degrees(math.acos(max(-1.0, min(1.0, dot(unit(u), unit(v))))))


def max_rotation(pos, quat):
    """(deg/mm, tilt deg/mm at that pair, arc length m, where)."""
    s = arc_lengths(pos)
    best = (0.0, 0.0, 0.0)
    for k in range(len(pos) - 1):
        step_mm = 1e3 * (s[k + 1] - s[k])
        if step_mm < 1e-3:
            continue
        rate = qangle_deg(quat[k], quat[k + 1]) / step_mm
        if rate > best[0]:
            za, zb = qrot(quat[k], (0.0, 0.0, 1.0)), qrot(quat[k + 1], (0.0, 0.0, 1.0))
            tilt = math.degrees(math.acos(max(-1.0, min(1.0, dot(za, zb))))) / step_mm
            best = (rate, tilt, 0.5 * (s[k] + s[k + 1]))
    at = best[2]
    if at < END_M or at > s[-1] - END_M:
        where = "end"
    elif heading_turn_deg(pos, s, at) > CORNER_DEG:
        where = "corner"
    else:
        where = "run"
    return best[0], best[1], at, where


def measure(tree):
    """{(run, file): dict} for every trajectory under tree/robust."""
    out = {}
    for run_dir in sorted(glob.glob(os.path.join(tree, "robust", "*"))):
        run = os.path.basename(run_dir)
        shape = run.split("-")[0] if not run.startswith("pipe-long") else "pipe-long"
        for csv in sorted(glob.glob(os.path.join(run_dir, "trajectory*.csv"))):
            pos, quat = read_csv(csv)
            if len(pos) < 2:
                continue
            m = {"shape": shape, "res": run.split("-")[2 if shape == "pipe-long" else 1]}
            m["rate"], m["tilt_rate"], m["at"], m["where"] = max_rotation(pos, quat)
            if shape in STRAIGHT:
                m["dz"], m["da"], m["dz_in"], m["da_in"] = line_deviation(pos, quat)
            out[(run, os.path.basename(csv))] = m
    return out


def cell(after, before, key, digits):
    a = after.get(key)
    if a is None:
        return "-"
    text = f"{a:.{digits}f}" if isinstance(a, float) else str(a)
    if before is None or before.get(key) is None:
        return text
    b = before[key]
    return (f"{b:.{digits}f}" if isinstance(b, float) else str(b)) + " -> " + text


def tables(after, before):
    L = ["## Up and down on straight seams (peak to peak of the deviation from a line, mm)", "",
         "| run | file | depth all | across all | depth inner | across inner |",
         "|---|---|---:|---:|---:|---:|"]
    for key, m in after.items():
        if "dz" in m:
            b = before.get(key) if before is not None else None
            L.append(f"| {key[0]} | {key[1]} | " + " | ".join(
                cell(m, b, k, 2) for k in ("dz", "da", "dz_in", "da_in")) + " |")
    L += ["", "## Largest rotation between consecutive waypoints", "",
          "| run | file | deg/mm | tilt deg/mm | at m | where |", "|---|---|---:|---:|---:|---|"]
    for key, m in after.items():
        b = before.get(key) if before is not None else None
        L.append(f"| {key[0]} | {key[1]} | " + " | ".join(
            cell(m, b, k, d) for k, d in (("rate", 2), ("tilt_rate", 2), ("at", 3),
                                          ("where", 0))) + " |")
    L += ["", "## Per shape and resolution (worst trajectory)", "",
          "| shape | resolution | depth p-p all mm | depth p-p inner mm | max deg/mm | "
          "max tilt deg/mm |", "|---|---|---:|---:|---:|---:|"]
    groups = sorted({(m["shape"], m["res"]) for m in after.values()})
    for shape, res in groups:
        def worst(tree, k):
            vals = [m[k] for m in tree.values() if m["shape"] == shape and m["res"] == res
                    and k in m and not math.isnan(m[k])]
            return max(vals) if vals else None
        row = []
        for k in ("dz", "dz_in", "rate", "tilt_rate"):
            a = worst(after, k)
            b = worst(before, k) if before is not None else None
            row.append("-" if a is None else (f"{b:.2f} -> " if b is not None else "") + f"{a:.2f}")
        L.append(f"| {shape} | {res} | " + " | ".join(row) + " |")
    return "\n".join(L) + "\n"


ACCURACY = (("iou_percent", "IoU %", 1.0, -0.5), ("lateral_mean_m", "lateral mean mm", 1e3, 0.05),
            ("depth_mean_m", "depth mean mm", 1e3, 0.05),
            ("tool_axis_mean_deg", "tool axis mean deg", 1.0, 0.5))


def metrics(tree):
    out = {}
    for path in sorted(glob.glob(os.path.join(tree, "robust", "*", "metrics.json"))):
        with open(path) as f:
            m = json.load(f)
        out[os.path.basename(os.path.dirname(path))] = {**m.get("detection", {}),
                                                        **m.get("trajectory", {})}
    return out


def accuracy_table(after_tree, before_tree):
    """Per run: each accuracy metric BEFORE -> AFTER, '!' where the rule is broken."""
    a, b = metrics(after_tree), metrics(before_tree)
    L = ["## Accuracy against --before (! = beyond the rule)", "",
         "| run | " + " | ".join(c[1] for c in ACCURACY) + " |",
         "|---|" + "---:|" * len(ACCURACY)]
    worst = {c[0]: 0.0 for c in ACCURACY}
    for run in sorted(set(a) & set(b)):
        cells = []
        for key, _, scale, limit in ACCURACY:
            x, y = b[run].get(key), a[run].get(key)
            if x is None or y is None:
                cells.append("-")
                continue
            d = (y - x) * scale
            bad = d < limit if limit < 0 else d > limit
            worst[key] = min(worst[key], d) if limit < 0 else max(worst[key], d)
            cells.append(f"{x * scale:.2f} -> {y * scale:.2f}" + (" !" if bad else ""))
        L.append(f"| {run} | " + " | ".join(cells) + " |")
    L += ["", "Worst change: " + ", ".join(f"{c[1]} {worst[c[0]]:+.3f}" for c in ACCURACY), ""]
    return "\n".join(L)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("--before")
    ap.add_argument("--markdown")
    a = ap.parse_args()
    after = measure(a.out)
    before = measure(a.before) if a.before else None
    text = tables(after, before)
    if a.before:
        text += "\n" + accuracy_table(a.out, a.before)
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write(text)
    print(text, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""Draws docs/robot.md's figures: torch angles, weave patterns and the worked multi-pass example.

Usage: /usr/bin/python3 scripts/plot_robot_figures.py [OUTDIR]   (default docs/figures)
The weave curves follow the definitions in docs/robot.md ("Weaving"); the passes are the worked
example there (a V 8 mm deep and 8 mm wide, 8 mm^2 beads), whose numbers tests/robot/test_weld.cpp
checks against the planner.
"""
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def torch(ax, base, lean_deg, length, label):
    """A torch whose tip is at `base`, its body leaning by lean_deg towards +x of the drawing."""
    a = math.radians(lean_deg)
    top = (base[0] + length * math.sin(a), base[1] + length * math.cos(a))
    ax.annotate("", xy=base, xytext=top, arrowprops=dict(arrowstyle="-|>", lw=2, color="tab:red"))
    ax.text(top[0], top[1] + 0.25, label, ha="center", fontsize=9)


def torch_angles(out):
    fig, (side, cross) = plt.subplots(1, 2, figsize=(10, 4))
    side.plot([-5, 5], [0, 0], color="grey", lw=3)
    side.annotate("", xy=(1.5, -0.7), xytext=(-1.5, -0.7), arrowprops=dict(arrowstyle="->"))
    side.text(0, -1.3, "travel (tool x)", ha="center")
    # Push: the body trails, the tip points ahead along travel; drag the other way.
    torch(side, (-2.5, 0), -25, 3, "push: +travel_angle")
    torch(side, (2.5, 0), 25, 3, "drag: -travel_angle")
    side.set_ylim(-1.6, 4)
    side.set_title("side view: travel angle about tool y", y=-0.12)
    cross.fill([-4, -0.2, -4], [0, -3, -3], color="lightgrey")
    cross.fill([4, 0.2, 4], [0, -3, -3], color="lightgrey")
    cross.plot([-4, -0.2, 0.2, 4], [0, -3, -3, 0], color="grey", lw=2)
    torch(cross, (0, -3), 0, 3.5, "work_angle 0")
    # +work_angle turns tool z towards -y (drawn left): the body leans right.
    torch(cross, (0, -3), 25, 3.5, "+work_angle: z towards -y")
    cross.text(3.6, 0.4, "+y", ha="center")
    cross.text(-3.6, 0.4, "-y", ha="center")
    cross.set_ylim(-3.5, 1.5)
    cross.set_title("cross-section, looking along travel: work angle", y=-0.12)
    for ax in (side, cross):
        ax.set_aspect("equal")
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "torch-angles.png"), dpi=110)


def weave_points(pattern, length, wavelength):
    pts = [(0.0, 0.0)]
    if pattern == "zigzag":
        s, k = 0.25 * wavelength, 0
        while s < length:
            pts.append((s, 1.0 if k % 2 == 0 else -1.0))
            s, k = s + 0.5 * wavelength, k + 1
    elif pattern == "sine":
        ds = wavelength / 16
        s = ds
        while s < length:
            pts.append((s, math.sin(2 * math.pi * s / wavelength)))
            s += ds
    else:
        s = 0.0
        while s < length:
            if s > 0:
                pts.append((s, 1.0))
            pts.append((s, -1.0))
            s += wavelength
    pts.append((length, 0.0))
    return pts


def weave_patterns(out):
    fig, axes = plt.subplots(3, 1, figsize=(8, 5), sharex=True)
    for ax, pattern in zip(axes, ["zigzag", "sine", "triangle"]):
        pts = weave_points(pattern, 12.0, 4.0)
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", ms=3)
        ax.axhline(0, color="grey", lw=0.8)
        ax.set_ylabel(pattern + "\noffset / A")
        ax.set_ylim(-1.4, 1.4)
    axes[-1].set_xlabel("arc length along the seam (mm), wavelength 4 mm")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "weave-patterns.png"), dpi=110)


def passes(out):
    fig, ax = plt.subplots(figsize=(6, 4.2))
    depth, run = 8.0, 0.5
    ax.plot([-run * depth - 3, -run * depth, 0, run * depth, run * depth + 3],
            [depth, depth, 0, depth, depth], color="black", lw=2)
    layers = [(0.0, 4.0, 1, "root"), (4.0, math.sqrt(32), 1, "fill 1"),
              (math.sqrt(32), depth, 2, "cap")]
    colours = ["tab:orange", "tab:blue", "tab:green"]
    for (base, top, n, name), colour in zip(layers, colours):
        ax.fill([-run * base, run * base, run * top, -run * top], [base, base, top, top],
                color=colour, alpha=0.35)
        mid = 0.5 * (base + top)
        for i in range(n):
            lateral = run * mid - (i + 0.5) * 2 * run * mid / n
            ax.plot(lateral, base, "kx")
            label = name if n == 1 else "%s %d" % (name, i + 1)
            ax.text(lateral, mid, label, ha="center", va="center", fontsize=9)
    ax.set_aspect("equal")
    ax.set_xlabel("across the groove (mm)")
    ax.set_ylabel("height above the root (mm)")
    ax.set_title("V 8 mm deep, 8 mm^2 beads: 4 passes (x: where the torch aims)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "passes.png"), dpi=110)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..",
                                                            "docs", "figures")
    torch_angles(out)
    weave_patterns(out)
    passes(out)


if __name__ == "__main__":
    main()

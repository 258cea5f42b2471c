#!/usr/bin/python3
"""Why the robust V fit reads narrow noisy grooves wide: a Monte Carlo of one cross-section.

    /usr/bin/python3 scripts/v_fit_bias.py [--profiles N] [--seed S]

A profile as the D415 renderer (`groovetrace synth`) makes it at 640x480, 0.45 m, seen square
on (lengths in mm): a 6 mm wide 50 deg V sampled every pixel pitch (0.91 mm) at a random
phase, three image rows of it; optionally the stereo matching window's blur (binomial 1-2-1
across the pixels, never across a depth jump, as synth's blur_disparity), depth noise (sigma
0.6 mm, correlated over the same window, as synth's noise_field) and the renderer's 0.5 mm
root gap (the table seen through it). Each profile is fitted as the robust method does (Tukey
weights at 4.685 sigma, the points within 2 sigma of a vertex left out; residuals in height,
where the method takes them orthogonal), started at the truth; and, with every point, by a V
blurred in the model by each candidate window (with the gap, also one that knows the gap: the
window's side samples in the slot dropped, as synth does). Prints the median width and apex
against the truth, and each candidate's summed robust cost: without the gap the lowest picks
the window the profiles were taken with; with it the costs tie, so the window's width has to
come from the pixel geometry. Needs numpy and scipy (Debian's python3-scipy).

Other grooves and sensors: --width, --angle, --pitch, --sigma, --window, --rows, and
--depth-step (the D415's 1 mm depth unit: heights rounded to it at a random phase per profile).
--ray-zones leaves out the points whose ray (here vertical: their u) passes within the zone of
a vertex, instead of those whose measured position lies within it: noise then no longer decides
which points near a rim are kept. --no-models prints the fit as today only.
"""
import argparse

import numpy as np
from scipy.optimize import least_squares

HALF_WIDTH, PITCH, SIGMA, WINDOW = 3.0, 0.91, 0.6, 11.0  # mm
GAP, JUMP = 0.5, 5.0  # mm: root gap, a depth jump
APEX = -HALF_WIDTH / np.tan(np.radians(25.0))
TABLE = APEX - 10.0  # mm: the table seen through the gap
ROWS, DEPTH_STEP, RAY_ZONES = 3, 0.0, False
TUKEY = 4.685


def window(a, axis=-1, jump=np.inf):
    """The 1-2-1 binomial window along one axis (edges repeated), never across a depth jump
    of more than `jump` (mm; as synth's blur_disparity: the slot's table keeps its own depth
    and its neighbours theirs)."""
    pad = [(0, 0)] * a.ndim
    pad[axis] = (1, 1)
    p = np.pad(a, pad, mode="edge")
    n = a.shape[axis]
    total = weight = 0.0
    for k, w in enumerate((0.25, 0.5, 0.25)):
        q = np.take(p, range(k, k + n), axis=axis)
        seen = w * (np.abs(q - a) <= jump)
        total, weight = total + seen * q, weight + seen
    return total / weight


def v_profile(x, u, blur=0.0, gap=0.0):
    """Height of the V x = (root u, root v, left edge u, right edge u, top v) at u, seen
    through a 1-2-1 window `blur` (mm) wide per step; with a root `gap` (mm), the window's
    side samples that fall into the slot are dropped (synth's jump rule)."""
    ru, rv, ul, ur, top = x

    def sharp(w):
        left = top + (rv - top) * (w - ul) / (ru - ul)
        right = rv + (top - rv) * (w - ru) / (ur - ru)
        return np.where(w < ul, top, np.where(w < ru, left, np.where(w < ur, right, top)))

    if blur == 0:
        return sharp(u)
    total, weight = 0.5 * sharp(u), 0.5
    for w in (u - blur, u + blur):
        seen = 0.25 * (np.abs(w - ru) >= gap / 2)
        total, weight = total + seen * sharp(w), weight + seen
    return total / weight


def scan_profile(rng, blur, noise, gap):
    """Points (u, v) of one profile as the renderer would measure them; with `gap`, rays
    between the root faces meet the table below."""
    u = np.arange(-WINDOW - 2 * PITCH, WINDOW + 2 * PITCH, PITCH) + rng.uniform(0, PITCH)
    v = v_profile((0, APEX, -HALF_WIDTH, HALF_WIDTH, 0.0), u)
    if gap:
        v = np.where(np.abs(u) < GAP / 2, TABLE, v)
    if blur:
        v = window(v, jump=JUMP)
    rows = ROWS
    white = rng.normal(size=(rows, u.size))
    correlated = window(window(white, 0), 1) / (0.25**2 + 0.5**2 + 0.25**2)
    heights = v + SIGMA * correlated * (1.0 if noise else 0.0)
    if DEPTH_STEP > 0:
        phase = rng.uniform(0, DEPTH_STEP)
        heights = np.round((heights + phase) / DEPTH_STEP) * DEPTH_STEP - phase
    keep = np.abs(u) <= WINDOW
    return np.tile(u[keep], rows), heights[:, keep].ravel()


def fit(u, v, blur, zone, gap=0.0, rounds=6):
    """Tukey-reweighted least squares of the V (residuals in v; the view is square on), the
    points within `zone` (mm) of a vertex left out, the model seen through the window `blur`
    with the root `gap`. Returns width, apex and robust cost."""
    x = np.array([0.0, APEX, -HALF_WIDTH, HALF_WIDTH, 0.0])
    c = TUKEY * SIGMA
    for _ in range(rounds):
        corners = np.array([[x[0], x[1]], [x[2], x[4]], [x[3], x[4]]])
        du = u[:, None] - corners[:, 0]
        dist = np.abs(du) if RAY_ZONES else np.hypot(du, v[:, None] - corners[:, 1])
        far = np.min(dist, 1) > zone
        r = v - v_profile(x, u, blur, gap)
        w = np.sqrt(np.where(np.abs(r) < c, (1 - (r / c) ** 2) ** 2, 0.0) * far)
        x = least_squares(lambda y: w * (v - v_profile(y, u, blur, gap)), x).x
    r = (v - v_profile(x, u, blur, gap)) / c
    cost = np.sum(np.where(np.abs(r) < 1, 1 - (1 - r**2) ** 3, 1.0))
    return x[3] - x[2], x[1] - x[4], cost


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--profiles", type=int, default=80)
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--width", type=float, default=6.0, help="top width (mm)")
    ap.add_argument("--angle", type=float, default=50.0, help="included angle (deg)")
    ap.add_argument("--pitch", type=float, default=0.91, help="pixel pitch on the part (mm)")
    ap.add_argument("--sigma", type=float, default=0.6, help="depth noise (mm)")
    ap.add_argument("--window", type=float, default=11.0, help="half window (mm)")
    ap.add_argument("--rows", type=int, default=3, help="image rows per profile")
    ap.add_argument("--depth-step", type=float, default=0.0, help="depth unit (mm; 0: none)")
    ap.add_argument("--ray-zones", action="store_true", help="vertex zones along the rays")
    ap.add_argument("--no-models", action="store_true", help="only the fit as today")
    args = ap.parse_args()
    global HALF_WIDTH, PITCH, SIGMA, WINDOW, APEX, TABLE, ROWS, DEPTH_STEP, RAY_ZONES
    HALF_WIDTH, PITCH, SIGMA, WINDOW = args.width / 2, args.pitch, args.sigma, args.window
    APEX = -HALF_WIDTH / np.tan(np.radians(args.angle / 2))
    TABLE = APEX - 10.0
    ROWS, DEPTH_STEP, RAY_ZONES = args.rows, args.depth_step, args.ray_zones
    candidates = [0.0, 0.5 * PITCH, PITCH, 1.5 * PITCH]
    print(f"truth: width {2 * HALF_WIDTH:.2f} mm, apex {APEX:.2f} mm (below the top)")
    for blur, noise, gap in ((False, True, False), (True, False, False), (True, True, False),
                             (True, True, True)):
        rng = np.random.default_rng(args.seed)
        profiles = [scan_profile(rng, blur, noise, gap) for _ in range(args.profiles)]
        print(f"data: blur {'on ' if blur else 'off'} noise {'on ' if noise else 'off'}"
              f" root gap {GAP if gap else 0} mm")
        # As the robust method fits today: a sharp V, the vertices' zones (2 sigma) left out.
        today = np.array([fit(u, v, 0.0, 2 * SIGMA) for u, v in profiles])
        print(f"  sharp V, zones out : width {np.median(today[:, 0]):5.2f} mm, "
              f"apex {np.median(today[:, 1]):6.2f} mm")
        # The window modelled instead of avoided: every point counts, the costs compare. With
        # a gap, also the model that knows it.
        for g in () if args.no_models else (0.0, GAP) if gap else (0.0,):
            for b in candidates:
                f = np.array([fit(u, v, b, 0.0, g) for u, v in profiles])
                print(f"  model gap {g:3.1f} blur {b:4.2f} mm: width {np.median(f[:, 0]):5.2f} mm, "
                      f"apex {np.median(f[:, 1]):6.2f} mm, cost {f[:, 2].sum():7.1f}")


if __name__ == "__main__":
    main()

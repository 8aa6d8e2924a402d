#!/usr/bin/env python3
"""Compares two virtual-camera trajectories written by
`steadiface_bag --trajectory` for the same input bag (two builds, two
machines): frame by frame, the angle between the virtual rotations and the
distance between the principal offsets in output pixels.

usage: compare_trajectories.py A.csv B.csv --width PX
           [--max-rotation-deg D] [--max-offset-px P]
Prints one line (frames, frames with a face target, worst and 99th-percentile
differences, the frame of the worst) and exits 1 when the frames differ, the
face target is held on different frames, or a bound is exceeded.
"""
import argparse
import csv
import math
import sys


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    out = []
    for r in rows:
        q = [float(r[k]) for k in ("qx", "qy", "qz", "qw")]
        t = (float(r["tx"]), float(r["ty"]))
        out.append((float(r["stamp"]), q, t, target(r["has_target"])))
    return out


def target(cell):
    """has_target: "1"/"0" (older steadiface_bag wrote the raw byte)."""
    return int(cell) if cell.isdigit() else (ord(cell) if cell else 0)


def angle_deg(q1, q2):
    """The angle of q1^-1 q2, from its vector part (exact near zero)."""
    x1, y1, z1, w1 = q1
    x2, y2, z2, w2 = q2
    # conj(q1) * q2
    w = w1 * w2 + x1 * x2 + y1 * y2 + z1 * z2
    x = w1 * x2 - x1 * w2 - y1 * z2 + z1 * y2
    y = w1 * y2 + x1 * z2 - y1 * w2 - z1 * x2
    z = w1 * z2 - x1 * y2 + y1 * x2 - z1 * w2
    return math.degrees(2.0 * math.atan2(math.sqrt(x * x + y * y + z * z), abs(w)))


def percentile(values, p):
    s = sorted(values)
    return s[min(len(s) - 1, int(round(p * (len(s) - 1))))]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--width", type=float, required=True,
                    help="image width [px]: offsets are fractions of it")
    ap.add_argument("--max-rotation-deg", type=float, default=math.inf)
    ap.add_argument("--max-offset-px", type=float, default=math.inf)
    args = ap.parse_args()
    a, b = read(args.a), read(args.b)
    if not a or len(a) != len(b) or any(abs(x[0] - y[0]) > 1e-6 for x, y in zip(a, b)):
        print("the trajectories have different frames (%d and %d rows)" % (len(a), len(b)))
        return 1
    rot = [angle_deg(x[1], y[1]) for x, y in zip(a, b)]
    off = [args.width * math.hypot(x[2][0] - y[2][0], x[2][1] - y[2][1]) for x, y in zip(a, b)]
    worst = max(range(len(rot)), key=lambda i: rot[i])
    faces = sum(1 for x in a if x[3])
    face_diff = sum(1 for x, y in zip(a, b) if bool(x[3]) != bool(y[3]))
    ok = (max(rot) <= args.max_rotation_deg and max(off) <= args.max_offset_px and
          face_diff == 0)
    print("%d frames, a face target on %d, on different frames %d; rotation max %.2g deg (frame %d), p99 %.2g deg; offset max %.2g px, "
          "p99 %.2g px; bounds %g deg, %g px: %s" % (
              len(a), faces, face_diff, max(rot), worst, percentile(rot, 0.99), max(off), percentile(off, 0.99),
              args.max_rotation_deg, args.max_offset_px, "within" if ok else "EXCEEDED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

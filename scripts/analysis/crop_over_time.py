#!/usr/bin/env python3
"""The dynamic crop over time next to the motion it answers.

Reads steadiface_evaluate trajectories (traj_<preset>_<method>.csv, run with
--crop-mode dynamic) and plots, per file, the width the output keeps
(1 - 2 crop_ratio) and the real camera's angular speed (from the
trajectory's real rotation vectors), on one time axis.

    scripts/analysis/crop_over_time.py OUT.png TRAJ.csv [TRAJ.csv ...]
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    t = [float(r["t"]) for r in rows]
    kept = [1.0 - 2.0 * float(r["crop_ratio"]) for r in rows]
    speed = [0.0]
    for a, b in zip(rows, rows[1:]):
        d = math.sqrt(sum((float(b["real_r" + k]) - float(a["real_r" + k])) ** 2 for k in "xyz"))
        speed.append(math.degrees(d) / max(1e-6, float(b["t"]) - float(a["t"])))
    return t, kept, speed


def main():
    if len(sys.argv) < 3:
        print(__doc__)
        return 2
    out, paths = sys.argv[1], sys.argv[2:]
    fig, axes = plt.subplots(len(paths), 1, figsize=(8, 2.6 * len(paths)), squeeze=False)
    for ax, path in zip(axes[:, 0], paths):
        t, kept, speed = load(path)
        ax.plot(t, speed, color="0.7", lw=0.8, label="camera's angular speed [deg/s]")
        ax.set_ylabel("deg/s")
        ax2 = ax.twinx()
        ax2.plot(t, kept, color="C0", lw=2, label="width kept")
        ax2.axhline(0.70, color="C3", ls="--", lw=1, label="fixed crop (0.70)")
        ax2.set_ylim(0.6, 1.0)
        ax2.set_ylabel("width kept")
        name = path.rsplit("/", 1)[-1].replace("traj_", "").replace(".csv", "")
        ax.set_title(name)
        lines = ax.get_lines() + ax2.get_lines()
        ax.legend(lines, [line.get_label() for line in lines], loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("time [s]")
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    return 0


if __name__ == "__main__":
    sys.exit(main())

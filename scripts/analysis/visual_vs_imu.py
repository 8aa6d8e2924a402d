#!/usr/bin/env python3
"""The camera's rotation from the video beside the gyro's.

Reads two steadiface_evaluate trajectories of the same sequence
(traj_<preset>_<method>.csv: one run with the IMU, one with
--rotation-source visual or auto over an IMU dropout) and plots, per frame,
the camera's turn from the previous frame about each axis (from the
trajectories' real rotations), the gyro's as lines and the video's as
dots (LABEL: which run they are), with an optional shaded window (the
dropout).

    scripts/analysis/visual_vs_imu.py OUT.png IMU.csv VIDEO.csv TITLE LABEL [S,E]
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def exp_so3(v):
    """Rodrigues: a rotation vector to its matrix."""
    a = np.linalg.norm(v)
    k = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    if a < 1e-12:
        return np.eye(3) + k
    return np.eye(3) + np.sin(a) / a * k + (1 - np.cos(a)) / a ** 2 * k @ k


def log_so3(m):
    """A rotation matrix (less than 180 deg) to its rotation vector."""
    a = np.arccos(np.clip((np.trace(m) - 1) / 2, -1, 1))
    w = np.array([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]]) / 2
    return w if a < 1e-9 else w * a / np.sin(a)


def turns(path):
    """Per frame: time [s] and the turn from the previous frame [deg/frame]."""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    t = np.array([float(r["t"]) for r in rows])
    r = [exp_so3(np.array([float(x["real_r" + k]) for k in "xyz"])) for x in rows]
    # R_r maps world to camera: the turn in the camera is R_i R_{i-1}^T.
    d = np.array([log_so3(b @ a.T) for a, b in zip(r, r[1:])])
    return t[1:], np.degrees(d)


def main(argv):
    if len(argv) < 6:
        sys.exit(__doc__)
    out, imu_path, video_path, title, label = argv[1:6]
    window = [float(v) for v in argv[6].split(",")] if len(argv) > 6 else None
    t_i, d_i = turns(imu_path)
    t_v, d_v = turns(video_path)
    fig, axes = plt.subplots(3, 1, figsize=(9, 6), sharex=True)
    for k, (ax, name) in enumerate(zip(axes, "xyz")):
        ax.plot(t_i, d_i[:, k], "-", color="tab:red", lw=1, label="the IMU, whole")
        ax.plot(t_v, d_v[:, k], ".", color="black", ms=3, label=label)
        if window:
            ax.axvspan(window[0], window[1], color="0.9", zorder=0)
        ax.set_ylabel("about %s [deg/frame]" % name)
    axes[0].legend(loc="upper right")
    axes[0].set_title(title)
    axes[-1].set_xlabel("time [s]")
    n = min(len(d_i), len(d_v))
    rms = np.sqrt(np.mean(np.sum((d_i[:n] - d_v[:n]) ** 2, axis=1)))
    fig.text(0.01, 0.01, "RMS difference %.3f deg per frame" % rms, fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    print("%s: RMS difference %.4f deg per frame over %d frames" % (out, rms, n))


if __name__ == "__main__":
    main(sys.argv)

#!/usr/bin/env python3
"""Plots steadiface evaluation trajectories in the style of the paper's
Figs. 4-6: head-centre trajectory and its power spectrum (input vs
gyro-only vs steadiface), real vs virtual rotation, and the principal
offset over time.

usage: plot_report.py DIR [--presets walk,run]
DIR holds traj_<preset>_<method>.csv files (steadiface_evaluate or
steadiface_bag output). Writes DIR/plots/<preset>_*.png.
"""
import argparse
import csv
import glob
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

COLORS = {"none": "0.5", "gyro-only": "tab:blue", "steadiface": "tab:red"}
LABELS = {"none": "input", "gyro-only": "gyro-only", "steadiface": "steadiface"}


def load(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    out = {}
    for k in rows[0].keys():
        out[k] = np.array([float(r[k]) for r in rows])
    return out


def spectrum(x, fps):
    x = x[np.isfinite(x)]
    if len(x) < 8:
        return np.array([0.0]), np.array([0.0])
    t = np.arange(len(x))
    x = x - np.polyval(np.polyfit(t, x, 1), t)
    p = np.abs(np.fft.rfft(x)) ** 2 / len(x)
    f = np.fft.rfftfreq(len(x), 1.0 / fps)
    return f[1:], p[1:]


def plot_preset(d, preset, out_dir):
    data = {}
    for m in ("none", "gyro-only", "steadiface"):
        p = os.path.join(d, "traj_%s_%s.csv" % (preset, m))
        if os.path.exists(p):
            data[m] = load(p)
    if not data:
        return []
    written = []
    fps = 1.0 / np.median(np.diff(next(iter(data.values()))["t"]))
    # 1. Head-centre trajectory and power spectrum (paper Fig. 4).
    fig, ax = plt.subplots(3, 1, figsize=(8, 8))
    for m, v in data.items():
        ax[0].plot(v["t"], v["head_out_x"] - np.nanmean(v["head_out_x"]), color=COLORS[m], label=LABELS[m])
        ax[1].plot(v["t"], v["head_out_y"] - np.nanmean(v["head_out_y"]), color=COLORS[m], label=LABELS[m])
        f, px = spectrum(v["head_out_x"], fps)
        f, py = spectrum(v["head_out_y"], fps)
        ax[2].semilogy(f, px + py + 1e-9, color=COLORS[m], label=LABELS[m])
    ax[0].set_ylabel("head x (output px)")
    ax[1].set_ylabel("head y (output px)")
    ax[1].set_xlabel("time (s)")
    ax[2].set_xlabel("frequency (Hz)")
    ax[2].set_ylabel("power")
    ax[0].legend(loc="upper right")
    ax[0].set_title("%s: head-centre trajectory and power spectrum" % preset)
    fig.tight_layout()
    p = os.path.join(out_dir, "%s_head.png" % preset)
    fig.savefig(p, dpi=90)
    plt.close(fig)
    written.append(p)
    # 2. Real vs virtual rotation (paper Fig. 5) and 3. principal offset (Fig. 6).
    fig, ax = plt.subplots(4, 1, figsize=(8, 9), sharex=True)
    names = ["x (tilt)", "y (pan)", "z (roll)"]
    ref = data.get("steadiface", data.get("gyro-only"))
    if ref is not None:
        for i, k in enumerate(("x", "y", "z")):
            ax[i].plot(ref["t"], ref["real_r" + k], color="0.4", label="real")
            for m in ("gyro-only", "steadiface"):
                if m in data:
                    ax[i].plot(data[m]["t"], data[m]["virt_r" + k], color=COLORS[m], label="virtual, " + LABELS[m])
            ax[i].set_ylabel("rot. %s (rad)" % names[i])
        for m in ("gyro-only", "steadiface"):
            if m in data:
                ax[3].plot(data[m]["t"], data[m]["tx"], color=COLORS[m], label="t_x " + LABELS[m])
                ax[3].plot(data[m]["t"], data[m]["ty"], color=COLORS[m], linestyle="--", label="t_y " + LABELS[m])
        ax[3].set_ylabel("principal offset (norm.)")
        ax[3].set_xlabel("time (s)")
        ax[0].legend(loc="upper right", fontsize=8)
        ax[3].legend(loc="upper right", fontsize=8)
        ax[0].set_title("%s: real vs virtual camera, principal offset" % preset)
        fig.tight_layout()
        p = os.path.join(out_dir, "%s_camera.png" % preset)
        fig.savefig(p, dpi=90)
        written.append(p)
    plt.close(fig)
    return written


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir", help="folder with traj_<preset>_<method>.csv files")
    ap.add_argument("--presets", help="comma-separated presets (default: every one found)")
    args = ap.parse_args()
    d = args.dir
    presets = args.presets.split(",") if args.presets else None
    if presets is None:
        presets = sorted({os.path.basename(p)[5:].rsplit("_", 1)[0]
                          for p in glob.glob(os.path.join(d, "traj_*.csv"))})
    out_dir = os.path.join(d, "plots")
    os.makedirs(out_dir, exist_ok=True)
    for preset in presets:
        for p in plot_preset(d, preset, out_dir):
            print("wrote " + p)
    return 0


if __name__ == "__main__":
    sys.exit(main())

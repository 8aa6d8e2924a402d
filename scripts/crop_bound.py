#!/usr/bin/env python3
"""What a crop margin allows on one sequence, whatever the stabilizer.

Reads the input's trajectory (traj_<preset>_none.csv from steadiface_evaluate)
and, for each crop ratio r, moves an idealized crop window over the input:
a pure image shift of at most r * width (x) and r * height (y) per side, no
rolling shutter, no rotation. It scores the head (or the background) in the
window with the scorecard's jitter (linear trend removed, FFT bins under
0.5 Hz zeroed, RMS, in output pixels) for two policies:

  clamp      causal: hold the point still until the margin forces the window
             to move, then move just enough (a simple policy that needs no
             knowledge of the future shake; not proven the best causal one);
  optimum    non-causal: the window path with the least jitter (projected
             gradient on the convex problem), knowing the whole clip.

    scripts/crop_bound.py out/eval/traj_run_none.csv [--point head|bg]
"""
import argparse
import csv

import numpy as np


def highpass_matrix(n, fps, cutoff_hz):
    """The scorecard's jitter filter as a matrix (detrend, then zero bins)."""
    A = np.zeros((n, n))
    t = np.arange(n)
    f = np.minimum(t, n - t) * fps / n
    for j in range(n):
        e = np.zeros(n)
        e[j] = 1.0
        b, a = np.polyfit(t, e, 1)
        F = np.fft.fft(e - (a + b * t))
        F[f < cutoff_hz] = 0.0
        A[:, j] = np.real(np.fft.ifft(F))
    return A


def jitter(A, x):
    return np.sqrt(sum(np.sum((A @ x[:, k]) ** 2) for k in range(2)) / len(x))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv")
    ap.add_argument("--point", choices=["head", "bg"], default="head")
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--fps", type=float, default=30.0)
    ap.add_argument("--crops", default="0.1,0.125,0.15,0.2")
    a = ap.parse_args()
    W, H = (float(v) for v in a.size.split("x"))
    keys = ("head_in_x", "head_in_y") if a.point == "head" else ("bg_out_x", "bg_out_y")
    with open(a.csv) as f:
        x = np.array([[float(r[keys[0]]), float(r[keys[1]])] for r in csv.DictReader(f)])
    n = len(x)
    A = highpass_matrix(n, a.fps, 0.5)
    L = np.linalg.eigvalsh(A.T @ A).max()
    j_in = jitter(A, x)
    print("| crop per side | input px | causal clamp px | vs input | non-causal optimum px | vs input |")
    print("|---|---|---|---|---|---|")
    for r in (float(v) for v in a.crops.split(",")):
        M = np.array([r * W, r * H])
        zoom = 1.0 / (1.0 - 2.0 * r)
        clamp = np.zeros_like(x)
        clamp[0] = x[0]
        for i in range(1, n):
            clamp[i] = np.clip(clamp[i - 1], x[i] - M, x[i] + M)
        best = clamp.copy()
        for _ in range(20000):
            best = np.clip(best - (A.T @ (A @ best)) / L, x - M, x + M)
        jc, jo = zoom * jitter(A, clamp), zoom * jitter(A, best)
        print("| %g %% | %.2f | %.2f | %.2fx | %.2f | %.2fx |"
              % (100 * r, j_in, jc, jc / j_in, jo, jo / j_in))


if __name__ == "__main__":
    main()

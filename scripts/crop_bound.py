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
  recentre   causal: hold the point at a slow running mean of its input
             position (exponential, --alpha per frame), the window moving
             just enough when the margin forces it (the clamp lags far
             behind after a large swing; this one drifts back);
  optimum    non-causal: the window path with the least jitter (projected
             gradient on the convex problem), knowing the whole clip.

    scripts/crop_bound.py out/eval/traj_run_none.csv [--point head|bg]
        [--frames A:B] (score frames A..B-1 only, e.g. the scorecard's
        longest run of finite samples) [--alpha 0.02]
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
    ap.add_argument("--frames", default="", help="A:B, frames scored")
    ap.add_argument("--alpha", type=float, default=0.02)
    a = ap.parse_args()
    W, H = (float(v) for v in a.size.split("x"))
    keys = ("head_in_x", "head_in_y") if a.point == "head" else ("bg_out_x", "bg_out_y")
    with open(a.csv) as f:
        x = np.array([[float(r[keys[0]]), float(r[keys[1]])] for r in csv.DictReader(f)])
    # The running mean starts at the first frame of the file, the scoring
    # (and the policies' windows) at --frames.
    mean = np.zeros_like(x)
    mean[0] = x[0]
    for i in range(1, len(x)):
        mean[i] = (1.0 - a.alpha) * mean[i - 1] + a.alpha * x[i]
    if a.frames:
        lo, hi = (int(v) for v in a.frames.split(":"))
        x, mean = x[lo:hi], mean[lo:hi]
    n = len(x)
    A = highpass_matrix(n, a.fps, 0.5)
    L = np.linalg.eigvalsh(A.T @ A).max()
    j_in = jitter(A, x)
    print("| crop per side | input px | causal clamp px | vs input | causal recentre px | vs input "
          "| non-causal optimum px | vs input |")
    print("|---|---|---|---|---|---|---|---|")
    for r in (float(v) for v in a.crops.split(",")):
        M = np.array([r * W, r * H])
        zoom = 1.0 / (1.0 - 2.0 * r)
        clamp = np.zeros_like(x)
        clamp[0] = x[0]
        for i in range(1, n):
            clamp[i] = np.clip(clamp[i - 1], x[i] - M, x[i] + M)
        recentre = np.clip(mean, x - M, x + M)
        best = clamp.copy()
        for _ in range(20000):
            best = np.clip(best - (A.T @ (A @ best)) / L, x - M, x + M)
        jc, jr, jo = (zoom * jitter(A, p) for p in (clamp, recentre, best))
        print("| %g %% | %.2f | %.2f | %.2fx | %.2f | %.2fx | %.2f | %.2fx |"
              % (100 * r, j_in, jc, jc / j_in, jr, jr / j_in, jo, jo / j_in))


if __name__ == "__main__":
    main()

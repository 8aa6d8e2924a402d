#!/usr/bin/env python3
"""What any head target that leaves the background alone could reach.

In layered mode the head is held within a disc (the reach the layer blend
can absorb) around where the background layer shows it. This script reads
the per-frame tube that `steadiface_evaluate --reach-tube` writes
(reach_<preset>_<method>.csv: the true head centre through the background
layer's pose, i.e. gyro-only's output head, and the reach, both in output
px) and scores, with the scorecard's jitter (the RMS of the > 0.5 Hz part
after removing the linear trend, by FFT, over the longest run of frames
with the head in view):

- the background layer's own head (gyro-only's);
- the non-causal optimum: the path inside the tube with the least jitter,
  knowing the whole clip (projected gradient; a lower bound for every
  method that keeps the head within the reach);
- two causal policies clamped into the tube: a critically damped tracking
  filter of the background layer's head, and a constant-velocity "coast"
  whose velocity adapts towards the head's.

Frames without a reach (the face not used) keep the last one, which is
optimistic. With --reach-scale K the tube's radius is multiplied by K.

usage: reach_bound.py REACH_CSV [...] [--reach-scale K [K ...]] [--fps F]
"""
import argparse
import csv
import math
import sys

import numpy as np


def high_pass_matrix(n, fps=30.0, cutoff_hz=0.5):
    """The scorecard's high-pass (linear detrend, FFT mask) as an n x n matrix."""
    i = np.arange(n)
    X = np.vstack([np.ones(n), i]).T
    detrend = np.eye(n) - X @ np.linalg.pinv(X)
    F = np.fft.fft(np.eye(n), axis=0)
    f = np.minimum(i, n - i) * fps / n
    mask = np.diag((f >= cutoff_hz).astype(float))
    return np.real(np.fft.ifft(mask @ F, axis=0)) @ detrend


def jitter(A, y):
    """common/high_pass_rms.cc: sqrt(sum over both axes / n)."""
    return math.sqrt(float(np.sum((A @ y) ** 2)) / y.shape[0])


def clamp_to_tube(y, P, R):
    d = y - P
    n = np.linalg.norm(d, axis=1)
    k = n > R
    d[k] *= (R[k] / n[k])[:, None]
    return P + d


def non_causal_optimum(P, R, A, iterations=4000):
    """The least-jitter path inside the tube (convex: projected gradient)."""
    y = P.copy()
    L = max(np.linalg.norm(A, 2) ** 2, 1e-12)
    for _ in range(iterations):
        y = clamp_to_tube(y - A.T @ (A @ y) / L, P, R)
    return y


def tracking_filter(P, R, hz, dt):
    """A critically damped second-order tracker of P, clamped into the tube."""
    w = 2 * math.pi * hz
    y, v, out = P[0].copy(), np.zeros(2), []
    for p, r in zip(P, R):
        v = v + (w * w * (p - y) - 2 * w * v) * dt
        y = clamp_to_tube((y + v * dt)[None, :], p[None, :], np.array([r]))[0]
        out.append(y.copy())
    return np.array(out)


def coast(P, R, gain, dt):
    """Keep moving at a velocity that adapts towards P's, clamped into the tube."""
    y, v, vp, prev, out = P[0].copy(), np.zeros(2), np.zeros(2), P[0].copy(), []
    for p, r in zip(P, R):
        vp = 0.8 * vp + 0.2 * (p - prev) / dt
        prev = p
        v = v + gain * (vp - v)
        y = clamp_to_tube((y + v * dt)[None, :], p[None, :], np.array([r]))[0]
        out.append(y.copy())
    return np.array(out)


def longest_run(valid):
    best, start = (0, 0), None
    for k, ok in enumerate(list(valid) + [False]):
        if ok and start is None:
            start = k
        if not ok and start is not None:
            if k - start > best[1] - best[0]:
                best = (start, k)
            start = None
    return best


def load(path):
    rows = list(csv.DictReader(open(path)))
    valid = [int(r["head_valid"]) > 0 for r in rows]
    a, b = longest_run(valid)
    P = np.array([[float(r["bg_head_x"]), float(r["bg_head_y"])] for r in rows[a:b]])
    R = np.array([float(r["reach_px"]) for r in rows[a:b]])
    last = next((x for x in R if x > 0), 0.0)
    for k in range(len(R)):  # frames without a reach keep the last one
        last = R[k] = R[k] if R[k] > 0 else last
    return P, R, (a, b - 1)


def score(P, R, fps):
    """Jitter of the background layer's head, the non-causal optimum and the
    best of each causal policy (over a few settings) [output px]."""
    A = high_pass_matrix(len(P), fps)
    dt = 1.0 / fps
    causal = {
        "tracking filter": min(jitter(A, tracking_filter(P, R, hz, dt)) for hz in (0.05, 0.1, 0.2, 0.4)),
        "coast": min(jitter(A, coast(P, R, g, dt)) for g in (0.02, 0.05, 0.1)),
    }
    return jitter(A, P), jitter(A, non_causal_optimum(P, R, A)), causal


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--reach-scale", type=float, nargs="+", default=[1.0])
    ap.add_argument("--fps", type=float, default=30.0)
    args = ap.parse_args(argv)
    print("| file | frames | reach px (median) | scale | background layer's head px | "
          "non-causal optimum | best causal: tracking filter | best causal: coast |")
    print("|---|---|---|---|---|---|---|---|")
    for path in args.files:
        P, R, (a, b) = load(path)
        for k in args.reach_scale:
            g, opt, causal = score(P, k * R, args.fps)
            cells = [f"{x:.2f} ({x / g:.2f}x)" for x in (opt, causal["tracking filter"], causal["coast"])]
            print(f"| {path.split('/')[-1]} | {a}-{b} | {np.median(R):.1f} | {k:g} | {g:.2f} | "
                  + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

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

With --lookahead K, one more column: the recentre policy given the next K
frames (K frames of latency). At each frame it picks the points p_i..p_i+K
that minimize sum |p_j - m_j|^2 + lambda |p_j - p_j-1|^2 (m the running
mean, --smooth lambda; p_i-1 already shown), each window shift allowed,
and shows p_i. With lambda 0 it is the recentre policy.

    scripts/analysis/crop_bound.py out/eval/traj_run_none.csv [--point head|bg]
        [--frames A:B] (score frames A..B-1 only, e.g. the scorecard's
        longest run of finite samples) [--alpha 0.02]
        [--feasible out/eval/feasible_run_gyro-only.csv]
        [--lookahead K --smooth 0.5]

With --feasible (written by `steadiface_evaluate --feasible-set`), one more
row scores the same policies on each frame's measured set of window shifts
instead of the idealized box: the shifts for which the output is defined with
the real rotation, rolling shutter included (eval::FeasibleOffsets), given as
radii in 72 directions. A policy's wanted shift is then projected onto that
polygon (the closest allowed shift). The zoom is the first --crops value's,
which must be the crop of the run that wrote the file.

With --feasible-roll (written by `steadiface_evaluate --feasible-set
--feasible-roll MAX`), one more row: the same sets for a window that may
also roll, every 0.025 rad within +-MAX, chosen afresh on every frame. A
roll moves the head as well (the file gives by how much), so a wanted shift
is replaced by the closest head position any roll and its allowed shifts
give. This is an optimistic bound for the virtual camera's third freedom: a
roll that changes from frame to frame is itself visible shake, and the
score does not count it. The union of the sets is not convex, so that
row's non-causal optimum is not computed (-). Each roll's set is the
star-shaped polygon around the rolled window's unshifted pose; a roll whose
unshifted window protrudes adds nothing there.
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


def polygons(radii):
    """Per frame, the feasible set's polygon vertices (n, k, 2) [input px]."""
    k = radii.shape[1]
    a = 2.0 * np.pi * np.arange(k) / k
    return radii[:, :, None] * np.stack([np.cos(a), np.sin(a)], axis=1)[None]


def project(poly, d):
    """Closest points of the polygons poly (n, k, 2) to d (n, 2)."""
    A = poly
    B = np.roll(poly, -1, axis=1)
    AB = B - A
    # Inside: d within the star-shaped polygon around 0 (the sector's
    # triangle 0, A, B).
    k = poly.shape[1]
    ang = np.mod(np.arctan2(d[:, 1], d[:, 0]), 2.0 * np.pi)
    j = np.minimum((ang / (2.0 * np.pi / k)).astype(int), k - 1)
    idx = np.arange(len(d))
    a, b = A[idx, j], B[idx, j]
    det = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        ca = (d[:, 0] * b[:, 1] - d[:, 1] * b[:, 0]) / det
        cb = (a[:, 0] * d[:, 1] - a[:, 1] * d[:, 0]) / det
    inside = np.isfinite(ca) & np.isfinite(cb) & (ca + cb <= 1.0)
    # Else the nearest point on the edges.
    denom = np.maximum((AB ** 2).sum(2), 1e-12)
    s = np.clip(((d[:, None, :] - A) * AB).sum(2) / denom, 0.0, 1.0)
    q = A + s[:, :, None] * AB
    e = ((q - d[:, None, :]) ** 2).sum(2).argmin(1)
    out = q[idx, e]
    out[inside] = d[inside]
    return out


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv")
    ap.add_argument("--point", choices=["head", "bg"], default="head")
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--fps", type=float, default=30.0)
    ap.add_argument("--crops", default="0.1,0.125,0.15,0.2")
    ap.add_argument("--frames", default="", help="A:B, frames scored")
    ap.add_argument("--alpha", type=float, default=0.02)
    ap.add_argument("--feasible", default="", help="feasible_<preset>_<method>.csv")
    ap.add_argument("--feasible-roll", default="", help="feasible_<preset>_<method>_roll.csv")
    ap.add_argument("--lookahead", type=int, default=-1, help="K frames known ahead")
    ap.add_argument("--smooth", type=float, default=0.5, help="lambda of --lookahead")
    return ap.parse_args()


def read_rolls(path, frames):
    """[(head shift (n, 2), polygons (n, k, 2))] per roll of a _roll.csv, and
    the largest roll."""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    rolls = []
    for roll in sorted({r["roll"] for r in rows}, key=float):
        sel = [r for r in rows if r["roll"] == roll]
        if len(sel) != frames:
            raise SystemExit("%s has %d frames at roll %s, expected %d"
                             % (path, len(sel), roll, frames))
        shift = np.array([[float(r["head_dx"]), float(r["head_dy"])] for r in sel])
        r_k = np.array([[float(v) for v in list(r.values())[4:]] for r in sel])
        rolls.append((np.nan_to_num(shift), polygons(r_k)))
    return rolls, max(abs(float(r["roll"])) for r in rows)


def read_inputs(a):
    """The point's track, its running mean (from the file's first frame),
    the measured feasible radii and rolls, all cut to --frames."""
    keys = ("head_in_x", "head_in_y") if a.point == "head" else ("bg_out_x", "bg_out_y")
    with open(a.csv) as f:
        x = np.array([[float(r[keys[0]]), float(r[keys[1]])] for r in csv.DictReader(f)])
    mean = np.zeros_like(x)
    mean[0] = x[0]
    for i in range(1, len(x)):
        mean[i] = (1.0 - a.alpha) * mean[i - 1] + a.alpha * x[i]
    radii = None
    if a.feasible:
        with open(a.feasible) as f:
            radii = np.array([[float(v) for v in list(r.values())[1:]] for r in csv.DictReader(f)])
        if len(radii) != len(x):
            raise SystemExit("%s has %d frames, %s %d" % (a.feasible, len(radii), a.csv, len(x)))
    rolls, max_roll = read_rolls(a.feasible_roll, len(x)) if a.feasible_roll else ([], 0.0)
    if a.frames:
        lo, hi = (int(v) for v in a.frames.split(":"))
        x, mean = x[lo:hi], mean[lo:hi]
        if radii is not None:
            radii = radii[lo:hi]
        rolls = [(sh[lo:hi], po[lo:hi]) for sh, po in rolls]
    return x, mean, radii, rolls, max_roll


class Bound(object):
    """The policies' jitter on one track: a causal clamp, a causal
    recentre, the non-causal optimum and (K >= 0) a K-frame lookahead."""

    def __init__(self, x, mean, fps, lookahead, smooth):
        self.x, self.mean, self.n = x, mean, len(x)
        self.A = highpass_matrix(self.n, fps, 0.5)
        self.L = np.linalg.eigvalsh(self.A.T @ self.A).max()
        self.j_in = jitter(self.A, x)
        self.K, self.smooth = lookahead, smooth

    def lookahead(self, allowed):
        """The recentre policy knowing frames i..i+K (projected gradient on
        each window's convex problem, 300 steps)."""
        x, mean, lam = self.x, self.mean, self.smooth
        p = np.zeros_like(x)
        for i in range(self.n):
            f = slice(i, min(self.n, i + self.K + 1))
            prev = p[i - 1] if i > 0 else None
            q = x[f] + allowed(mean[f] - x[f], f)
            for _ in range(300):
                g = q - mean[f]
                v = np.diff(q, axis=0)
                g[1:] += lam * v
                g[:-1] -= lam * v
                if prev is not None:
                    g[0] += lam * (q[0] - prev)
                q = x[f] + allowed(q - g / (1.0 + 4.0 * lam) - x[f], f)
            p[i] = q[0]
        return p

    def row(self, label, r, allowed, iterations, optimum=True):
        """One table row: the three policies, each wanted shift d (window
        shift, input px) replaced by allowed(d, frames), the closest one the
        margin allows on those frames."""
        x, A, j_in = self.x, self.A, self.j_in
        clamp = np.zeros_like(x)
        clamp[0] = x[0] + allowed(np.zeros((1, 2)), slice(0, 1))[0]
        for i in range(1, self.n):
            clamp[i] = x[i] + allowed((clamp[i - 1] - x[i])[None], slice(i, i + 1))[0]
        recentre = x + allowed(self.mean - x, slice(None))
        best = clamp.copy()
        for _ in range(iterations if optimum else 0):
            best = x + allowed(best - (A.T @ (A @ best)) / self.L - x, slice(None))
        zoom = 1.0 / (1.0 - 2.0 * r)
        jc, jr, jo = (zoom * jitter(A, p) for p in (clamp, recentre, best))
        line = ("| %s | %.2f | %.2f | %.2fx | %.2f | %.2fx | " % (label, j_in, jc, jc / j_in, jr, jr / j_in)
                + ("%.2f | %.2fx |" % (jo, jo / j_in) if optimum else "- | - |"))
        if self.K >= 0:
            jl = zoom * jitter(A, self.lookahead(allowed))
            line += " %.2f | %.2fx |" % (jl, jl / j_in)
        print(line)


def rolled_projector(rolls):
    """allowed(d, frames) over the measured rolls: the closest head move to d
    that some roll and its shifts allow."""
    def rolled(d, frames):
        best, cost = None, None
        for shift, poly in rolls:
            q = shift[frames] + project(poly[frames], d - shift[frames])
            c = ((q - d) ** 2).sum(1)
            if best is None:
                best, cost = q, c
            else:
                better = c < cost
                best[better], cost[better] = q[better], c[better]
        return best
    return rolled


def main():
    a = parse_args()
    W, H = (float(v) for v in a.size.split("x"))
    # The running mean starts at the first frame of the file, the scoring
    # (and the policies' windows) at --frames.
    x, mean, radii, rolls, max_roll = read_inputs(a)
    bound = Bound(x, mean, a.fps, a.lookahead, a.smooth)
    K = a.lookahead
    print("| crop per side | input px | causal clamp px | vs input | causal recentre px | vs input "
          "| non-causal optimum px | vs input |"
          + (" recentre, %d-frame lookahead px | vs input |" % K if K >= 0 else ""))
    print("|---|---|---|---|---|---|---|---|" + ("---|---|" if K >= 0 else ""))
    crops = [float(v) for v in a.crops.split(",")]
    for r in crops:
        M = np.array([r * W, r * H])
        bound.row("%g %%" % (100 * r), r, lambda d, frames: np.clip(d, -M, M), 20000)
    r = crops[0]  # the measured sets' rows: the crop of the run that wrote them
    if radii is not None:
        poly = polygons(radii)
        bound.row("%g %%, measured set" % (100 * r), r,
                  lambda d, frames: project(poly[frames], d), 6000)
    if rolls:
        bound.row("%g %%, measured set, rolling +-%g rad" % (100 * r, max_roll), r,
                  rolled_projector(rolls), 0, optimum=False)


if __name__ == "__main__":
    main()

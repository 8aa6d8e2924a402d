#!/usr/bin/env python3
"""scripts/analysis/reach_bound.py on tubes whose answer is known: a tube
wider than the fast motion lets the non-causal optimum remove it all; a tube
of radius 0 leaves the background layer's head as it is; every path stays
in its tube, and the optimum is never worse than a causal policy.

usage: reach_bound_test.py [--junit FILE]
"""
import math
import os
import sys
import tempfile
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "scripts", "analysis"))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
import reach_bound  # noqa: E402
from junit_unittest import run_main  # noqa: E402

FPS = 30.0


def walk_with_bob(n=90, amplitude=8.0, hz=2.0):
    """A head walking across at 60 px/s with a vertical bob [output px]."""
    t = np.arange(n) / FPS
    return np.stack([100 + 60 * t, 180 + amplitude * np.sin(2 * math.pi * hz * t)], axis=1)


class ReachBoundTest(unittest.TestCase):
    def test_the_high_pass_ignores_a_linear_path_and_keeps_fast_motion(self):
        A = reach_bound.high_pass_matrix(90, FPS)
        t = np.arange(90) / FPS
        line = np.stack([3 + 40 * t, 7 - 5 * t], axis=1)
        self.assertLess(reach_bound.jitter(A, line), 1e-9)
        # 3 Hz over 3 s (nine whole periods) of amplitude 5 on one axis: its
        # RMS, 5 / sqrt(2), up to the detrend of a sine's small slope.
        sine = np.stack([5 * np.sin(2 * math.pi * 3 * t), np.zeros(90)], axis=1)
        self.assertAlmostEqual(reach_bound.jitter(A, sine), 5 / math.sqrt(2), delta=0.05)

    def test_a_tube_wider_than_the_bob_lets_the_optimum_remove_it(self):
        P = walk_with_bob(amplitude=8.0)
        g, opt, _ = reach_bound.score(P, np.full(len(P), 8.5), FPS)
        self.assertGreater(g, 5.0)
        self.assertLess(opt, 0.01 * g)

    def test_a_tube_of_radius_zero_leaves_the_head_as_it_is(self):
        P = walk_with_bob()
        g, opt, causal = reach_bound.score(P, np.zeros(len(P)), FPS)
        self.assertAlmostEqual(opt, g, places=9)
        for value in causal.values():
            self.assertAlmostEqual(value, g, places=9)

    def test_every_path_stays_in_its_tube_and_the_optimum_is_the_least(self):
        P = walk_with_bob(amplitude=12.0)
        R = np.full(len(P), 5.0)
        A = reach_bound.high_pass_matrix(len(P), FPS)
        paths = {"optimum": reach_bound.non_causal_optimum(P, R, A),
                 "tracking": reach_bound.tracking_filter(P, R, 0.2, 1 / FPS),
                 "coast": reach_bound.coast(P, R, 0.05, 1 / FPS)}
        for name, y in paths.items():
            self.assertLessEqual(np.max(np.linalg.norm(y - P, axis=1)), 5.0 + 1e-9, name)
        opt = reach_bound.jitter(A, paths["optimum"])
        self.assertLessEqual(opt, reach_bound.jitter(A, paths["tracking"]) + 1e-9)
        self.assertLessEqual(opt, reach_bound.jitter(A, paths["coast"]) + 1e-9)
        # The bob is 12 px and the tube 5: the optimum leaves about 7 px of it.
        g = reach_bound.jitter(A, P)
        self.assertGreater(opt, 0.4 * g)
        self.assertLess(opt, 0.75 * g)

    def test_load_takes_the_longest_run_and_fills_missing_reaches(self):
        path = os.path.join(tempfile.mkdtemp(), "reach.csv")
        with open(path, "w") as f:
            f.write("t,bg_head_x,bg_head_y,head_valid,reach_px\n")
            rows = [(1, 4.0)] * 2 + [(0, 0.0)] + [(1, 0.0), (1, 3.0), (1, 0.0), (1, 5.0)]
            for i, (valid, reach) in enumerate(rows):
                f.write("%g,%d,%d,%d,%g\n" % (i / FPS, i, 2 * i, valid, reach))
        P, R, (a, b) = reach_bound.load(path)
        self.assertEqual((a, b), (3, 6))
        self.assertEqual(P[0].tolist(), [3.0, 6.0])
        self.assertEqual(R.tolist(), [3.0, 3.0, 3.0, 5.0])  # the first keeps the next one


if __name__ == "__main__":
    sys.exit(run_main(ReachBoundTest, "reach_bound"))

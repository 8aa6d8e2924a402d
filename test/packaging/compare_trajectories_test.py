#!/usr/bin/env python3
"""scripts/compare_trajectories.py, the judge of the Debian 11 vs Debian 12
walk-bag check, on trajectories with known differences: it passes identical
ones and fails each kind of difference just past its bound.

usage: compare_trajectories_test.py [--junit FILE]
"""
import math
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
SCRIPT = os.path.join(REPO, "scripts", "compare_trajectories.py")
sys.path.insert(0, os.path.join(REPO, "scripts"))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
import compare_trajectories  # noqa: E402
from junit_unittest import run_main  # noqa: E402

HEADER = "stamp,qx,qy,qz,qw,tx,ty,rqx,rqy,rqz,rqw,has_target,hx,hy,cx,cy,w_fit\n"


def write(path, frames):
    """frames: (yaw_deg, tx, has_target) per frame, 30 fps."""
    with open(path, "w") as f:
        f.write(HEADER)
        for i, (yaw, tx, face) in enumerate(frames):
            h = math.radians(yaw) / 2
            f.write("%.6f,0,0,%.17g,%.17g,%.17g,0.001,0,0,0,1,%d,0.5,0.5,0.5,0.5,100\n" % (
                100 + i / 30.0, math.sin(h), math.cos(h), tx, face))


class CompareTrajectoriesTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        self.base = [(0.3 * math.sin(i / 5.0), 0.01 * math.cos(i / 7.0), int(i > 3))
                     for i in range(60)]
        self.a = os.path.join(self.dir, "a.csv")
        write(self.a, self.base)

    def judge(self, frames):
        b = os.path.join(self.dir, "b.csv")
        write(b, frames)
        return subprocess.run([sys.executable, SCRIPT, self.a, b, "--width", "1000",
                               "--max-rotation-deg", "0.001", "--max-offset-px", "0.01"],
                              capture_output=True, text=True)

    def test_identical_trajectories_pass(self):
        r = self.judge(self.base)
        self.assertEqual(r.returncode, 0, r.stdout)
        self.assertIn("60 frames, a face target on 56, on different frames 0", r.stdout)

    def test_a_rotation_past_the_bound_fails(self):
        frames = list(self.base)
        frames[30] = (frames[30][0] + 0.0015, frames[30][1], frames[30][2])
        r = self.judge(frames)
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn("rotation max 0.0015 deg (frame 30)", r.stdout)

    def test_an_offset_past_the_bound_fails(self):
        frames = list(self.base)
        frames[10] = (frames[10][0], frames[10][1] + 2e-5, frames[10][2])  # 0.02 px
        r = self.judge(frames)
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn("offset max 0.02 px", r.stdout)

    def test_a_face_held_on_other_frames_fails(self):
        frames = [(y, t, 1) for y, t, _ in self.base]
        r = self.judge(frames)
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn("on different frames 4", r.stdout)

    def test_different_frames_fail(self):
        r = self.judge(self.base[:-1])
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn("different frames (60 and 59 rows)", r.stdout)

    def test_angle_is_exact_in_closed_form(self):
        q90 = [0, 0, math.sin(math.pi / 4), math.cos(math.pi / 4)]
        self.assertAlmostEqual(compare_trajectories.angle_deg([0, 0, 0, 1], q90), 90.0, places=12)
        tiny = [math.sin(1e-9), 0, 0, math.cos(1e-9)]  # 2e-9 rad about x
        self.assertAlmostEqual(compare_trajectories.angle_deg([0, 0, 0, 1], tiny) /
                               math.degrees(2e-9), 1.0, places=9)
        # q and -q are one rotation.
        self.assertAlmostEqual(compare_trajectories.angle_deg(q90, [-c for c in q90]), 0.0)


if __name__ == "__main__":
    sys.exit(run_main(CompareTrajectoriesTest, "compare_trajectories"))

#!/usr/bin/env python3
"""rostest of the gyro-vs-video diagnostic (see gyro_video_check.test).
--case permuted: WARN naming imu/R_cam_imu, with the right axis
permutation suggested, within 5 s of the first stabilized frame; --case
offset: WARN naming imu/time_offset with a correction of +30 +- 5 ms within
5 s; --case ok: the check judges and never WARNs."""
import argparse
import sys
import threading
import time
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus

from steadiface.msg import StabilizerState
from stabilizer_rostest import quat_to_R

ARGS = None


class GyroVideoCheckTest(unittest.TestCase):
    def test_diagnostic(self):
        lock = threading.Lock()
        seen = {"first_frame": None, "statuses": [], "states": []}
        name = ARGS.node.lstrip("/") + ": gyro vs video"

        def on_diag(m):
            with lock:
                for s in m.status:
                    if s.name == name:
                        seen["statuses"].append((time.time(), s))

        def on_state(m):
            with lock:
                if seen["first_frame"] is None:
                    seen["first_frame"] = time.time()
                seen["states"].append(m)

        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=50)
        rospy.Subscriber("/camera/state", StabilizerState, on_state, queue_size=300)
        end = time.time() + 60
        while time.time() < end and not rospy.is_shutdown():
            with lock:
                n = len(seen["states"])
                done = seen["first_frame"] is not None and time.time() - seen["first_frame"] > 8.5
            if done:
                break
            time.sleep(0.1)
        with lock:
            first = seen["first_frame"]
            statuses = list(seen["statuses"])
            states = list(seen["states"])
        self.assertIsNotNone(first, "no stabilized frame")
        warns = [(t - first, s) for t, s in statuses if s.level == DiagnosticStatus.WARN]
        judged_ok = [s for t, s in statuses if s.level == DiagnosticStatus.OK and "agrees" in s.message]
        last = states[-1]
        print("case %s: %d frames; %d WARN, %d judged-OK statuses; first WARN at %s s: %s; "
              "last state: residual %.2f px, best mounting %.2f px, suggested [%.3f %.3f %.3f %.3f], "
              "offset correction %.1f ms" % (
                  ARGS.case, len(states), len(warns), len(judged_ok),
                  "%.1f" % warns[0][0] if warns else "-", warns[0][1].message if warns else "",
                  last.check_residual_px, last.check_best_mounting_residual_px,
                  last.suggested_R_cam_imu.x, last.suggested_R_cam_imu.y,
                  last.suggested_R_cam_imu.z, last.suggested_R_cam_imu.w,
                  last.imu_offset_correction_s * 1e3))
        applied = [m.imu_offset_applied_s for m in states]
        print("applied offset correction, every 30th frame [ms]: %s" %
              " ".join("%.1f" % (a * 1e3) for a in applied[::30]))
        if ARGS.case == "ok":
            # gyro_video_check/apply_offset (on by default) stays near zero.
            self.assertLess(max(abs(a) for a in applied), 0.003, "applied drifted")
            self.assertEqual(warns, [], "WARN with the right settings")
            self.assertGreater(len(judged_ok), 0, "the check never judged")
            return
        self.assertTrue(warns, "no WARN")
        self.assertLess(warns[0][0], 5.0, "the WARN came %.1f s after the first frame" % warns[0][0])
        if ARGS.case == "permuted":
            self.assertIn("imu/R_cam_imu", warns[0][1].message)
            q = last.suggested_R_cam_imu
            # The bag's IMU: R_imu_cam swaps x and y and flips z (its own
            # inverse), so imu/R_cam_imu should be that rotation.
            M = np.array([[0, 1, 0], [1, 0, 0], [0, 0, -1.0]])
            R = quat_to_R(q)
            self.assertLess(np.abs(R - M.T).max(), 1e-6, R)
            # No offset is applied while the rotation contradicts the video.
            self.assertEqual(max(abs(a) for a in applied), 0.0)
        else:
            self.assertIn("imu/time_offset", warns[0][1].message)
            self.assertAlmostEqual(last.imu_offset_correction_s, 0.030, delta=0.005)
            # The node applies it (apply_offset on by default): towards
            # +30 ms, never beyond it, never faster than apply_rate (5 ms/s).
            self.assertGreater(applied[-1], 0.010, "the correction was not applied")
            self.assertLess(max(applied), 0.035)
            for a, b, ma, mb in zip(applied, applied[1:], states, states[1:]):
                dt = (mb.header.stamp - ma.header.stamp).to_sec()
                self.assertLessEqual(abs(b - a), 0.005 * max(dt, 0.0) + 1e-6)


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--case", required=True, choices=["ok", "permuted", "offset"])
    p.add_argument("--node", default="/camera/steadiface")
    ARGS, rest = p.parse_known_args(rospy.myargv()[1:])
    sys.argv = [sys.argv[0]] + rest
    rospy.init_node("gyro_video_check_rostest")
    rostest.rosrun("steadiface", "gyro_video_check_rostest", GyroVideoCheckTest, sys.argv)

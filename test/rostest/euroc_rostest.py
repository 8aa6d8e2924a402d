#!/usr/bin/env python3
"""rostest: a EuRoC-style bag (no camera_info, IMU in its own rotated frame)
through the nodelet with camera_info_url and imu/R_cam_imu from parameters.
Checks that every frame is stabilized as mono8 (the crop zoomed to the input size), that no
frame is dropped for want of a camera_info, and that the background's
jitter (ground truth from the simulator's CSV, mapped through each frame's
published warp) falls well below the input's: it would not with the IMU's
axes taken as the camera's."""
import argparse
import sys
from types import SimpleNamespace
import threading
import time
import unittest

import numpy as np
import rospy
import rostest
import yaml
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs.msg import CameraInfo, Image

from steadiface.msg import StabilizerState
# The scorecard's helpers, shared with the other rostests (same folder).
from stabilizer_rostest import highpass_rms, quat_to_R
from truth_file import read_truth

ARGS = None


def quat(x, y, z, w):
    return SimpleNamespace(x=x, y=y, z=z, w=w)


class EurocTest(unittest.TestCase):
    def background_through(self, sts, inf, truth):
        """A far-background direction fixed in the world, in the input (the
        calibration's K and the true rotation) and through each state's
        warp into the output (its camera_info's K) [px]."""
        with open(ARGS.calibration) as f:
            cal = yaml.safe_load(f)
        K_in = np.array(cal["camera_matrix"]["data"], dtype=float).reshape(3, 3)
        d = None
        b_in, b_out = [], []
        for s in sts:
            key = round(s.header.stamp.to_sec(), 3)
            if key not in truth or key not in inf:
                continue
            R_true = truth[key]
            if d is None:  # a far-background direction fixed in the world
                d = R_true.T.dot(np.array([0.05, 0.03, 1.0]))
            p = K_in.dot(R_true.dot(d))
            p /= p[2]
            K_out = np.array(inf[key].K).reshape(3, 3)
            self.assertGreater(K_out[0, 0], 1.2 * K_in[0, 0])  # the 15 % crop, zoomed
            v, r = s.virtual_rotation, s.real_rotation
            H = K_out.dot(quat_to_R(v).dot(quat_to_R(r).T)).dot(
                np.linalg.inv(K_in))
            q = H.dot(p)
            b_in.append(p[:2])
            b_out.append(q[:2] / q[2])
        return b_in, b_out

    def test_euroc_style_bag(self):
        lock = threading.Lock()
        images, infos, states, diag = [], {}, [], {}

        def on_image(m):
            with lock:
                images.append((m.encoding, m.width, m.height))

        def on_info(m):
            with lock:
                infos[round(m.header.stamp.to_sec(), 3)] = m

        def on_state(m):
            with lock:
                states.append(m)

        def on_diag(m):
            with lock:
                for s in m.status:
                    diag[s.name] = s

        rospy.Subscriber("/cam0/image_stabilized/image_raw", Image, on_image, queue_size=50)
        rospy.Subscriber("/cam0/image_stabilized/camera_info", CameraInfo, on_info, queue_size=50)
        rospy.Subscriber("/cam0/state", StabilizerState, on_state, queue_size=200)
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=50)
        truth = {}
        for r in read_truth(ARGS.truth)[1]:
            truth[round(float(r["stamp"]), 3)] = quat_to_R(
                quat(*(float(r["row7_q" + k]) for k in "xyzw")))
        n_frames = len(truth)
        end = time.time() + 70
        last = (-1, time.time())
        while time.time() < end and not rospy.is_shutdown():
            with lock:
                n = len(states)
            if n >= n_frames or (n > 0 and time.time() - last[1] > 5.0):
                break
            if n != last[0]:
                last = (n, time.time())
            time.sleep(0.1)
        time.sleep(1.5)  # the last diagnostics
        with lock:
            imgs, sts, inf, dg = list(images), list(states), dict(infos), dict(diag)
        # Live: the first frames can go by before the subscriptions connect,
        # and a loaded machine drops a few (91-97 of 100 seen here); none may
        # be dropped for want of intrinsics (checked below).
        self.assertGreaterEqual(len(sts), 0.8 * n_frames,
                                "stabilized %d of %d frames" % (len(sts), n_frames))
        self.assertTrue(all(e == "mono8" for e, _, _ in imgs), set(e for e, _, _ in imgs))
        sizes = set((w, h) for _, w, h in imgs)
        self.assertEqual(len(sizes), 1, sizes)
        w, h = sizes.pop()
        self.assertEqual((w, h), (752, 480))  # the crop is zoomed back to the input size
        self.assertFalse(any(s.has_target for s in sts), "a face where there is none")
        name = [k for k in dg if k.endswith(": frames")]
        self.assertTrue(name, "no frames diagnostic: %s" % list(dg))
        values = {kv.key: kv.value for kv in dg[name[0]].values}
        self.assertEqual(values.get("dropped: bad camera_info"), "0", values)

        b_in, b_out = self.background_through(sts, inf, truth)
        self.assertGreater(len(b_in), 0.7 * n_frames)
        j_in, j_out = highpass_rms(b_in, 20.0), highpass_rms(b_out, 20.0)
        print("EuRoC-style: %d/%d frames %dx%d mono8; background jitter %.2f -> %.2f px" % (
            len(sts), n_frames, w, h, j_in, j_out))
        self.assertLess(j_out, 0.35 * j_in)


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--truth", required=True)
    p.add_argument("--calibration", required=True)
    ARGS, rest = p.parse_known_args(rospy.myargv()[1:])
    sys.argv = [sys.argv[0]] + rest
    rospy.init_node("euroc_rostest")
    rostest.rosrun("steadiface", "euroc_rostest", EurocTest, sys.argv)

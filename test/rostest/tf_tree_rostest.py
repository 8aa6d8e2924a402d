#!/usr/bin/env python3
"""rostest for the node's place in a robot's TF tree.

--tree: a bag's camera frame already has a parent (a static base_link ->
camera_link -> <camera> chain, as a URDF or a camera driver gives it). The
node, with its defaults, must not give that frame a second parent: every
frame on /tf and /tf_static has exactly one parent, and base_link resolves
to the stabilized camera and to the integrated gyro's frame.

--late-tf: the IMU has its own frame and its static TF comes 2 s after the
first image. Until then the "IMU extrinsics" diagnostic WARNs and names the
missing transform; once it is published the node takes it (OK, "from TF
<imu> -> <camera>") and keeps publishing stabilized images."""
import argparse
import sys
import threading
import time
import unittest

import rospy
import rostest
import tf2_ros
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import TransformStamped
from sensor_msgs.msg import Image
from tf2_msgs.msg import TFMessage

from stabilizer_rostest import wait_for

ARGS = None


class Watch(object):
    """Parents per child frame on /tf and /tf_static, stabilized images,
    and the diagnostics' latest level and message per name."""

    def __init__(self, camera_ns, image_topic):
        self.lock = threading.Lock()
        self.parents = {}
        self.images = []
        self.inputs = []
        self.diag = {}
        self.diag_history = []
        rospy.Subscriber("/tf", TFMessage, self.on_tf, queue_size=200)
        rospy.Subscriber("/tf_static", TFMessage, self.on_tf, queue_size=20)
        rospy.Subscriber(camera_ns + "/image_stabilized/image_raw", Image, self.on_image,
                         queue_size=50)
        rospy.Subscriber(image_topic, Image, self.on_input, queue_size=50)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diag, queue_size=50)

    def on_tf(self, m):
        with self.lock:
            for t in m.transforms:
                self.parents.setdefault(t.child_frame_id, set()).add(t.header.frame_id)

    def on_image(self, m):
        with self.lock:
            self.images.append(time.time())

    def on_input(self, m):
        with self.lock:
            self.inputs.append(time.time())

    def on_diag(self, m):
        with self.lock:
            for s in m.status:
                if s.name.endswith("IMU extrinsics"):
                    self.diag_history.append((time.time(), s.level, s.message))
                self.diag[s.name] = (s.level, s.message)


class TfTree(unittest.TestCase):
    def test_every_frame_has_one_parent_and_the_chain_resolves(self):
        w = Watch("/camera", "/camera/image_raw")
        buf = tf2_ros.Buffer()
        tf2_ros.TransformListener(buf)
        self.assertTrue(wait_for(lambda: len(w.images) >= 30, 60.0),
                        "no stabilized images")
        cam = ARGS.camera_frame
        for target in (cam + "_stabilized", cam + "_world"):
            ok = wait_for(lambda: buf.can_transform("base_link", target, rospy.Time(0)), 10.0)
            self.assertTrue(ok, "base_link -> %s does not resolve" % target)
        with w.lock:
            parents = {c: set(p) for c, p in w.parents.items()}
        for child, p in parents.items():
            self.assertEqual(len(p), 1, "%s has parents %s" % (child, sorted(p)))
        self.assertEqual(parents.get(cam), {"camera_link"})
        self.assertEqual(parents.get(cam + "_stabilized"), {cam})
        self.assertEqual(parents.get(cam + "_world"), {cam})


class LateTf(unittest.TestCase):
    def test_extrinsics_are_taken_when_the_static_tf_comes(self):
        w = Watch("/cam0", "/cam0/image_raw")
        self.assertTrue(wait_for(lambda: len(w.inputs) > 0, 60.0), "no input images")
        first = time.time()
        name = ARGS.imu_frame + " -> " + ARGS.camera_frame
        warned = wait_for(lambda: any(l == DiagnosticStatus.WARN and name in m
                                      for _, l, m in list(w.diag_history)), 10.0)
        self.assertTrue(warned, "no WARN naming the missing TF; saw %s" % w.diag_history[-3:])
        while time.time() < first + 2.0:
            time.sleep(0.05)
        pub = tf2_ros.StaticTransformBroadcaster()
        t = TransformStamped()
        t.header.stamp = rospy.Time.now()
        t.header.frame_id = ARGS.camera_frame
        t.child_frame_id = ARGS.imu_frame
        q = [float(v) for v in ARGS.rotation.split(",")]
        t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, \
            t.transform.rotation.w = q
        pub.sendTransform(t)
        published = time.time()
        ok = wait_for(lambda: any(s > published and l == DiagnosticStatus.OK and
                                  ("from TF " + name) in m for s, l, m in list(w.diag_history)),
                      10.0)
        self.assertTrue(ok, "the TF was not taken; saw %s" % w.diag_history[-3:])
        taken = time.time()
        self.assertTrue(wait_for(lambda: sum(1 for s in list(w.images) if s > taken) >= 10, 10.0),
                        "no stabilized images after the TF was taken")


def main():
    global ARGS
    p = argparse.ArgumentParser()
    p.add_argument("--tree", action="store_true")
    p.add_argument("--late-tf", action="store_true")
    p.add_argument("--camera-frame", default="camera_optical")
    p.add_argument("--imu-frame", default="imu4")
    p.add_argument("--rotation", default="0,0,0,1", help="R_cam_imu as x,y,z,w")
    ARGS, rest = p.parse_known_args(rospy.myargv(sys.argv)[1:])
    rospy.init_node("tf_tree_rostest")
    if ARGS.tree:
        rostest.rosrun("steadiface", "tf_tree", TfTree, sys.argv[:1] + rest)
    else:
        rostest.rosrun("steadiface", "late_tf", LateTf, sys.argv[:1] + rest)


if __name__ == "__main__":
    main()

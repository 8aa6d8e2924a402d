#!/usr/bin/env python3
"""The IMU publisher killed mid-run and started again (rotation_source auto,
the default). The test publishes the simulated bag's frames in real time
with fresh stamps; the IMU comes from a separate process on the same clock
(imu_publisher.py). After 3 s the test kills that process (SIGKILL), after
3 s more it starts it again, and it plays 4 s more. Asserts that

  - the rotation source switches both ways: imu, then visual, then imu
    again, in the state messages;
  - no frame passes unstabilized: every published frame has a state, and
    the "frames passed through without imu" counter stays 0;
  - nothing published is non-finite."""
import argparse
import os
import signal
import subprocess
import sys
import time
import unittest

import rospy
import rostest
from sensor_msgs.msg import Image

from fault_injection_rostest import Player, Watch, within
from steadiface.msg import StabilizerState

ARGS = None


class Sources(object):
    """The rotation source of each state, in order, and the images out."""

    def __init__(self):
        self.sources = []
        rospy.Subscriber("/camera/state", StabilizerState, self.on_state, queue_size=500)

    def on_state(self, m):
        self.sources.append(m.rotation_source)


def runs(sources):
    """The sources with repeats collapsed: ['imu', 'visual', 'imu']."""
    out = []
    for s in sources:
        if not out or out[-1] != s:
            out.append(s)
    return out


class ImuRestartTest(unittest.TestCase):
    def start_imu(self, p, start):
        here = os.path.dirname(os.path.abspath(__file__))
        return subprocess.Popen([sys.executable, os.path.join(here, "imu_publisher.py"),
                                 "--bag", ARGS.bag, "--base", repr(p.base), "--wall0", repr(p.wall0),
                                 "--t0", repr(p.t0), "--length", repr(p.length),
                                 "--from", repr(start)])

    def test_the_source_switches_both_ways_and_no_frame_passes_through(self):
        w = Watch(ARGS.node)
        src = Sources()
        p = Player(ARGS.bag)
        p.imu_hook = lambda m: None  # the IMU comes from its own process
        self.assertTrue(within(lambda: p.pub_img.get_num_connections() > 0, 20),
                        "the stabilizer never subscribed")
        # The IMU process gets 2.5 s to start and connect before the stream.
        p.base = rospy.Time.now().to_sec() + 2.5
        p.wall0 = time.time() + 2.5
        imu = self.start_imu(p, 0.0)
        try:
            p.play(3.0)
            imu.send_signal(signal.SIGKILL)
            imu.wait()
            p.play(3.0)
            imu = self.start_imu(p, p.stream_t + 0.05)
            p.play(4.0)
            # The last frames out before the IMU stops for good.
            time.sleep(1.0)
        finally:
            imu.send_signal(signal.SIGKILL)
            imu.wait()
        print("[ imu restart ] %d frames out, %d states; sources %s; %d visual"
              % (w.frames_out, len(src.sources), runs(src.sources), src.sources.count("visual")))
        seen = runs(src.sources)
        if seen[:1] == ["visual"]:
            seen = seen[1:]  # the IMU process was slow to start: not what is tested
        self.assertEqual(seen, ["imu", "visual", "imu"])
        self.assertEqual(len(src.sources), w.frames_out, "a frame was published without a state")
        self.assertEqual(w.value("gyro", "frames passed through without imu"), 0.0)
        self.assertEqual(w.nonfinite, [])


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--bag", required=True)
    ap.add_argument("--node", default="/camera/steadiface")
    ARGS, _ = ap.parse_known_args()
    rospy.init_node("imu_restart_test")
    rostest.rosrun("steadiface", "imu_restart", ImuRestartTest, sys.argv)

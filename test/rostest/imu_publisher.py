#!/usr/bin/env python3
"""The IMU of the imu_restart rostest, as its own process so that the test
can kill it and start it again: publishes the bag's /imu messages in real
time on a shared clock (stamp = BASE + t, sent at wall time WALL0 + t, t
the message's time in the looped bag stream), from stream time FROM on."""
import argparse
import time

import rosbag
import rospy
from sensor_msgs.msg import Imu


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bag", required=True)
    ap.add_argument("--base", type=float, required=True, help="stamp of stream time 0 [s]")
    ap.add_argument("--wall0", type=float, required=True, help="wall time of stream time 0 [s]")
    ap.add_argument("--t0", type=float, required=True, help="the bag's stream time 0 [s of bag stamps]")
    ap.add_argument("--length", type=float, required=True, help="one loop of the stream [s]")
    ap.add_argument("--from", dest="start", type=float, default=0.0, help="first stream time [s]")
    a, _ = ap.parse_known_args()
    rospy.init_node("test_imu", anonymous=True, disable_signals=True)
    with rosbag.Bag(a.bag) as b:
        imu = [m for _, m, _ in b.read_messages(topics=["/imu"])]
    rel = [m.header.stamp.to_sec() - a.t0 for m in imu]
    pub = rospy.Publisher("/imu", Imu, queue_size=2000)
    loop = int(a.start // a.length)
    i = next((k for k, r in enumerate(rel) if r + loop * a.length >= a.start), len(rel))
    while not rospy.is_shutdown():
        if i >= len(imu):
            i, loop = 0, loop + 1
        t = rel[i] + loop * a.length
        delay = a.wall0 + t - time.time()
        if delay > 0:
            time.sleep(delay)
        m = imu[i]
        m.header.stamp = rospy.Time.from_sec(a.base + t)
        pub.publish(m)
        i += 1


if __name__ == "__main__":
    main()

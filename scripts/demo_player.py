#!/usr/bin/env python3
"""demo.launch's player: plays a bag's camera and IMU topics into the demo's
namespace, or, without a bag, first simulates one (the walking selfie,
steadiface_simulate, into ROS_HOME). It plays in wall time (rosbag play
without --clock), so nothing on a running system switches to simulated
time; the stabilizer works from the messages' own stamps.

  rosrun steadiface demo_player.py [_bag:=FILE] [_loop:=true] [_rate:=1.0]
      [_seconds:=10] [_size:=640x360]
"""
import os
import subprocess
import sys

import rospy


def simulate(seconds, size):
    """The walking selfie as a bag in ROS_HOME (made once per duration and size)."""
    home = os.environ.get("ROS_HOME", os.path.join(os.path.expanduser("~"), ".ros"))
    os.makedirs(home, exist_ok=True)
    bag = os.path.join(home, "steadiface_demo_walk_%gs_%s.bag" % (seconds, size))
    if not os.path.exists(bag):
        rospy.loginfo("demo_player: simulating the walking selfie into %s", bag)
        tmp = bag + ".partial.bag"
        cmd = ["rosrun", "steadiface", "steadiface_simulate", "--preset", "walk",
               "--duration", str(seconds), "--size", size, "--out", tmp]
        if subprocess.call(cmd, stdout=subprocess.DEVNULL) != 0:
            rospy.logfatal("demo_player: steadiface_simulate failed: %s", " ".join(cmd))
            return None
        os.rename(tmp, bag)
        for sidecar in (".truth.csv",):
            if os.path.exists(tmp + sidecar):
                os.rename(tmp + sidecar, bag + sidecar)
    return bag


def main():
    rospy.init_node("demo_player")
    bag = rospy.get_param("~bag", "")
    if not bag:
        bag = simulate(float(rospy.get_param("~seconds", 10.0)), rospy.get_param("~size", "640x360"))
        if bag is None:
            return 1
    if not os.path.exists(bag):
        rospy.logfatal("demo_player: no bag at %s", bag)
        return 1
    # The bag's absolute topics move into this node's namespace (the demo's).
    ns = rospy.get_namespace().rstrip("/")
    cmd = ["rosbag", "play", "-q", "--rate", str(rospy.get_param("~rate", 1.0)), bag,
           "/camera/image_raw:=%s/camera/image_raw" % ns,
           "/camera/camera_info:=%s/camera/camera_info" % ns,
           "/imu:=%s/imu" % ns]
    if rospy.get_param("~loop", True):
        cmd.insert(2, "--loop")
    rospy.loginfo("demo_player: %s", " ".join(cmd))
    player = subprocess.Popen(cmd)
    rospy.on_shutdown(player.terminate)
    while not rospy.is_shutdown() and player.poll() is None:
        rospy.sleep(0.2)
    if player.poll() is None:
        player.terminate()
    return 0


if __name__ == "__main__":
    sys.exit(main())

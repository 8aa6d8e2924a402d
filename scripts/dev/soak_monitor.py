#!/usr/bin/env python3
"""Soak monitor: records latency two ways, both on the ROS clock divided by
the playback rate (so in wall seconds): image stamp -> publication of the
stabilized image as the node reports it (StabilizerState.latency_ms), and
image stamp -> arrival of the stabilized image here (adds transport to
another process and Python deserialization of the image); samples the RSS
of a process and prints a summary.
usage: soak_monitor.py PID SECONDS OUT.json [RATE=1]
SOAK_NO_IMAGE_SUBSCRIBER=1: do not subscribe to the images (latency as the
node reports it, without a Python consumer competing for the CPU)."""
import json
import os
import sys
import time

import rospy
from sensor_msgs.msg import Image

from steadiface.msg import StabilizerState


def rss_mb(pid):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def main():
    pid, seconds, out = int(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
    rate = float(sys.argv[4]) if len(sys.argv) > 4 else 1.0
    rospy.init_node("soak_monitor", anonymous=True)
    lat = []
    frames = [0]
    # Without an image subscriber, frames are counted on the state topic.
    count_states = os.environ.get("SOAK_NO_IMAGE_SUBSCRIBER") == "1"

    def on_image(m):
        frames[0] += 1
        d = (rospy.Time.now() - m.header.stamp).to_sec() / rate
        if 0 <= d < 10:
            lat.append(d * 1000.0)

    pub_lat, proc, arrival, wait = [], [], [], []

    def on_state(m):
        if count_states:
            frames[0] += 1
        proc.append(m.total_ms)
        if m.latency_ms > 0:
            pub_lat.append(m.latency_ms / rate)
            arrival.append(m.arrival_latency_ms / rate)
            wait.append(m.gyro_wait_ms / rate)

    if not count_states:
        rospy.Subscriber("/camera/image_stabilized/image_raw", Image, on_image, queue_size=10)
    rospy.Subscriber("/camera/state", StabilizerState, on_state, queue_size=100)
    samples = []
    t0 = time.time()
    while time.time() - t0 < seconds and not rospy.is_shutdown():
        samples.append((time.time() - t0, rss_mb(pid)))
        time.sleep(5.0)
    warm = [s for s in samples if s[0] >= min(60.0, seconds / 3)]
    slope = 0.0
    if len(warm) >= 3:
        n = len(warm)
        mt = sum(s[0] for s in warm) / n
        mr = sum(s[1] for s in warm) / n
        den = sum((s[0] - mt) ** 2 for s in warm)
        slope = sum((s[0] - mt) * (s[1] - mr) for s in warm) / den * 3600.0 if den > 0 else 0.0
    lat.sort()
    pub_lat.sort()
    proc.sort()
    arrival.sort()
    wait.sort()

    def pct(p, v=None):
        v = lat if v is None else v
        return v[min(len(v) - 1, int(p * (len(v) - 1) + 0.5))] if v else float("nan")
    res = {"seconds": seconds, "rate": rate, "frames": frames[0], "rss_start_mb": samples[0][1] if samples else None,
           "rss_end_mb": samples[-1][1] if samples else None, "rss_slope_mb_per_h": slope,
           "latency_p50_ms": pct(0.5), "latency_p99_ms": pct(0.99),
           "publish_latency_p50_ms": pct(0.5, pub_lat), "publish_latency_p99_ms": pct(0.99, pub_lat),
           "arrival_p50_ms": pct(0.5, arrival), "arrival_p99_ms": pct(0.99, arrival),
           "gyro_wait_p50_ms": pct(0.5, wait), "gyro_wait_p99_ms": pct(0.99, wait),
           "processing_p50_ms": pct(0.5, proc), "processing_p99_ms": pct(0.99, proc),
           "states": len(pub_lat)}
    with open(out, "w") as f:
        json.dump(res, f, indent=1)
    print(json.dumps(res))
    ok = frames[0] > 0
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Soak monitor: subscribes to the stabilized images, records latency
(receive time - image stamp, on the ROS clock), samples the RSS of a
process, and prints a summary. usage: soak_monitor.py PID SECONDS OUT.json"""
import json
import sys
import time

import rospy
from sensor_msgs.msg import Image


def rss_mb(pid):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def main():
    pid, seconds, out = int(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
    rospy.init_node("soak_monitor", anonymous=True)
    lat = []
    frames = [0]

    def on_image(m):
        frames[0] += 1
        d = (rospy.Time.now() - m.header.stamp).to_sec()
        if 0 <= d < 10:
            lat.append(d * 1000.0)

    rospy.Subscriber("/camera/image_stabilized/image_raw", Image, on_image, queue_size=10)
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
    pct = lambda p: lat[min(len(lat) - 1, int(p * (len(lat) - 1) + 0.5))] if lat else float("nan")
    res = {"seconds": seconds, "frames": frames[0], "rss_start_mb": samples[0][1] if samples else None,
           "rss_end_mb": samples[-1][1] if samples else None, "rss_slope_mb_per_h": slope,
           "latency_p50_ms": pct(0.5), "latency_p99_ms": pct(0.99)}
    with open(out, "w") as f:
        json.dump(res, f, indent=1)
    print(json.dumps(res))
    ok = frames[0] > 0
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

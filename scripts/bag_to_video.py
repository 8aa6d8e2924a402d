#!/usr/bin/env python3
"""Writes one image topic of a bag to a lossless FFV1 video through ffmpeg
(bgr8 / rgb8 / mono8 images), so video tools (ffmpeg's stabilizers, the
approximate scorer) see exactly the frames steadiface saw.
  bag_to_video.py BAG TOPIC OUT.mkv [--fps 30]"""
import argparse
import subprocess
import sys

import numpy as np
import rosbag


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("bag")
    ap.add_argument("topic")
    ap.add_argument("out")
    ap.add_argument("--fps", type=float, default=30.0)
    a = ap.parse_args()
    proc = None
    n = 0
    with rosbag.Bag(a.bag) as bag:
        topics = [a.topic, a.topic.lstrip("/")]
        for _, m, _ in bag.read_messages(topics=topics):
            if m.encoding not in ("bgr8", "rgb8", "mono8"):
                sys.exit("bag_to_video: unsupported encoding %s" % m.encoding)
            ch = 1 if m.encoding == "mono8" else 3
            img = np.frombuffer(m.data, dtype=np.uint8).reshape(m.height, m.step)[:, : m.width * ch]
            img = img.reshape(m.height, m.width, ch)
            if m.encoding == "rgb8":
                img = img[:, :, ::-1]
            elif ch == 1:
                img = np.repeat(img, 3, axis=2)
            if proc is None:
                proc = subprocess.Popen(
                    ["ffmpeg", "-hide_banner", "-loglevel", "error", "-y", "-f", "rawvideo",
                     "-pix_fmt", "bgr24", "-s", "%dx%d" % (m.width, m.height), "-r", str(a.fps),
                     "-i", "-", "-c:v", "ffv1", "-pix_fmt", "bgr0", a.out],
                    stdin=subprocess.PIPE)
            proc.stdin.write(np.ascontiguousarray(img).tobytes())
            n += 1
    if proc is None:
        sys.exit("bag_to_video: no images on %s in %s" % (a.topic, a.bag))
    proc.stdin.close()
    if proc.wait() != 0:
        sys.exit("bag_to_video: ffmpeg failed")
    print("%s: %d frames" % (a.out, n))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Prints a markdown table from steadiface_bag report JSONs
(report_<preset>_<method>.json with ground truth): input, gyro-only and
steadiface per preset. usage: summarize_reports.py DIR"""
import argparse
import glob
import json
import os
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("usage:")[0].strip())
    ap.add_argument("dir", help="folder with report_<preset>_<method>.json files")
    d = ap.parse_args().dir
    rows = []
    for p in sorted(glob.glob(os.path.join(d, "report_*_*.json"))):
        preset, method = os.path.basename(p)[len("report_"):-len(".json")].rsplit("_", 1)
        with open(p) as f:
            r = json.load(f)
        rows.append((preset, method, r))
    print("| sequence | method | head jitter (px) | background jitter (px) | cropping | undefined frames | fps (offline) | solver p50 (ms) | total p50 (ms) |")
    print("|---|---|---|---|---|---|---|---|---|")
    seen = set()
    for preset, method, r in rows:
        gt = r.get("ground_truth")
        if gt and preset not in seen:
            seen.add(preset)
            print("| %s | input | %.2f | %.2f | 1.00 | - | - | - | - |" % (
                preset, gt["head_jitter_in_px"], gt["background_jitter_in_px"]))
        t = r["timings_ms"]
        print("| %s | %s | %s | %s | %s | %s | %.1f | %.3f | %.2f |" % (
            preset, method,
            "%.2f" % gt["head_jitter_out_px"] if gt else "-",
            "%.2f" % gt["background_jitter_out_px"] if gt else "-",
            "%.2f" % gt["cropping"] if gt else "-",
            "%.1f%%" % (100 * gt["undefined_fraction"]) if gt else "-",
            r["throughput_fps"], t["solver"][0], t["total"][0]))
    if any(m == "steadiface-layered" for _, m, _ in rows):
        print()
        print("(steadiface-layered: the bag report maps the head through the subject "
              "layer and its background point, near the view centre, through the "
              "background layer; the band, the slow whole-frame shift and the "
              "subject covering that point are not modelled. The exact figures of "
              "the layered mesh are steadiface_evaluate's, docs/evaluation.md.)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

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
    print("| sequence | method | head jitter (px) | background jitter (px) | visible background jitter (px) | cropping | undefined frames | fps (offline) | solver p50 (ms) | total p50 (ms) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    seen = set()

    def px(gt, key):
        return "-" if not gt or gt.get(key) is None else "%.2f" % gt[key]
    for preset, method, r in rows:
        gt = r.get("ground_truth")
        if gt and preset not in seen:
            seen.add(preset)
            print("| %s | input | %s | %s | %s | 1.00 | - | - | - | - |" % (
                preset, px(gt, "head_jitter_in_px"), px(gt, "background_jitter_in_px"),
                px(gt, "visible_background_jitter_in_px")))
        t = r["timings_ms"]
        print("| %s | %s | %s | %s | %s | %s | %s | %.1f | %.3f | %.2f |" % (
            preset, method, px(gt, "head_jitter_out_px"), px(gt, "background_jitter_out_px"),
            px(gt, "visible_background_jitter_out_px"),
            "%.2f" % gt["cropping"] if gt else "-",
            "%.1f%%" % (100 * gt["undefined_fraction"]) if gt else "-",
            r["throughput_fps"], t["solver"][0], t["total"][0]))
    print()
    print("(Ground truth scored by eval::Scorecard, as steadiface_evaluate scores: "
          "each frame's exact warp, the layered mesh included. Background: far "
          "points all over the view; visible background: those the subject does "
          "not cover.)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

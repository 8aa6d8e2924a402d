#!/usr/bin/env python3
"""Counts test cases in JUnit XML files (gtest, rostest, catkin) and prints
one line per failure, with the start of its message (a CI log may show only
its tail), then one closing line: `N passed, N failed[, N skipped]`. Exits 1
on any failure or when no test ran at all, so an empty run can never look
green.

usage: test_summary.py RESULTS_DIR [--expect-files N]
"""
import glob
import os
import sys
import xml.etree.ElementTree as ET


def main():
    root = sys.argv[1]
    expect = 0
    if "--expect-files" in sys.argv:
        expect = int(sys.argv[sys.argv.index("--expect-files") + 1])
    passed = failed = skipped = 0
    failures = []
    files = sorted(glob.glob(os.path.join(root, "**", "*.xml"), recursive=True))
    for path in files:
        try:
            tree = ET.parse(path)
        except ET.ParseError as e:
            failed += 1
            failures.append("%s: unreadable result file (%s)" % (path, e))
            continue
        cases = tree.getroot().iter("testcase")
        n_cases = 0
        for case in cases:
            n_cases += 1
            name = "%s.%s" % (case.get("classname", "?"), case.get("name", "?"))
            bad = case.find("failure")
            if bad is None:
                bad = case.find("error")
            if bad is not None:
                failed += 1
                why = " ".join((bad.get("message") or bad.text or "").split())
                failures.append("%s: %s%s" % (os.path.basename(path), name,
                                              (" -- " + why[:400]) if why else ""))
            elif case.find("skipped") is not None or case.get("status") == "notrun":
                skipped += 1
            else:
                passed += 1
        if n_cases == 0:
            failed += 1
            failures.append("%s: no test case recorded (crash or timeout?)" % path)
    if len(files) < expect:
        failed += expect - len(files)
        failures.append("expected %d result files, found %d (a test binary did "
                        "not run or crashed before writing results)" % (expect, len(files)))
    for f in failures:
        print("FAILED: " + f)
    line = "%d passed, %d failed" % (passed, failed)
    if skipped:
        line += ", %d skipped" % skipped
    print(line)
    return 1 if failed or passed == 0 else 0


if __name__ == "__main__":
    sys.exit(main())

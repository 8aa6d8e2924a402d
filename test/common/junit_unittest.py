"""Runs a Python unittest TestCase for scripts/test: with --junit FILE it
also writes the JUnit XML that scripts/dev/test_summary.py counts."""
import os
import sys
import unittest
import xml.etree.ElementTree as ET


def run_main(case, suite_name):
    """Runs one TestCase class; with --junit FILE also writes its JUnit XML
    (for scripts/test's count). Returns the exit code."""
    argv = list(sys.argv)
    junit = None
    if "--junit" in argv:
        i = argv.index("--junit")
        junit = argv[i + 1]
    suite = unittest.defaultTestLoader.loadTestsFromTestCase(case)
    ids = [t.id() for t in suite]  # running the suite drops its tests
    result = unittest.TextTestRunner(verbosity=2).run(suite)
    if junit:
        write_junit(junit, suite_name, ids, result)
    return 0 if result.wasSuccessful() else 1


def write_junit(path, name, ids, result):
    failed = {t.id(): msg for t, msg in result.failures + result.errors}
    root = ET.Element("testsuite", name=name, tests=str(len(ids)), failures=str(len(failed)))
    for test_id in ids:
        case = ET.SubElement(root, "testcase", classname=name, name=test_id.rsplit(".", 1)[-1])
        if test_id in failed:
            ET.SubElement(case, "failure", message=failed[test_id][-2000:])
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    ET.ElementTree(root).write(path)

#!/usr/bin/env python3
"""The user docs (README and docs/ other than the evaluation and the
design notes) speak to users: no development history ("the machine of that
day", "it did once here", "this box", "this session", "issue #"). A
measurement keeps its date, machine and command instead.

usage: user_docs_test.py [--junit FILE]
"""
import os
import re
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
from junit_unittest import run_main  # noqa: E402

USER_DOCS = ["README.md", "docs/ros_api.md", "docs/parameters.md", "docs/calibration.md",
             "docs/platforms.md", "docs/reliability.md", "docs/benchmarks.md"]
HISTORY = [r"of that day", r"that day's", r"did once here", r"this box", r"this machine",
           r"\bsession\b", r"\bissue\s*#?\d", r"\bhere \(20\d\d"]


class UserDocsTest(unittest.TestCase):
    def test_no_development_history(self):
        found = []
        for doc in USER_DOCS:
            with open(os.path.join(REPO, doc)) as f:
                for n, line in enumerate(f, 1):
                    for pattern in HISTORY:
                        if re.search(pattern, line, re.I):
                            found.append("%s:%d: %s" % (doc, n, line.strip()))
        self.assertEqual(found, [])


if __name__ == "__main__":
    sys.exit(run_main(UserDocsTest, "user_docs"))

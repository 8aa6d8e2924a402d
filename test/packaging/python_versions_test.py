#!/usr/bin/env python3
"""Every Python file of the package parses with the grammar of Python 3.8,
the oldest Python a ROS Noetic user has (Ubuntu 20.04; Debian 11 has 3.9, and
scripts/dev/check_noetic_stack runs the nodelet rostest's script there).

This checks syntax only (match statements, `X | Y` in annotations evaluated
at run time are not caught by it when they are mere expressions). The
rostests exercise the scripts' behaviour under Python 3.9 in the Debian 11
root.

usage: python_versions_test.py [--junit FILE]
"""
import ast
import os
import subprocess
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
from junit_unittest import run_main  # noqa: E402

OLDEST = (3, 8)


def python_files():
    """Tracked and untracked (not ignored) files named *.py or with a
    python shebang."""
    out = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard"],
                         cwd=REPO, capture_output=True, text=True, check=True).stdout.split()
    files = []
    for rel in out:
        path = os.path.join(REPO, rel)
        if not os.path.isfile(path):
            continue
        if rel.endswith(".py"):
            files.append(rel)
            continue
        if "." in os.path.basename(rel):
            continue
        with open(path, "rb") as f:
            if b"python" in f.readline():
                files.append(rel)
    return files


class PythonVersionsTest(unittest.TestCase):
    def test_every_python_file_parses_as_python_3_8(self):
        files = python_files()
        self.assertGreater(len(files), 10)
        bad = []
        for rel in files:
            with open(os.path.join(REPO, rel)) as f:
                src = f.read()
            try:
                ast.parse(src, rel, feature_version=OLDEST)
            except SyntaxError as e:
                bad.append("%s:%s: %s" % (rel, e.lineno, e.msg))
        self.assertEqual(bad, [], "not Python 3.8:\n  " + "\n  ".join(bad))

    def test_newer_syntax_is_rejected(self):
        # The check itself: a match statement (3.10) and a parenthesized
        # context manager list (3.9) are refused under 3.8's grammar.
        for src in ("match x:\n    case 1:\n        pass\n",
                    "with (open('a') as a, open('b') as b):\n    pass\n"):
            with self.assertRaises(SyntaxError):
                ast.parse(src, feature_version=OLDEST)


if __name__ == "__main__":
    sys.exit(run_main(PythonVersionsTest, "python_versions"))

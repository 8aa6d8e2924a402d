#!/usr/bin/env python3
"""The core's modules include only modules below them, in the order of
docs/design.md's folder table (scripts/dev/include_graph.py). The checker is
first run on small trees whose answer is known: a planted upward include, a
private header of a module above, a ROS header in the core.

usage: include_graph_test.py [--junit FILE]
"""
import os
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
sys.path.insert(0, os.path.join(REPO, "scripts", "dev"))
from junit_unittest import run_main  # noqa: E402
import include_graph as ig  # noqa: E402

DESIGN = (
    "# Design\n\n### The core's folders\n\n"
    "| folder | what it holds |\n|---|---|\n"
    "| `common/` | low |\n| `camera/` | middle |\n| `warp/` | high |\n\n"
    "### Another table\n\n| `pipeline/` | not part of the order |\n"
)


def tree(root, files):
    """Writes {relative path: text} under root."""
    for rel, text in files.items():
        path = os.path.join(root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w") as fh:
            fh.write(text)


def public(module, name):
    return os.path.join("steadiface_core", "include", "steadiface_core", module, name)


def private(module, name):
    return os.path.join("steadiface_core", "src", module, name)


class IncludeGraphTest(unittest.TestCase):
    def test_reads_the_order_from_the_folder_table_only(self):
        self.assertEqual(ig.module_order(DESIGN), ["common", "camera", "warp"])

    def test_downward_includes_pass(self):
        with tempfile.TemporaryDirectory() as root:
            tree(root, {
                public("camera", "a.h"): '#include "steadiface_core/common/s.h"\n',
                private("warp", "b.cc"): ('#include "steadiface_core/camera/a.h"\n'
                                          '#include "warp/kernels.h"\n#include <vector>\n'),
            })
            errors, graph = ig.violations(root, ["common", "camera", "warp"])
            self.assertEqual(errors, [])
            self.assertEqual(graph["warp"], {"camera", "warp"})

    def test_a_planted_upward_include_fails_and_is_named(self):
        with tempfile.TemporaryDirectory() as root:
            tree(root, {
                public("camera", "a.h"): ('#pragma once\n\n#include <Eigen/Core>\n'
                                          '#include "steadiface_core/warp/warper.h"\n'),
            })
            errors, _ = ig.violations(root, ["common", "camera", "warp"])
            self.assertEqual(len(errors), 1)
            self.assertIn("camera/a.h:4:", errors[0])
            self.assertIn("camera includes steadiface_core/warp/warper.h", errors[0])

    def test_a_private_header_of_a_higher_module_fails(self):
        with tempfile.TemporaryDirectory() as root:
            tree(root, {private("common", "x.cc"): '#include "warp/mesh_scanline.h"\n'})
            errors, _ = ig.violations(root, ["common", "camera", "warp"])
            self.assertEqual(len(errors), 1)
            self.assertIn("common includes warp/mesh_scanline.h", errors[0])

    def test_ros_headers_and_unlisted_modules_fail(self):
        with tempfile.TemporaryDirectory() as root:
            tree(root, {
                private("camera", "r.cc"): "#include <ros/ros.h>\n",
                private("newmod", "n.cc"): "\n",
            })
            errors = sorted(ig.violations(root, ["common", "camera", "warp"])[0])
            self.assertEqual(len(errors), 2)
            self.assertIn("the core includes ros/ros.h", errors[0])
            self.assertIn("module 'newmod' is not a row", errors[1])

    def test_the_repository_keeps_the_order(self):
        with open(os.path.join(REPO, "docs", "design.md")) as fh:
            order = ig.module_order(fh.read())
        self.assertGreaterEqual(len(order), 10)
        errors, graph = ig.violations(REPO, order)
        self.assertEqual(errors, [], "\n".join(errors))
        # Every module of the tree is a row, and the order is not vacuous:
        # the pipeline sits above what it calls.
        self.assertLess(order.index("camera"), order.index("gyro"))
        self.assertIn("stabilizer", graph["pipeline"])


if __name__ == "__main__":
    sys.exit(run_main(IncludeGraphTest, "packaging.include_graph"))

#!/usr/bin/env python3
"""docs/ros_api.md against the code it documents, read here on its own:

- topics: every name the ROS layer subscribes to or advertises
  (steadiface_ros/src/stabilizer_ros.cc; a camera subscription or
  publication brings its camera_info), plus those of the libraries it uses
  there (tf2's listener and broadcaster, diagnostic_updater,
  dynamic_reconfigure), in "Subscribed Topics" or "Published Topics";
- services: dynamic_reconfigure's and any advertiseService;
- parameters: every key of the parameter table the node reads
  (steadiface_ros/src/parameter_table.inc) is a row or under a `prefix/*`
  row of "Parameters", and every row names a key or a group that exists;
- tf: every child frame the wrapper publishes (stabilizer_wrapper*.cc) is in
  "Provided tf Transforms", with the camera frame as its parent, and the
  page lists no other.

Each direction fails: a name in the code missing from the page, or a name on
the page that the code does not have.

usage: ros_api_test.py [--junit FILE]
"""
import os
import re
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
from junit_unittest import run_main  # noqa: E402

DOC = os.path.join(REPO, "docs", "ros_api.md")
ROS = os.path.join(REPO, "steadiface_ros", "src", "stabilizer_ros.cc")
WRAPPER = [os.path.join(REPO, "steadiface_ros", "src", f)
           for f in ("stabilizer_wrapper.cc", "stabilizer_wrapper_publish.cc")]
TABLE = os.path.join(REPO, "steadiface_ros", "src", "parameter_table.inc")


def read(path):
    with open(path) as f:
        return f.read()


def section_names(doc, title):
    """The first column's backticked names of the table under `### title`."""
    m = re.search(r"^### %s\n(.*?)(?=^##)" % re.escape(title), doc + "\n##", re.M | re.S)
    if not m:
        raise AssertionError("docs/ros_api.md has no section '%s'" % title)
    names = []
    for line in m.group(1).splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 2 or not line.startswith("|") or set(cells[0]) <= set("-"):
            continue
        names += re.findall(r"`([^`]+)`", cells[0])
    return names


class RosApiTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.doc = read(DOC)
        cls.ros = read(ROS)
        cls.wrapper = "\n".join(read(f) for f in WRAPPER)

    def code_topics(self):
        subs, pubs = set(), set()
        for kind, name in re.findall(r"\b(subscribe|subscribeCamera|advertise|advertiseCamera)"
                                     r"(?:<[^>]*>)?\(\s*\"([^\"]+)\"", self.ros):
            into = subs if kind.startswith("subscribe") else pubs
            into.add(name)
            if kind.endswith("Camera"):
                into.add(name.rsplit("/", 1)[0] + "/camera_info" if "/" in name else "camera_info")
        if "TransformListener" in self.ros:
            subs |= {"/tf", "/tf_static"}
        if "sendTransform" in self.ros:
            pubs.add("/tf")
        if "diagnostic_updater::Updater" in self.ros or "updater_->add" in self.ros:
            pubs.add("/diagnostics")
        if "dynamic_reconfigure::Server" in self.ros:
            pubs |= {"~parameter_descriptions", "~parameter_updates"}
        return subs, pubs

    def test_subscribed_topics(self):
        subs, _ = self.code_topics()
        self.assertEqual(set(section_names(self.doc, "Subscribed Topics")), subs)

    def test_published_topics(self):
        _, pubs = self.code_topics()
        self.assertEqual(set(section_names(self.doc, "Published Topics")), pubs)

    def test_services(self):
        services = set(re.findall(r"advertiseService\(\s*\"([^\"]+)\"", self.ros))
        if "dynamic_reconfigure::Server" in self.ros:
            services.add("~set_parameters")
        self.assertEqual(set(section_names(self.doc, "Services")), services)

    def test_parameters(self):
        keys = re.findall(r'^\{"([^"]+)", ParameterType::\w+, [^,]+, [^,]+, "[^"]*", "[^"]*", true\}',
                          read(TABLE), re.M)
        self.assertGreater(len(keys), 100)
        rows = [n[1:] if n.startswith("~") else n for n in section_names(self.doc, "Parameters")]
        exact = {r for r in rows if not r.endswith("/*")}
        groups = {r[:-1] for r in rows if r.endswith("/*")}
        missing = [k for k in keys if k not in exact and not any(k.startswith(g) for g in groups)]
        self.assertEqual(missing, [], "keys the page does not list")
        unknown = [r for r in exact if r not in keys]
        unknown += [g + "*" for g in groups if not any(k.startswith(g) for k in keys)]
        self.assertEqual(unknown, [], "rows that name no key")

    def test_provided_tf(self):
        # child_frame_id = <expression>: the stabilized frame (out_header's,
        # <camera_frame> + stabilized_suffix), suffixes added to it, and
        # WorldFrame(camera) (<camera_frame>_world).
        children = set()
        for expr in re.findall(r"child_frame_id\s*=\s*([^;]+);", self.wrapper):
            expr = expr.strip()
            if expr == "out_header.frame_id":
                children.add("<camera_frame>_stabilized")
            elif expr.startswith("out_header.frame_id +"):
                children.add("<camera_frame>_stabilized" + re.search(r'"([^"]+)"', expr).group(1))
            elif expr.startswith("WorldFrame("):
                body = re.search(r"::WorldFrame\(.*?\n}", self.wrapper, re.S).group(0)
                suffix = re.search(r'camera_frame \+ "([^"]+)"', body).group(1)
                children.add("<camera_frame>" + suffix)
            else:
                self.fail("a TF child frame the test does not know: %s" % expr)
        parents = set(re.findall(r"\bt\.header\.frame_id\s*=\s*(\w+);", self.wrapper))
        parents |= set(re.findall(r"\bw\.header\.frame_id\s*=\s*(\w+);", self.wrapper))
        self.assertEqual(parents, {"camera_frame"}, "every provided frame hangs below the camera")
        names = section_names(self.doc, "Provided tf Transforms")
        self.assertEqual(names[0::2], ["<camera_frame>"] * (len(names) // 2))
        self.assertEqual(set(names[1::2]), children)

    def test_required_tf(self):
        lookups = re.findall(r"lookupTransform\(\s*(\w+),\s*(\w+)", self.ros)
        self.assertEqual(lookups, [("camera_frame", "imu_frame")])
        self.assertEqual(section_names(self.doc, "Required tf Transforms"),
                         ["<camera_frame>", "<imu frame>"])


if __name__ == "__main__":
    sys.exit(run_main(RosApiTest, "ros_api_doc"))

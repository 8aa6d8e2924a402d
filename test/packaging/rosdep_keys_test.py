#!/usr/bin/env python3
"""Every dependency key of package.xml resolves the way `rosdep install`
resolves it on the platforms ROS1 users run.

A key resolves when it names a ROS Noetic package (noetic-packages.txt, from
ros/rosdistro's noetic/distribution.yaml) or when rosdep's system databases
(base.yaml, python.yaml) map it to apt packages on each platform below.
A key that resolves nowhere makes `rosdep install --from-paths src
--ignore-src -y` fail for every user.

The databases are read from $STEADIFACE_ROSDEP_DIR, else from ../shared/rosdep
beside the repository when it exists, else from the committed copy in
test/data/rosdep (origin in its README.md).

usage: rosdep_keys_test.py [--junit FILE]     (exit 0 when every key resolves)
"""
import os
import sys
import unittest
import xml.etree.ElementTree as ET

import yaml

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common"))
from junit_unittest import run_main  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# (rosdep OS name, codename): Noetic's tier-1 platform and the two Debian
# releases whose own archive carries ROS1.
PLATFORMS = [("ubuntu", "focal"), ("debian", "bullseye"), ("debian", "bookworm")]

DEPEND_TAGS = ("depend", "build_depend", "build_export_depend", "exec_depend",
               "test_depend", "buildtool_depend", "doc_depend")


def rosdep_dir():
    env = os.environ.get("STEADIFACE_ROSDEP_DIR")
    if env:
        return env
    shared = os.path.join(os.path.dirname(REPO), "shared", "rosdep")
    if os.path.isfile(os.path.join(shared, "base.yaml")):
        return shared
    return os.path.join(REPO, "test", "data", "rosdep")


class RosdepDatabase:
    """The subset of rosdep's resolution that apt-based platforms use."""

    def __init__(self, directory):
        self.rules = {}
        for name in ("base.yaml", "python.yaml"):
            with open(os.path.join(directory, name)) as f:
                self.rules.update(yaml.safe_load(f))
        with open(os.path.join(directory, "noetic-packages.txt")) as f:
            self.ros_packages = {line.strip() for line in f if line.strip()}

    def resolve(self, key, os_name, codename):
        """Returns ("ros", [key]), ("apt", [packages]) or (None, reason)."""
        if key in self.ros_packages:
            return "ros", [key]
        if key not in self.rules:
            return None, "not a Noetic package and not in base.yaml or python.yaml"
        rule = self.rules[key].get(os_name) if isinstance(self.rules[key], dict) else None
        if rule is None:
            return None, "no rule for %s" % os_name
        if isinstance(rule, dict) and ("*" in rule or codename in rule or
                                       any(k not in ("apt", "pip", "source") for k in rule)):
            if codename in rule:
                rule = rule[codename]
            elif "*" in rule:
                rule = rule["*"]
            else:
                return None, "no rule for %s %s" % (os_name, codename)
        packages = self._apt_packages(rule)
        if not packages:
            return None, "no apt packages for %s %s" % (os_name, codename)
        return "apt", packages

    @staticmethod
    def _apt_packages(rule):
        if isinstance(rule, list):
            return rule
        if isinstance(rule, str):
            return rule.split()
        if isinstance(rule, dict):
            apt = rule.get("apt", rule)
            if isinstance(apt, dict):
                return RosdepDatabase._apt_packages(apt.get("packages"))
        return None


def package_keys(package_xml):
    root = ET.parse(package_xml).getroot()
    keys = []
    for tag in DEPEND_TAGS:
        keys += [(tag, e.text.strip()) for e in root.findall(tag)]
    return keys


def unresolved(db, keys):
    bad = []
    for tag, key in keys:
        for os_name, codename in PLATFORMS:
            kind, why = db.resolve(key, os_name, codename)
            if kind is None:
                bad.append("<%s>%s</%s> on %s %s: %s" % (tag, key, tag, os_name, codename, why))
    return bad


class RosdepKeysTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.db = RosdepDatabase(rosdep_dir())

    def test_every_key_of_package_xml_resolves(self):
        keys = package_keys(os.path.join(REPO, "package.xml"))
        self.assertGreater(len(keys), 20)
        bad = unresolved(self.db, keys)
        self.assertEqual(bad, [], "keys rosdep cannot resolve:\n  " + "\n  ".join(bad))

    def test_keys_resolve_to_the_expected_packages(self):
        # Closed checks of the resolver on keys whose answer is known.
        self.assertEqual(self.db.resolve("roscpp", "ubuntu", "focal"), ("ros", ["roscpp"]))
        self.assertEqual(self.db.resolve("eigen", "debian", "bullseye"), ("apt", ["libeigen3-dev"]))
        self.assertEqual(self.db.resolve("libdlib-dev", "ubuntu", "focal"),
                         ("apt", ["libdlib-dev"]))
        self.assertEqual(self.db.resolve("python3-numpy", "ubuntu", "focal")[0], "apt")

    def test_unknown_keys_are_reported(self):
        # The Debian package names that are not rosdep keys: the resolver must
        # reject them, or the first test could never fail.
        for key in ("libdlib-data", "opencv-data"):
            kind, why = self.db.resolve(key, "ubuntu", "focal")
            self.assertIsNone(kind, key)
            self.assertIn("not a Noetic package", why)
        self.assertEqual(len(unresolved(self.db, [("exec_depend", "libdlib-data")])),
                         len(PLATFORMS))

    def test_package_xml_declares_url_and_maintainer(self):
        root = ET.parse(os.path.join(REPO, "package.xml")).getroot()
        maintainers = root.findall("maintainer")
        self.assertTrue(maintainers)
        for m in maintainers:
            self.assertIn("@", m.get("email", ""))
            self.assertTrue((m.text or "").strip())
        urls = [u.text.strip() for u in root.findall("url") if u.text]
        self.assertTrue(urls, "package.xml has no <url>")
        for u in urls:
            self.assertRegex(u, r"^https?://")


if __name__ == "__main__":
    sys.exit(run_main(RosdepKeysTest, "rosdep_keys"))

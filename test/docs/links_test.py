#!/usr/bin/env python3
"""Every relative link in README.md and docs/*.md resolves: to a file or
folder of the repository, and where it names an anchor (#...), to a heading
of that file (GitHub's anchor rules). Web links are not fetched.

usage: links_test.py [--junit FILE]
"""
import glob
import os
import re
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
from junit_unittest import run_main  # noqa: E402

LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)|!\[[^\]]*\]\(([^)\s]+)\)")


def slug(heading):
    """GitHub's anchor for a heading's text."""
    text = re.sub(r"[`*]", "", heading.strip().lower())
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path):
    out, seen = set(), {}
    in_code = False
    with open(path) as f:
        for line in f:
            if line.startswith("```"):
                in_code = not in_code
            if in_code:
                continue
            m = re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", line)
            if m:
                s = slug(m.group(1))
                n = seen.get(s, 0)
                seen[s] = n + 1
                out.add(s if n == 0 else "%s-%d" % (s, n))
    return out


def links(path):
    in_code = False
    with open(path) as f:
        for number, line in enumerate(f, 1):
            if line.startswith("```"):
                in_code = not in_code
            if in_code:
                continue
            for m in LINK.finditer(line):
                yield number, m.group(1) or m.group(2)


def broken(paths):
    bad = []
    for path in paths:
        rel = os.path.relpath(path, REPO)
        for number, target in links(path):
            if re.match(r"^[a-z]+:", target):  # http:, https:, mailto:
                continue
            file_part, _, anchor = target.partition("#")
            dest = path if not file_part else os.path.normpath(
                os.path.join(os.path.dirname(path), file_part))
            if not os.path.exists(dest):
                bad.append("%s:%d: %s: no such file" % (rel, number, target))
            elif anchor and dest.endswith(".md") and anchor not in anchors(dest):
                bad.append("%s:%d: %s: no such heading" % (rel, number, target))
    return bad


def documents():
    return [os.path.join(REPO, "README.md")] + sorted(glob.glob(os.path.join(REPO, "docs", "*.md")))


class LinksTest(unittest.TestCase):
    def test_every_link_resolves(self):
        docs = documents()
        n = sum(1 for d in docs for _ in links(d))
        self.assertGreater(n, 5)
        bad = broken(docs)
        self.assertEqual(bad, [], "broken links:\n  " + "\n  ".join(bad))

    def test_a_broken_link_is_found(self):
        import tempfile
        d = tempfile.mkdtemp(dir=os.path.join(REPO, "docs"))
        try:
            p = os.path.join(d, "t.md")
            with open(p, "w") as f:
                f.write("# A `code` heading, too\n\n[ok](#a-code-heading-too) [ok](../../README.md)\n"
                        "[bad](#nowhere) [bad](missing.md) ![img](none.png)\n"
                        "```\n[in code](ignored.md)\n```\n")
            bad = broken([p])
            self.assertEqual(len(bad), 3, bad)
            self.assertTrue(any("#nowhere: no such heading" in b for b in bad))
            self.assertTrue(any("missing.md: no such file" in b for b in bad))
        finally:
            for f in os.listdir(d):
                os.remove(os.path.join(d, f))
            os.rmdir(d)

    def test_slugs_follow_github(self):
        self.assertEqual(slug("Stabilize your camera"), "stabilize-your-camera")
        self.assertEqual(slug("ROS API: nodes, topics, TF"), "ros-api-nodes-topics-tf")
        self.assertEqual(slug("Conventions (paper §4.1)"), "conventions-paper-41")
        self.assertEqual(slug("`warp/mode` and E_f"), "warpmode-and-e_f")


if __name__ == "__main__":
    sys.exit(run_main(LinksTest, "doc_links"))

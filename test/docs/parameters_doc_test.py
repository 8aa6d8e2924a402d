#!/usr/bin/env python3
"""docs/parameters.md against the files it documents, read here on their
own (not through the generator): every key of config/default.yaml has a row
with its default, every dynamic_reconfigure parameter of
config/Steadiface.cfg appears as a run-time name on the row of a key whose
default is the .cfg's, and every generated file (default.yaml, Steadiface.cfg,
parameter_table.inc, this doc) is what scripts/dev/gen_parameters.py writes
from config/parameters.yaml today.

usage: parameters_doc_test.py [--junit FILE]
"""
import ast
import os
import re
import subprocess
import sys
import tempfile
import unittest

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
from junit_unittest import run_main  # noqa: E402

DOC = os.path.join(REPO, "docs", "parameters.md")


def leaves(node, prefix=""):
    """{'a/b': value} for every non-mapping value of a YAML document."""
    out = {}
    for k, v in node.items():
        key = prefix + k
        if isinstance(v, dict):
            out.update(leaves(v, key + "/"))
        else:
            out[key] = v
    return out


def doc_rows(text):
    """{key: (default, run-time name or None)} from the doc's tables."""
    rows = {}
    for line in text.splitlines():
        m = re.match(r"\| `([^`]+)` \|.*\| `(.*)` \| [^|]* \| (.*) \|$", line)
        if m:
            runtime = re.match(r"yes: `(\w+)`", m.group(3))
            rows[m.group(1)] = (yaml.safe_load(m.group(2)), runtime.group(1) if runtime else None)
    return rows


def cfg_defaults():
    out = {}
    with open(os.path.join(REPO, "config", "Steadiface.cfg")) as f:
        for line in f:
            m = re.match(r'\s*\w+\.add\("(\w+)",\s*\w+,\s*0,\s*"[^"]*",\s*([^,)]+)', line)
            if m:
                out[m.group(1)] = ast.literal_eval(m.group(2).strip())
    return out


def problems(rows, yaml_leaves, cfg):
    bad = []
    for key, value in yaml_leaves.items():
        if key not in rows:
            bad.append("default.yaml key %s is missing" % key)
        elif rows[key][0] != value:
            bad.append("%s: the doc says %r, default.yaml %r" % (key, rows[key][0], value))
    by_name = {name: key for key, (_, name) in rows.items() if name}
    for name, default in cfg.items():
        if name not in by_name:
            bad.append("Steadiface.cfg parameter %s is missing" % name)
        elif rows[by_name[name]][0] != default:
            bad.append("%s (%s): the doc says %r, Steadiface.cfg %r" % (
                name, by_name[name], rows[by_name[name]][0], default))
    return bad


class ParametersDocTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(DOC) as f:
            cls.text = f.read()
        with open(os.path.join(REPO, "config", "default.yaml")) as f:
            cls.yaml = leaves(yaml.safe_load(f))
        cls.cfg = cfg_defaults()

    def test_every_key_and_default_is_documented(self):
        rows = doc_rows(self.text)
        self.assertGreater(len(self.yaml), 100)
        self.assertGreater(len(self.cfg), 40)
        bad = problems(rows, self.yaml, self.cfg)
        self.assertEqual(bad, [], "docs/parameters.md disagrees:\n  " + "\n  ".join(bad))

    def test_a_missing_key_or_a_changed_default_is_caught(self):
        rows = doc_rows(self.text)
        dropped = dict(rows)
        del dropped["weights/fit"]
        self.assertIn("default.yaml key weights/fit is missing", problems(dropped, self.yaml, {}))
        self.assertIn("Steadiface.cfg parameter w_fit is missing",
                      problems(dropped, {}, self.cfg))
        changed = dict(rows)
        changed["head/w_stay"] = (20000.0, changed["head/w_stay"][1])
        bad = problems(changed, self.yaml, self.cfg)
        self.assertIn("head/w_stay: the doc says 20000.0, default.yaml 5000.0", bad)
        self.assertIn("head_w_stay (head/w_stay): the doc says 20000.0, Steadiface.cfg 5000.0", bad)

    def test_every_generated_file_is_what_the_table_says(self):
        r = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "dev", "gen_parameters.py"),
                            "--check"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)

    def test_a_bad_row_is_refused_and_a_change_reaches_every_file(self):
        sys.path.insert(0, os.path.join(REPO, "scripts", "dev"))
        import gen_parameters as g
        sections = g.load_table()
        before = g.render_all(sections)
        row = next(e for s in sections for e in s["keys"] if e["key"] == "weights/fit")
        row["max"] = 5.0  # the default (100) would lie outside the range
        with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
            yaml.safe_dump(sections, f)
        try:
            with self.assertRaises(SystemExit):
                g.load_table(f.name)
        finally:
            os.remove(f.name)
        row["max"] = 1.0e7  # a valid change: the range reaches the node, the .cfg and the doc
        after = g.render_all(sections)
        for name in ("cfg", "inc", "doc"):
            self.assertNotEqual(before[name], after[name], name)
        self.assertIn('"weights/fit", ParameterType::kDouble, 0.0, 10000000.0', after["inc"])
        self.assertIn('"w_fit", double_t, 0', after["cfg"])
        self.assertIn("100.0, 0.0, 10000000.0)", after["cfg"])

if __name__ == "__main__":
    sys.exit(run_main(ParametersDocTest, "parameters_doc"))

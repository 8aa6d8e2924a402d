#!/usr/bin/env python3
"""No function in the package's C++ or Python (libraries, tools,
benchmarks, tests and their helpers, scripts) is longer than 80 lines,
except those listed in scripts/dev/function_length_allowlist.txt, which may
not grow and leave the list once split (a ratchet). The line counter is
checked first on C++ and Python text whose function lengths are known.

usage: function_length_test.py [--junit FILE]
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
import function_lengths as fl  # noqa: E402

ALLOW = os.path.join(REPO, "scripts", "dev", "function_length_allowlist.txt")


def body(n):
    """n - 2 statement lines: with its braces' lines, n lines."""
    return "".join("  x += %d;\n" % k for k in range(n - 2))


KNOWN = (
    "namespace a {\n"
    "// a comment with a brace { and a call f() {\n"
    "int Short(int x) {\n" + body(5) + "}\n"
    "void Klass::Method(const std::vector<int>& v,\n"
    "                   double (*g)(double)) const {\n"
    "  auto lambda = [&](int y) {\n"
    "    if (y > 0) {\n"
    "      return \"}}}\";\n"
    "    }\n"
    "    return std::string(\"{\");\n"
    "  };\n"
    "  for (int i = 0; i < 3; ++i) {\n"
    "    lambda(i);\n"
    "  }\n" + body(12) + "}\n"
    "Klass::Klass(int a) : a_(a), b_(Make(a)) {\n" + body(7) + "}\n"
    "struct Local {\n"
    "  int Get() const { return 1; }\n"
    "};\n"
    "}  // namespace a\n"
)


class FunctionLengthTest(unittest.TestCase):
    def test_counts_known_functions(self):
        found = {name: n for name, _, _, n in fl.functions(KNOWN)}
        # Method: its 2-line signature is not counted, its braces' lines
        # are; the lambda, the if and the for belong to it.
        self.assertEqual(found, {"Short": 5, "Klass::Method": 21, "Klass::Klass": 7, "Get": 1})

    def test_counts_python_functions_and_names_gtest_cases(self):
        py = "def f(x):\n" + "    x += 1\n" * 5 + "\n\ndef g():\n    def h():\n        pass\n    return h\n"
        found = {name: n for name, _, _, n in fl.python_functions(py)}
        self.assertEqual(found, {"f": 6, "g": 4, "h": 2})
        cc = "TEST(Suite, Name) {\n" + body(4) + "}\n"
        self.assertEqual([(n, k) for n, _, _, k in fl.functions(cc)], [("Suite.Name", 4)])

    def test_ratchet_rejects_new_grown_and_stale_entries(self):
        found = {("a.cc", "F"): 90, ("a.cc", "G"): 100}
        self.assertEqual(fl.ratchet_errors(found, {("a.cc", "F"): 90, ("a.cc", "G"): 100}, 80), [])
        self.assertEqual(len(fl.ratchet_errors(found, {("a.cc", "F"): 90}, 80)), 1)  # G is new
        self.assertEqual(len(fl.ratchet_errors(found, {("a.cc", "F"): 85, ("a.cc", "G"): 100}, 80)), 1)
        stale = {("a.cc", "F"): 90, ("a.cc", "G"): 100, ("b.cc", "H"): 120}
        self.assertEqual(len(fl.ratchet_errors(found, stale, 80)), 1)

    def test_a_new_long_function_fails_the_repository_check(self):
        with tempfile.TemporaryDirectory() as root:
            src = os.path.join(root, "steadiface_core", "src")
            os.makedirs(src)
            with open(os.path.join(src, "x.cc"), "w") as fh:
                fh.write("void Long() {\n" + body(81) + "}\nvoid Fine() {\n" + body(80) + "}\n")
            tools = os.path.join(root, "scripts", "dev")
            os.makedirs(tools)
            with open(os.path.join(tools, "tool"), "w") as fh:  # a script without .py
                fh.write("#!/usr/bin/env python3\ndef main():\n" + "    pass\n" * 80)
            build = os.path.join(root, "build", "gen")
            os.makedirs(build)
            with open(os.path.join(build, "y.cc"), "w") as fh:  # skipped
                fh.write("void Generated() {\n" + body(90) + "}\n")
            found = fl.long_functions(root, 80)
            self.assertEqual(found, {("steadiface_core/src/x.cc", "Long"): 81,
                                     (os.path.join("scripts", "dev", "tool"), "main"): 81})

    def test_repository_keeps_to_the_allowlist(self):
        found = fl.long_functions(REPO, 80)
        errors = fl.ratchet_errors(found, fl.read_allow(ALLOW), 80)
        self.assertEqual(errors, [], "\n".join(errors))


if __name__ == "__main__":
    sys.exit(run_main(FunctionLengthTest, "packaging.function_length"))

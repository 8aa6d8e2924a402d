#!/usr/bin/env python3
"""Lengths of the functions in the package: C++ (.cc and .h: libraries,
tools, benchmarks, tests and their helpers) and Python (.py, and scripts
whose first line names python).

A C++ function is a brace block opened right after a parameter list (optionally
followed by const, override, noexcept, a trailing return type or a
constructor's initializer list) outside any other function; its length is
the number of lines from the line of its opening brace to that of its closing
brace. Comments, string and character literals are blanked first, so braces
in them do not count. Lambdas and control blocks belong to their function.
A Python function (def, at any depth) runs from its def line to its last
line; a nested def counts within its parent too. Build, devel and install
spaces and .git are skipped.

usage: function_lengths.py [--max N] [--allow FILE] [--write-allow FILE] [ROOT]
  Prints every function longer than N lines (default 80), longest first.
  --allow FILE: exits 1 when a function longer than N is not in FILE, or is
  longer than FILE records for it, or FILE lists one that is no longer over
  N (a ratchet: split functions leave the list, none may join or grow).
  --write-allow FILE: writes the current list in FILE's format.
"""
import ast
import os
import re
import sys

SKIP_DIRS = re.compile(r"^(\.git|build.*|devel.*|install.*|out|data|__pycache__|node_modules)$")
SIGNATURE = re.compile(
    r"([A-Za-z_~][A-Za-z_0-9]*(?:::[A-Za-z_~][A-Za-z_0-9]*)*)\s*"
    r"\((?:[^(){};]|\((?:[^()]|\([^()]*\))*\))*\)\s*"
    r"(?:const\s*)?(?:override\s*)?(?:noexcept\s*)?(?:->\s*[^{;]+?)?\s*"
    r"(?::[^{;]*)?$",
    re.S,
)
TEST_MACROS = {"TEST", "TEST_F", "TEST_P", "BENCHMARK_F"}
NOT_FUNCTIONS = {"if", "for", "while", "switch", "catch", "return", "sizeof", "decltype"}


def blank(src):
    """`src` with comments and literals replaced by blanks (newlines kept)."""
    out = []
    i, n = 0, len(src)
    while i < n:
        c = src[i]
        if src.startswith("//", i):
            j = src.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif src.startswith("/*", i):
            j = src.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("".join(ch if ch == "\n" else " " for ch in src[i:j]))
            i = j
        elif src.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', src[i:])
            end = src.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append("".join(ch if ch == "\n" else " " for ch in src[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and src[j] != c and src[j] != "\n":
                j += 2 if src[j] == "\\" else 1
            out.append(c + " " * (j - i - 1) + (c if j < n else ""))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(text):
    """[(name, first_line, last_line, lines)] of the functions in C++ `text`."""
    s = blank(text)
    found, stack = [], []  # stack of (is_function, line, name)
    line = 1
    for i, c in enumerate(s):
        if c == "\n":
            line += 1
        elif c == "{":
            name = None
            if not any(f for f, _, _ in stack):
                m = SIGNATURE.search(s[max(0, i - 3000):i])
                if m and m.group(1).split("::")[-1] not in NOT_FUNCTIONS:
                    name = m.group(1)
                    if name in TEST_MACROS:  # TEST(Suite, Name): the test's name
                        args = re.match(r"\w+\s*\(([^)]*)\)", m.group(0))
                        name = ".".join(a.strip() for a in args.group(1).split(","))
            stack.append((name is not None, line, name))
        elif c == "}" and stack:
            is_function, first, name = stack.pop()
            if is_function:
                found.append((name, first, line, line - first + 1))
    return found


def python_functions(text):
    """[(name, first_line, last_line, lines)] of the defs in Python `text`."""
    found = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            found.append((node.name, node.lineno, node.end_lineno,
                          node.end_lineno - node.lineno + 1))
    return found


def is_python(path):
    if path.endswith(".py"):
        return True
    if os.path.splitext(path)[1]:
        return False
    try:
        with open(path, "rb") as fh:
            first = fh.readline(200)
    except OSError:
        return False
    return first.startswith(b"#!") and b"python" in first


def source_files(root):
    """(path, kind) of every C++ and Python file under root."""
    for dirpath, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if not SKIP_DIRS.match(d))
        for f in sorted(files):
            path = os.path.join(dirpath, f)
            if f.endswith((".cc", ".h", ".cpp", ".hpp")):
                yield path, "c++"
            elif is_python(path):
                yield path, "python"


def long_functions(root, limit):
    """{(path, name): lines} of the functions longer than `limit` lines."""
    result = {}
    for path, kind in source_files(root):
        with open(path, encoding="utf-8") as fh:
            text = fh.read()
        found = functions(text) if kind == "c++" else python_functions(text)
        for name, _, _, n in found:
            if n > limit:
                key = (os.path.relpath(path, root), name)
                result[key] = max(n, result.get(key, 0))
    return result


def read_allow(path):
    allow = {}
    with open(path, encoding="utf-8") as fh:
        for raw in fh:
            raw = raw.split("#", 1)[0].strip()
            if raw:
                n, path_, name = raw.split()
                allow[(path_, name)] = int(n)
    return allow


def ratchet_errors(found, allow, limit):
    """Messages for functions over `limit` that the allowlist does not
    permit, and for allowlist entries that are stale."""
    errors = []
    for key, n in sorted(found.items()):
        if key not in allow:
            errors.append("%s: %s has %d lines (max %d)" % (key[0], key[1], n, limit))
        elif n > allow[key]:
            errors.append("%s: %s grew to %d lines (listed at %d)" % (key[0], key[1], n, allow[key]))
    for key, n in sorted(allow.items()):
        if key not in found:
            errors.append("%s: %s is listed but no longer over %d lines: remove it" % (key[0], key[1], limit))
    return errors


def main(argv):
    limit, allow_path, write_path, root = 80, None, None, None
    it = iter(argv)
    for a in it:
        if a == "--max":
            limit = int(next(it))
        elif a == "--allow":
            allow_path = next(it)
        elif a == "--write-allow":
            write_path = next(it)
        else:
            root = a
    root = root or os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    found = long_functions(root, limit)
    for (path, name), n in sorted(found.items(), key=lambda kv: -kv[1]):
        print("%4d %s %s" % (n, path, name))
    print("%d functions over %d lines" % (len(found), limit))
    if write_path:
        with open(write_path, "w", encoding="utf-8") as fh:
            fh.write("# Functions over %d lines, to be split (scripts/dev/function_lengths.py).\n"
                     "# A ratchet: none may join or grow; a split one must leave.\n" % limit)
            for (path, name), n in sorted(found.items(), key=lambda kv: -kv[1]):
                fh.write("%d %s %s\n" % (n, path, name))
    if allow_path:
        errors = ratchet_errors(found, read_allow(allow_path), limit)
        for e in errors:
            print("error: " + e, file=sys.stderr)
        return 1 if errors else 0
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

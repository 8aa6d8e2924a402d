#!/usr/bin/env python3
"""The core's modules may only include modules below them (earlier rows).

The order is the one docs/design.md draws: the rows of its table under
"### The core's folders", top row lowest (common), each row one folder. A
file in module M (steadiface_core/include/steadiface_core/M/... or
steadiface_core/src/M/...) may include "steadiface_core/N/..." only for N == M
or N on a row above M's; a private header in quotes ("warp/mesh_scanline.h",
under src/warp/) counts as its module's. Nothing in steadiface_core may include a
steadiface_ros header or a ROS one.

usage: include_graph.py [--graph] [ROOT]
  Prints every include that points up, as "file:line: M includes N (N comes
  after M in docs/design.md's folder table: an upward include)", and exits 1
  if there is one. --graph also prints each module's includes.
"""
import os
import re
import sys

CORE = "steadiface_core"
MODULE_DIRS = (os.path.join(CORE, "include", "steadiface_core"), os.path.join(CORE, "src"))
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')
TABLE_HEADING = "### The core's folders"
ROW = re.compile(r"^\|\s*`([a-z_]+)/`\s*\|")
FORBIDDEN_PREFIXES = ("steadiface_ros/", "ros/", "nodelet/", "pluginlib/", "dynamic_reconfigure/")


def module_order(design_md):
    """The folders of design.md's table, lowest first."""
    order, in_table = [], False
    for line in design_md.splitlines():
        if line.startswith("### "):
            in_table = line.strip() == TABLE_HEADING
            continue
        if in_table:
            m = ROW.match(line)
            if m:
                order.append(m.group(1))
    return order


def includes_of(text):
    """(line number, included path, quoted?) for every #include in `text`."""
    out = []
    for n, line in enumerate(text.splitlines(), 1):
        m = INCLUDE.match(line)
        if m:
            out.append((n, m.group(2), m.group(1) == '"'))
    return out


def included_module(inc, quoted, rank):
    """The core module `inc` names: steadiface_core/M/... (public), or M/...
    in quotes (a private header under src/M/); None for anything else."""
    parts = inc.split("/")
    if len(parts) >= 3 and parts[0] == "steadiface_core":
        return parts[1]
    if quoted and len(parts) >= 2 and parts[0] in rank:
        return parts[0]
    return None


def core_files(root):
    """(module, path relative to root) of every file under the module dirs."""
    for base in MODULE_DIRS:
        top = os.path.join(root, base)
        for dirpath, _, files in os.walk(top):
            rel = os.path.relpath(dirpath, top)
            if rel == ".":
                continue  # loose files belong to no module
            module = rel.split(os.sep)[0]
            for f in sorted(files):
                if f.endswith((".h", ".cc", ".hpp", ".cpp", ".inc")):
                    yield module, os.path.relpath(os.path.join(dirpath, f), root)


def violations(root, order):
    """Every include that breaks the order, and the module graph."""
    rank = {m: i for i, m in enumerate(order)}
    errors, graph = [], {}
    for module, path in core_files(root):
        if module not in rank:
            errors.append("%s: module '%s' is not a row of docs/design.md's folder table"
                          % (path, module))
            continue
        with open(os.path.join(root, path), errors="replace") as fh:
            text = fh.read()
        for line, inc, quoted in includes_of(text):
            if inc.startswith(FORBIDDEN_PREFIXES):
                errors.append("%s:%d: the core includes %s" % (path, line, inc))
                continue
            target = included_module(inc, quoted, rank)
            if target is None:
                continue
            graph.setdefault(module, set()).add(target)
            if target == module:
                continue
            if target not in rank:
                errors.append("%s:%d: includes %s of unknown module '%s'" % (path, line, inc, target))
            elif rank[target] > rank[module]:
                errors.append("%s:%d: %s includes %s (%s comes after %s in docs/design.md's "
                              "folder table: an upward include)"
                              % (path, line, module, inc, target, module))
    return errors, graph


def main(argv):
    args = [a for a in argv if not a.startswith("--")]
    root = args[0] if args else os.path.dirname(os.path.dirname(os.path.dirname(
        os.path.abspath(__file__))))
    with open(os.path.join(root, "docs", "design.md")) as fh:
        order = module_order(fh.read())
    errors, graph = violations(root, order)
    if "--graph" in argv:
        for m in order:
            deps = sorted(graph.get(m, set()) - {m}, key=order.index)
            print("%-12s -> %s" % (m, ", ".join(deps)))
    for e in errors:
        print(e)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

#!/usr/bin/env python3
"""Writes docs/parameters.md, the reference of every ~parameter, from the
files that define them:

- config/default.yaml: each key, its default (the YAML value) and its
  meaning and unit (the key's comment: "meaning [unit] (default)");
- steadiface_ros/src/params.cc: the range each key is checked against when
  the node or steadiface_bag reads it (r.Num / r.Int);
- config/Steadiface.cfg: which keys dynamic_reconfigure changes at run time,
  under which name and within which range (joined to the YAML keys through
  the options field both set, read from params.cc's ConfigFromOptions).

usage: gen_parameters_doc.py [--check]
  --check  write nothing; exit 1 when docs/parameters.md differs from what
           this script would write (CI runs it).
"""
import ast
import os
import re
import sys

import yaml

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_YAML = os.path.join(REPO, "config", "default.yaml")
CFG = os.path.join(REPO, "config", "Steadiface.cfg")
PARAMS_CC = os.path.join(REPO, "steadiface_ros", "src", "params.cc")
OUT = os.path.join(REPO, "docs", "parameters.md")

# params.cc's local aliases -> the PipelineOptions / WrapperOptions path.
READER_ALIASES = {"po->": "", "wo->": "wrapper.", "s.": "stabilizer.", "f.": "face.",
                  "lw.": "warp.layered.", "c.": "gyro_video_check."}
CONFIG_ALIASES = {"o.": "stabilizer.", "w.": "warp."}
# Keys params.cc reads into a local before parsing it.
LOCAL_FIELDS = {"warp/mode": "warp.mode"}


def yaml_entries():
    """[(key, comment, section title)] in file order; nested keys joined by '/'."""
    entries, stack, section, header, pending = [], [], "", None, []
    for line in open(DEFAULT_YAML):
        stripped = line.strip()
        if not stripped:
            pending = []
            continue
        if stripped.startswith("#"):
            m = re.match(r"#\s*-+\s*(.*?)\s*-*$", stripped)
            if m and stripped.startswith("# ----"):
                header, pending = m.group(1), []
            else:
                pending.append(stripped.lstrip("#").strip())
            continue
        indent = len(line) - len(line.lstrip(" "))
        m = re.match(r"([A-Za-z_][A-Za-z0-9_]*):\s*(.*)$", stripped)
        if not m:
            continue
        name, rest = m.groups()
        if indent == 0 and (header is not None or split_comment(rest)[0] == ""):
            # A top-level block: under the header just above it, else its name.
            section, header = (header if header is not None else name), None
        while stack and stack[-1][0] >= indent:
            stack.pop()
        value, comment = split_comment(rest)
        if value == "":
            stack.append((indent, name))
            pending = [comment] if comment else pending
            continue
        key = "/".join([s[1] for s in stack] + [name])
        text = comment or " ".join(pending)
        entries.append((key, text, section or (stack[0][1] if stack else "")))
        pending = []
    return entries


def split_comment(rest):
    """'value  # comment' -> (value, comment), '#' inside quotes kept."""
    quote = None
    for i, ch in enumerate(rest):
        if ch in "\"'" and quote is None:
            quote = ch
        elif ch == quote:
            quote = None
        elif ch == "#" and quote is None:
            return rest[:i].strip(), rest[i + 1:].strip()
    return rest.strip(), ""


def lookup(doc, key):
    for part in key.split("/"):
        doc = doc[part]
    return doc


def normalize(expr, aliases):
    expr = expr.strip().lstrip("&")
    for prefix, full in aliases.items():
        if expr.startswith(prefix):
            return full + expr[len(prefix):]
    return expr


def reader_fields():
    """{yaml key: (options field, lo, hi)} from params.cc's reader calls."""
    src = open(PARAMS_CC).read()
    out = {}
    for kind, key, rest in re.findall(r'r\.(Num|Int|Bool|Str|Path|Vec)\("([^"]+)",\s*([^;]*)\);', src):
        args = [a.strip() for a in rest.split(",")]
        field = normalize(args[0], READER_ALIASES)
        lo = hi = None
        if kind in ("Num", "Int") and len(args) == 3:
            lo, hi = args[1], args[2]
        out[key] = (LOCAL_FIELDS.get(key, field), lo, hi)
    return out


def config_fields():
    """{options field: cfg name} from params.cc's ConfigFromOptions."""
    src = open(PARAMS_CC).read()
    body = src[src.index("ConfigFromOptions("):]
    out = {}
    for name, expr in re.findall(r"\bc\.(\w+)\s*=\s*([^;]+);", body):
        m = re.search(r"\(([^()]*)\)\s*$", expr)  # WarpModeName(w.mode)
        out[normalize(m.group(1) if m else expr, CONFIG_ALIASES)] = name
    return out


def cfg_params():
    """{cfg name: (description, default, lo, hi)} from Steadiface.cfg."""
    out = {}
    for line in open(CFG):
        m = re.match(r'\s*\w+\.add\("(\w+)",\s*(\w+),\s*0,\s*"([^"]*)",\s*(.*)\)\s*$', line)
        if not m:
            continue
        name, _, desc, rest = m.groups()
        rest = re.sub(r",\s*edit_method=\w+", "", rest)
        vals = [ast.literal_eval(v.strip()) for v in rest.split(",")]
        vals += [None] * (3 - len(vals))
        out[name] = (desc, vals[0], vals[1], vals[2])
    return out


def fmt(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"%s"' % v
    if isinstance(v, float):  # as YAML reads it back: 1.0e-06, not 1e-06
        mantissa, e, exp = repr(v).partition("e")
        return mantissa + (".0" if e and "." not in mantissa else "") + e + exp
    return str(v)


def unit_of(comment):
    m = re.search(r"\[([^\]]+)\]", comment)
    return m.group(1) if m else ""


def restates(inner, value):
    """Whether "(inner)" at a comment's end restates the default `value`."""
    first = re.split(r"[;,]|\s", inner.strip(), maxsplit=1)[0].strip("\"'")
    if isinstance(value, bool):
        return first.lower() == str(value).lower()
    if isinstance(value, (int, float)):
        try:
            return float(first) == float(value)
        except ValueError:
            return False
    return first == str(value)


def meaning_of(comment, value):
    text = re.sub(r"\s*\[[^\]]+\]", "", comment, count=1)
    m = re.search(r"\s*\(([^()]*)\)\s*$", text)
    if m and restates(m.group(1), value):
        text = text[:m.start()]
    return text.replace("|", "\\|").strip() or "-"


def rows():
    doc = yaml.safe_load(open(DEFAULT_YAML))
    readers, to_cfg, cfg = reader_fields(), config_fields(), cfg_params()
    out = []
    for key, comment, section in yaml_entries():
        field, lo, hi = readers.get(key, (None, None, None))
        name = to_cfg.get(field) if field else None
        runtime = "no"
        if name in cfg:
            _, _, clo, chi = cfg[name]
            runtime = "yes: `%s`" % name + ("" if clo is None else " [%s, %s]" % (fmt(clo), fmt(chi)))
        rng = "[%s, %s]" % (lo, hi) if lo is not None else "-"
        value = lookup(doc, key)
        out.append((section, key, meaning_of(comment, value), unit_of(comment), fmt(value),
                    rng, runtime, name))
    return out, cfg


def render():
    table, cfg = rows()
    lines = ["# Parameters", "",
             "Every private parameter of the stabilizer (`steadiface_node`, the nodelet",
             "`steadiface/StabilizerNodelet` and `steadiface_bag --params`), as",
             "`config/default.yaml` states it. **Generated** by",
             "`scripts/dev/gen_parameters_doc.py` from `config/default.yaml`,",
             "`config/Steadiface.cfg` and `steadiface_ros/src/params.cc`; do not edit by",
             "hand (CI fails when this file is stale).", "",
             "- **default**: the value in `config/default.yaml`, which the launch files",
             "  load before your overlay (`stabilize.launch params:=my.yaml`).",
             "- **range**: values outside it are refused when the node starts, with a",
             "  message naming the key.",
             "- **run time**: the `dynamic_reconfigure` name (`rosrun rqt_reconfigure",
             "  rqt_reconfigure`) and its slider range; \"no\" means: set it before",
             "  start.", ""]
    section = None
    for sec, key, meaning, unit, default, rng, runtime, _ in table:
        if sec != section:
            lines += ["## %s" % (sec[0].upper() + sec[1:] if sec else "General"), "",
                      "| key | meaning | unit | default | range | run time |",
                      "|---|---|---|---|---|---|"]
            section = sec
        lines.append("| `%s` | %s | %s | `%s` | %s | %s |" % (key, meaning, unit or "-", default,
                                                          rng, runtime))
    out = []
    for line in lines:  # a blank line before each new heading
        if line.startswith("## ") and out and out[-1] != "":
            out.append("")
        out.append(line)
    mapped = {r[7] for r in table if r[7]}
    orphans = sorted(set(cfg) - mapped)
    if orphans:
        raise SystemExit("gen_parameters_doc: Steadiface.cfg parameters with no "
                         "default.yaml key: %s" % ", ".join(orphans))
    return "\n".join(out) + "\n"


def main():
    text = render()
    if "--check" in sys.argv:
        current = open(OUT).read() if os.path.exists(OUT) else ""
        if current != text:
            print("docs/parameters.md is stale: run scripts/dev/gen_parameters_doc.py")
            return 1
        print("docs/parameters.md is current")
        return 0
    with open(OUT, "w") as f:
        f.write(text)
    print("wrote %s" % os.path.relpath(OUT, REPO))
    return 0


if __name__ == "__main__":
    sys.exit(main())

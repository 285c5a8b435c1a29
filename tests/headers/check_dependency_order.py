#!/usr/bin/env python3
"""Fails when a header of include/arbor includes a header of a module above its own.

Module order (each may include itself and the modules to its left; every module may include core):

    core <- model <- spatial <- dynamics <- derivatives <- ad <- ocp <- nmpc

qp depends on core only (it may include core and qp, nothing else); ocp and nmpc may include qp,
the modules below them may not. Headers directly in include/arbor (umbrella headers) may include
any module. A header in a folder that is not a module is reported too (add the module here).

Usage: check_dependency_order.py <include-dir> [<base-dir for the printed paths>]
Prints one line per offending include (file:line: from -> to (#include ...)), exit status 1 if
there is any, 0 otherwise. Direct includes only (the order is transitive). Comments are ignored.
"""
import os
import re
import sys

ORDER = ["core", "model", "spatial", "dynamics", "derivatives", "ad", "ocp", "nmpc"]
QP_USERS = {"ocp", "nmpc"}
MODULES = set(ORDER) | {"qp"}


def allowed(src, dst):
    if src == dst or dst == "core" or src is None:
        return True
    if src == "qp":
        return False
    if dst == "qp":
        return src in QP_USERS
    return ORDER.index(dst) < ORDER.index(src)


def strip_comments(text):
    """Removes // and /* */ comments, keeping the newlines (line numbers)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        else:
            out.append(text[i])
            i += 1
    return "".join(out)


INCLUDE = re.compile(r'^[ \t]*#[ \t]*include[ \t]*([<"])([^>"]+)[>"]', re.M)


def module_of(rel):
    """Module of a path relative to include/arbor: its first folder, None for umbrella headers."""
    parts = rel.split("/")
    return parts[0] if len(parts) > 1 else None


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    include_dir = os.path.abspath(argv[1])
    base = os.path.abspath(argv[2]) if len(argv) > 2 else os.path.dirname(include_dir)
    root = os.path.join(include_dir, "arbor")
    if not os.path.isdir(root):
        print(f"check_dependency_order: no folder {root}")
        return 2
    problems, checked_headers, checked_includes = [], 0, 0
    for dirpath, _, files in sorted(os.walk(root)):
        for f in sorted(files):
            if not f.endswith((".hpp", ".h")):
                continue
            path = os.path.join(dirpath, f)
            rel = os.path.relpath(path, root).replace(os.sep, "/")
            shown = os.path.relpath(path, base)
            src = module_of(rel)
            checked_headers += 1
            if src is not None and src not in MODULES:
                problems.append(f"{shown}:1: '{src}' is not a module of the dependency order")
                continue
            with open(path, encoding="utf-8") as fh:
                text = strip_comments(fh.read())
            for m in INCLUDE.finditer(text):
                name = m.group(2).strip()
                target = None
                if name.startswith("arbor/"):
                    target = name[len("arbor/"):]
                elif m.group(1) == '"':
                    # a quoted include relative to the including header, if it resolves there
                    cand = os.path.normpath(os.path.join(dirpath, name))
                    if os.path.isfile(cand) and cand.startswith(root + os.sep):
                        target = os.path.relpath(cand, root).replace(os.sep, "/")
                if target is None:
                    continue  # not an arbor header (Eigen, the standard library, ...)
                checked_includes += 1
                dst = module_of(target)
                line = text.count("\n", 0, m.start()) + 1
                spelled = m.group(1) + name + (">" if m.group(1) == "<" else '"')
                if dst is not None and dst not in MODULES:
                    problems.append(f"{shown}:{line}: {src} -> '{dst}', not a module "
                                    f"(#include {spelled})")
                elif dst is None and src is not None:
                    problems.append(f"{shown}:{line}: {src} -> an umbrella header "
                                    f"(#include {spelled})")
                elif dst is not None and not allowed(src, dst):
                    problems.append(f"{shown}:{line}: {src} -> {dst} (#include {spelled})")
    for p in problems:
        print(p)
    order = " <- ".join(ORDER) + "; qp <- core only"
    if problems:
        print(f"check_dependency_order: {len(problems)} include(s) against the module order "
              f"({order})")
        return 1
    print(f"check_dependency_order: {checked_headers} headers, {checked_includes} includes of "
          f"arbor headers, all in the module order ({order})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

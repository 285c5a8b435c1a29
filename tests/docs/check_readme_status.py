#!/usr/bin/env python3
"""Checks that the figures of README.md's status table are those of the benchmark tables.

Each claim below names a row of the status table (by the start of its first cell), a pattern
that must occur in that row, and the values the pattern's groups must hold, computed from a
table of a benchmark RESULTS file. The RESULTS files put the newest section first, so each table
is the first one of its file whose header has the named columns. A figure that no longer matches
(a benchmark re-run, a README left behind) fails the check with both values printed.

Usage: check_readme_status.py <source-dir>            check README.md
       check_readme_status.py <source-dir> --self-test  alter each checked figure of README.md in
                                                        turn (in memory): every one must be caught
"""
import os
import re
import sys

ARMS = ("iiwa7", "kinova_gen3", "yumi_no_grippers")
RBD = ("rnea", "crba", "aba", "minverse")
FIRST_ORDER = ("rnea_derivatives", "aba_derivatives")


def tables(text):
    """Every markdown table of `text` as (header cells, rows of cells), in document order."""
    out, lines, i = [], text.splitlines(), 0
    cells = lambda l: [c.strip() for c in l.strip().strip("|").split("|")]
    while i < len(lines):
        if lines[i].startswith("|") and i + 1 < len(lines) and re.match(r"^\|[-:| ]+\|$",
                                                                        lines[i + 1].strip()):
            header, rows, i = cells(lines[i]), [], i + 2
            while i < len(lines) and lines[i].startswith("|"):
                rows.append(cells(lines[i]))
                i += 1
            out.append((header, rows))
        else:
            i += 1
    return out


def first_table(text, columns, what):
    for header, rows in tables(text):
        if all(c in header for c in columns):
            return [dict(zip(header, r)) for r in rows]
    raise LookupError(f"{what}: no table with the columns {columns}")


def number(cell):
    """The last number of a cell ('3.52 -> **3.49 us**' -> 3.49, '6 621' -> 6621)."""
    found = re.findall(r"\d[\d ]*(?:\.\d+)?", cell.replace("**", ""))
    if not found:
        raise ValueError(f"no number in '{cell}'")
    return float(found[-1].replace(" ", ""))


def pinocchio_ratios(src, kernels, robots):
    """Pinocchio / arbor instructions of the newest before/after table of bench/RESULTS.md, for
    these kernels and robots; its 'ratio after' column must agree with the counts."""
    rows = first_table(src["bench/RESULTS.md"], ("kernel", "Pinocchio 3.7.0", "after",
                                                 "ratio after"), "bench/RESULTS.md")
    ratios = []
    for r in rows:
        if r["robot"] in robots and r["kernel"] in kernels:
            ratio = number(r["Pinocchio 3.7.0"]) / number(r["after"])
            if abs(ratio - number(r["ratio after"])) > 0.0051:
                raise ValueError(f"bench/RESULTS.md: {r['robot']} {r['kernel']}: ratio after "
                                 f"{r['ratio after']} is not {number(r['Pinocchio 3.7.0'])} / "
                                 f"{number(r['after'])} = {ratio:.2f}")
            ratios.append(ratio)
    if len(ratios) != len(kernels) * len(robots):
        raise LookupError(f"bench/RESULTS.md: {len(ratios)} rows for {kernels} x {robots}")
    return [f"{min(ratios):.2f}", f"{max(ratios):.2f}"]


def second_order(src, column):
    rows = first_table(src["bench/derivatives/RESULTS.md"], ("robot", "H_ID time", "H_FD time"),
                       "bench/derivatives/RESULTS.md")
    return f"{number(next(r for r in rows if r['robot'] == 'kinova_gen3')[column]):.2f}"


def generated_ad(src, row, column):
    rows = first_table(src["bench/ad/RESULTS.md"], ("generated AD (H^g) us", "paper AD us"),
                       "bench/ad/RESULTS.md")
    return next(r for r in rows if r[""] == row)[column]


# (status row: start of its first cell, pattern in the row, values of its groups)
CLAIMS = [
    ("spatial algebra", r"(\d+\.\d+)x-(\d+\.\d+)x fewer instructions than Pinocchio on the arms",
     lambda s: pinocchio_ratios(s, RBD, ARMS)),
    ("spatial algebra", r"(\d+\.\d+)x-(\d+\.\d+)x on Atlas",
     lambda s: pinocchio_ratios(s, RBD, ("atlas",))),
    ("first-order analytical derivatives",
     r"(\d+\.\d+)x-(\d+\.\d+)x fewer instructions than Pinocchio on the arms",
     lambda s: pinocchio_ratios(s, FIRST_ORDER, ARMS)),
    ("first-order analytical derivatives", r"(\d+\.\d+)x-(\d+\.\d+)x on Atlas",
     lambda s: pinocchio_ratios(s, FIRST_ORDER, ("atlas",))),
    ("second-order analytical derivatives", r"H_ID (\d+\.\d+) us, H_FD (\d+\.\d+) us",
     lambda s: [second_order(s, "H_ID time"), second_order(s, "H_FD time")]),
    ("generated AD", r"H_ID (\d+\.\d+) us, H_FD (\d+\.\d+) us \(the paper's AD: (\d+\.\d+) and "
     r"(\d+\.\d+) us\)",
     lambda s: [generated_ad(s, "H_ID", "generated AD (H^g) us"),
                generated_ad(s, "H_FD", "generated AD (H^g) us"),
                generated_ad(s, "H_ID", "paper AD us"), generated_ad(s, "H_FD", "paper AD us")]),
]


def status_rows(readme):
    text = readme.split("\n## Status", 1)[1].split("\n## ", 1)[0]
    return [l for l in text.splitlines() if l.startswith("| ")]


def check(readme, src):
    """Problems found (empty: every figure matches), and how many figures were checked."""
    problems, checked = [], 0
    rows = status_rows(readme)
    for key, pattern, expected in CLAIMS:
        row = [l for l in rows if l[2:].lstrip("`").startswith(key)]
        if len(row) != 1:
            problems.append(f"README.md status table: {len(row)} rows start with '{key}'")
            continue
        m = re.search(pattern, row[0])
        if not m:
            problems.append(f"README.md status row '{key}': no '{pattern}'")
            continue
        want = expected(src)
        got = list(m.groups())
        checked += len(got)
        if got != want:
            problems.append(f"README.md status row '{key}': '{m.group(0)}' states {got}, the "
                            f"benchmark tables give {want}")
    return problems, checked


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    root = argv[1]
    read = lambda p: open(os.path.join(root, p), encoding="utf-8").read()
    src = {p: read(p) for p in ("bench/RESULTS.md", "bench/derivatives/RESULTS.md",
                                "bench/ad/RESULTS.md")}
    readme = read("README.md")
    problems, checked = check(readme, src)
    if "--self-test" in argv[2:]:
        if problems:
            print("self-test needs a README that passes:\n  " + "\n  ".join(problems))
            return 1
        missed, altered = [], 0
        for key, pattern, _ in CLAIMS:
            row = next(l for l in status_rows(readme) if l[2:].lstrip("`").startswith(key))
            m = re.search(pattern, row)
            for g in range(1, len(m.groups()) + 1):
                figure = m.group(g)
                decimals = len(figure.split(".")[1])  # one unit more in the last digit
                wrong = f"{float(figure) + 10 ** -decimals:.{decimals}f}"
                bad_row = row[:m.start(g)] + wrong + row[m.end(g):]
                altered += 1
                if not check(readme.replace(row, bad_row), src)[0]:
                    missed.append(f"'{key}': {figure} -> {wrong} not caught")
        for line in missed:
            print(line)
        print(f"check_readme_status self-test: {altered - len(missed)} of {altered} altered "
              f"figures caught")
        return 1 if missed else 0
    for line in problems:
        print(line)
    print(f"check_readme_status: {checked} figures of README.md's status table checked against "
          f"bench/RESULTS.md, bench/derivatives/RESULTS.md, bench/ad/RESULTS.md: "
          + (f"{len(problems)} problem(s)" if problems else "all match"))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

#!/usr/bin/env python3
"""Checks that every figure the README and the docs quote agrees with the one table it comes from.

(a) Every benchmark RESULTS file (bench/**/RESULTS*.md) opens with a "Current figures" table:
    two to five rows, each with its figure, value, commit, machine, build and the command that
    reproduces it.
(b) Every number of a README status row's state cell (backticked names aside) occurs in the
    Current figures table of a RESULTS file the row cites, and a row that quotes a number cites one.
(c) Figures the docs and comments repeat (REPEATS: the interior point's workspace) agree with
    their one source, a Current figures row; the README states one suite time.
(d) CLAIMS below: figures recomputed from the detailed tables of the record.

Each claim below names a row of the status table (by the start of its first cell), a pattern
that must occur in that row, and the values the pattern's groups must hold, computed from a
table of a benchmark RESULTS file. The RESULTS files put the newest section first, so each table
is the first one of its file whose header has the named columns. A figure that no longer matches
(a benchmark re-run, a README left behind) fails the check with both values printed.

Usage: check_readme_status.py <source-dir>            check README.md, the RESULTS files, REPEATS
       check_readme_status.py <source-dir> --self-test  alter each checked figure in turn (in
                                                        memory): every one must be caught
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


# ---- (a) the Current figures tables -------------------------------------------------------------

CURRENT_COLUMNS = ("figure", "value", "commit", "machine", "build (default build?)", "command")


def results_files(root):
    """Every RESULTS*.md under bench/, relative to root (history/ folders hold no current table)."""
    out = []
    for folder, dirs, files in os.walk(os.path.join(root, "bench")):
        dirs[:] = sorted(d for d in dirs if d != "history")
        out += [os.path.relpath(os.path.join(folder, f), root) for f in sorted(files)
                if f.startswith("RESULTS") and f.endswith(".md")]
    return out


def current_table(text, path):
    """The rows (dicts) of the Current figures table that opens `path`, or a problem string."""
    sections = text.split("\n## ")
    if len(sections) < 2 or not sections[1].startswith("Current figures\n"):
        return (f"{path}: its first section is not '## Current figures' (rewritten by its "
                f"generator script? put the table back with the new figures)")
    found = tables("\n" + sections[1])
    if not found:
        return f"{path}: no table under '## Current figures'"
    header, rows = found[0]
    if tuple(header) != CURRENT_COLUMNS:
        return f"{path}: Current figures columns {header}, expected {list(CURRENT_COLUMNS)}"
    if not 2 <= len(rows) <= 5:
        return f"{path}: Current figures has {len(rows)} rows (two to five)"
    for r in rows:
        row = dict(zip(header, r))
        if not re.fullmatch(r"[0-9a-f]{7,40}", row.get("commit", "")):
            return f"{path}: Current figures row '{row.get('figure')}': no commit hash"
        if not row.get("command") or not row.get("value") or not row.get("machine") \
                or not row.get("build (default build?)"):
            return f"{path}: Current figures row '{row.get('figure')}': an empty cell"
    return [dict(zip(header, r)) for r in rows]


def check_current_tables(src):
    out = {}
    problems = []
    for path, text in src.items():
        if not path.startswith("bench/"):
            continue
        got = current_table(text, path)
        if isinstance(got, str):
            problems.append(got)
        else:
            out[path] = got
    return out, problems


# ---- (b) the numbers of the status rows ----------------------------------------------------------

NUMBER = re.compile(r"(?<![\w.])(\d{1,3}(?: \d{3})+(?![\d.])|\d+(?:\.\d+)?)")


def numbers(text):
    """The numbers of `text` as written ('2 996 880' -> '2996880'), none inside a word (Gen3)."""
    return [n.replace(" ", "") for n in NUMBER.findall(text)]


def state_cell(row):
    return row.strip().strip("|").split("|", 1)[1].strip()


def check_status_numbers(readme, current):
    problems, checked = [], 0
    for row in status_rows(readme):
        state = state_cell(row)
        cited = re.findall(r"`(bench/[\w/.-]*RESULTS[\w-]*\.md)`", state)
        quoted = numbers(re.sub(r"`[^`]*`", " ", state))
        if not quoted:
            continue
        name = row[2:42]
        if not cited:
            problems.append(f"README.md status row '{name}...': quotes {quoted} but cites no "
                            f"RESULTS file")
            continue
        known = set()
        for path in cited:
            if path not in current:
                problems.append(f"README.md status row '{name}...': cites {path}, which has no "
                                f"Current figures table")
                continue
            for r in current[path]:
                known.update(numbers(" ".join(r.values())))
        for n in quoted:
            checked += 1
            if n not in known:
                problems.append(f"README.md status row '{name}...': {n} is in no Current figures "
                                f"row of {', '.join(cited)}")
    return problems, checked


# ---- (c) figures repeated in the docs and comments ---------------------------------------------

def ipm_kb(current):
    """The interior point's workspace, double and float, in whole KB, from bench/qp/RESULTS.md."""
    row = next(r for r in current["bench/qp/RESULTS.md"] if "ipm_bytes" in r["figure"])
    double, single = re.findall(r"(\d+(?:\.\d+)?) KB", row["value"])
    return [f"{float(double):.0f}", f"{float(single):.0f}"]


# (file, pattern whose groups repeat a figure, the values from their source). A file whose text
# no longer has the pattern no longer repeats the figure: nothing to check there.
REPEATS = [
    ("docs/api.md", r"`qp::OcpInteriorPoint<Qp>`[^\n]*?\| (\d+) KB / (\d+) KB", ipm_kb),
    ("docs/qp.md", r"~(\d+) KB at the Kinova\s+size in double", lambda c: ipm_kb(c)[:1]),
    ("docs/nmpc.md", r"OcpInteriorPoint<Ctrl::Qp>, ~(\d+) KB", lambda c: ipm_kb(c)[:1]),
    ("include/arbor/qp/ocp_interior_point.hpp", r"~(\d+) KB at the Kinova size in double",
     lambda c: ipm_kb(c)[:1]),
]


def check_repeats(src, current):
    problems, checked = [], 0
    for path, pattern, expected in REPEATS:
        try:
            want = expected(current)
        except (KeyError, StopIteration, ValueError):
            problems.append(f"{path}: the source of '{pattern}' is missing from its Current "
                            f"figures")
            continue
        for m in re.finditer(pattern, src[path]):
            checked += len(m.groups())
            if list(m.groups()) != want:
                problems.append(f"{path}: '{m.group(0)}' states {list(m.groups())}, its source "
                                f"(a Current figures row) gives {want}")
    return problems, checked


def check_suite_time(readme):
    times = re.findall(r"\d+ min \d+ s", readme)
    return [] if len(times) == 1 else [f"README.md states {len(times)} suite times {times} (one: "
                                       f"the newest; the others in bench/history/test-suite.md)"]


def check_all(readme, src):
    current, problems = check_current_tables(src)
    p, checked = check(readme, src)
    problems += p
    for part in (check_status_numbers(readme, current), check_repeats(src, current)):
        problems += part[0]
        checked += part[1]
    problems += check_suite_time(readme)
    return problems, checked


def altered(figure):
    """`figure` with one unit more in its last digit."""
    decimals = len(figure.split(".")[1]) if "." in figure else 0
    return f"{float(figure) + 10 ** -decimals:.{decimals}f}"


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    root = argv[1]
    read = lambda p: open(os.path.join(root, p), encoding="utf-8").read()
    paths = results_files(root) + [p for p, _, _ in REPEATS]
    src = {p: read(p) for p in dict.fromkeys(paths)}
    readme = read("README.md")
    problems, checked = check_all(readme, src)
    if "--self-test" in argv[2:]:
        if problems:
            print("self-test needs a README that passes:\n  " + "\n  ".join(problems))
            return 1
        missed, count = [], 0
        # (d) the recomputed claims
        for key, pattern, _ in CLAIMS:
            row = next(l for l in status_rows(readme) if l[2:].lstrip("`").startswith(key))
            m = re.search(pattern, row)
            for g in range(1, len(m.groups()) + 1):
                wrong = altered(m.group(g))
                bad_row = row[:m.start(g)] + wrong + row[m.end(g):]
                count += 1
                if not check_all(readme.replace(row, bad_row), src)[0]:
                    missed.append(f"'{key}': {m.group(g)} -> {wrong} not caught")
        # (b) every number of every status row's state cell (a number whose altered value is also
        # in the cited table cannot be caught by its presence there: not counted)
        current = check_current_tables(src)[0]
        for row in status_rows(readme):
            state = state_cell(row)
            cited = re.findall(r"`(bench/[\w/.-]*RESULTS[\w-]*\.md)`", state)
            known = {n for p in cited for r in current.get(p, [])
                     for n in numbers(" ".join(r.values()))}
            plain = re.sub(r"`[^`]*`", lambda m: "\0" * len(m.group(0)), state)
            offset = row.index(state)
            for m in NUMBER.finditer(plain):
                if " " in m.group(1):
                    continue
                wrong = altered(m.group(1))
                if wrong in known:
                    continue
                a, b = offset + m.start(1), offset + m.end(1)
                count += 1
                if not check_all(readme.replace(row, row[:a] + wrong + row[b:]), src)[0]:
                    missed.append(f"status row '{row[2:30]}': {m.group(1)} -> {wrong} not caught")
        # (c) every repeated figure
        for path, pattern, _ in REPEATS:
            for m in re.finditer(pattern, src[path]):
                for g in range(1, len(m.groups()) + 1):
                    bad = dict(src)
                    bad[path] = src[path][:m.start(g)] + altered(m.group(g)) + src[path][m.end(g):]
                    count += 1
                    if not check_all(readme, bad)[0]:
                        missed.append(f"{path}: {m.group(g)} altered, not caught")
        # (a) each Current figures table without its commit, and a second suite time
        for path in results_files(root):
            bad = dict(src)
            bad[path] = re.sub(r"\| [0-9a-f]{7,40} \|", "| HEAD |", src[path], count=1)
            count += 1
            if not check_all(readme, bad)[0]:
                missed.append(f"{path}: a Current figures row without a commit not caught")
        count += 1
        if not check_all(readme + "\nSuite time: 40 min 32 s\n", src)[0]:
            missed.append("a second suite time not caught")
        for line in missed:
            print(line)
        print(f"check_readme_status self-test: {count - len(missed)} of {count} altered "
              f"figures caught")
        return 1 if missed else 0
    for line in problems:
        print(line)
    print(f"check_readme_status: {checked} figures of README.md's status table and of the docs "
          f"checked against the Current figures of {len(results_files(root))} RESULTS files and "
          f"the record's tables: " + (f"{len(problems)} problem(s)" if problems else "all match"))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

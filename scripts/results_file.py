#!/usr/bin/env python3
"""Writes a benchmark's new record into a RESULTS file without losing what the file holds.

A RESULTS file is: a title line, a "## Current figures" table (the figures a reader quotes, each
with its commit and command; edited by hand), the sentence "Everything below is the dated
record ...", then the dated record, newest section first. A generator script (bench_targets.sh,
contour_targets.sh, bench/ad/report.py) produces a whole new record; this tool puts it in as the
newest section, under a heading that names the date, the commit and the command, and keeps the
title, the Current figures table and every older section below it. It then lists the Current
figures rows whose command is the one that just ran: those are the rows to re-read against the new
record (the table is never rewritten by a script; a figure changes when a person checks it).

  results_file.py OUT NEW_RECORD --command "bash scripts/bench_targets.sh"
  results_file.py --self-test
"""
import argparse
import datetime
import os
import subprocess
import sys
import tempfile

CURRENT = "## Current figures"
RECORD_MARK = "Everything below is the dated record"


def split_results(text):
    """(title, current block incl. the record sentence, rest) of an existing RESULTS file; the
    current block is empty when the file has none."""
    lines = text.splitlines(keepends=True)
    title = lines[0] if lines and lines[0].startswith("# ") else ""
    body = lines[1:] if title else lines
    try:
        start = next(i for i, l in enumerate(body) if l.startswith(CURRENT))
    except StopIteration:
        return title, "", "".join(body)
    end = None
    for i in range(start, len(body)):
        if body[i].startswith(RECORD_MARK):
            end = i
            while end < len(body) and body[end].strip():  # the sentence's paragraph
                end += 1
            break
    if end is None:  # no record sentence: the block ends at the next heading
        end = next((i for i in range(start + 1, len(body)) if body[i].startswith("## ")), len(body))
    return title, "".join(body[:end]), "".join(body[end:])


def rows_of_command(current, command):
    return [l.rstrip("\n") for l in current.splitlines(keepends=True)
            if l.startswith("|") and command and command in l]


def merge(old_text, new_record, command, date, commit):
    title, current, rest = split_results(old_text)
    new_lines = new_record.splitlines(keepends=True)
    if new_lines and new_lines[0].startswith("# "):  # the generator's own title
        if not title:
            title = new_lines[0]
        new_lines = new_lines[1:]
    record = "".join(new_lines).strip("\n")
    # The generator's sections become subsections of the dated one.
    record = "\n".join(("#" + l) if l.startswith("## ") else l for l in record.split("\n"))
    head = f"## {date}, {commit}: `{command}`\n\n" if command else f"## {date}, {commit}\n\n"
    parts = [title.rstrip("\n") + "\n" if title else "", "\n" if title else ""]
    if current:
        parts += [current.strip("\n") + "\n", "\n"]
    parts += [head, record + "\n"]
    if rest.strip():
        parts += ["\n", rest.lstrip("\n")]
    return "".join(parts), rows_of_command(current, command)


def git_commit(path):
    try:
        out = subprocess.run(["git", "-C", os.path.dirname(os.path.abspath(path)), "rev-parse",
                              "--short", "HEAD"], capture_output=True, text=True, check=True)
        return out.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown commit"


def self_test():
    old = ("# Target benchmarks\n\n## Current figures\n\n| figure | value | command |\n|---|---|---|\n"
           "| rnea | 3357 | `bash scripts/bench_targets.sh` |\n| qp | 9 | `bash other.sh` |\n\n"
           "Everything below is the dated record these figures come from, newest section first,\n"
           "each figure as measured at its own date and commit.\n\n"
           "Generated on 2026-12-01.\n\n## Old table\n\n| a | b |\n")
    new = "# Target benchmarks (emulated)\n\n## Cortex-M7\n\n| rnea | 3300 |\n"
    text, rows = merge(old, new, "bash scripts/bench_targets.sh", "2026-12-08", "abc1234")
    checks = [
        (text.startswith("# Target benchmarks\n\n## Current figures\n"), "title and table kept"),
        ("| qp | 9 | `bash other.sh` |" in text, "every Current row kept"),
        (text.index("## 2026-12-08, abc1234") > text.index(RECORD_MARK), "new record below"),
        (text.index("### Cortex-M7") > text.index("## 2026-12-08"), "sections nested"),
        (text.index("Generated on 2026-12-01.") > text.index("| rnea | 3300 |"), "old kept below"),
        ("## Old table" in text and "| a | b |" in text, "old sections kept"),
        (text.count("# Target benchmarks") == 1, "one title"),
        (rows == ["| rnea | 3357 | `bash scripts/bench_targets.sh` |"], "rows of the command"),
    ]
    text2, rows2 = merge("", new, "cmd", "d", "c")  # no file yet: the generator's title
    checks += [(text2.startswith("# Target benchmarks (emulated)\n\n## d, c: `cmd`"), "new file"),
               (rows2 == [], "no rows without a table")]
    bad = [name for ok, name in checks if not ok]
    for name in bad:
        print(f"results_file self-test FAILED: {name}", file=sys.stderr)
    if not bad:
        print(f"results_file self-test: {len(checks)} checks passed")
    return 1 if bad else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out", nargs="?")
    ap.add_argument("new_record", nargs="?")
    ap.add_argument("--command", default="")
    ap.add_argument("--self-test", action="store_true")
    a = ap.parse_args()
    if a.self_test:
        return self_test()
    if not a.out or not a.new_record:
        ap.error("OUT and NEW_RECORD are required")
    old = open(a.out).read() if os.path.exists(a.out) else ""
    new = open(a.new_record).read()
    text, rows = merge(old, new, a.command, datetime.date.today().isoformat(), git_commit(a.out))
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(os.path.abspath(a.out)))
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(tmp, a.out)  # never a half-written RESULTS file
    print(f"results_file: {a.out}: new record added as the newest section; the Current figures "
          f"table and the older record kept")
    for r in rows:
        print(f"results_file: re-read this Current figure against the new record: {r}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

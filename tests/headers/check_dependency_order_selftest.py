#!/usr/bin/env python3
"""Self-test of check_dependency_order.py: on the fixture tree (fixture/include) it must fail and
print exactly the lines of fixture/expected.txt (every violation, nothing for allowed includes)."""
import os
import subprocess
import sys

here = os.path.dirname(os.path.abspath(__file__))
fixture = os.path.join(here, "fixture")
run = subprocess.run(
    [sys.executable, os.path.join(here, "check_dependency_order.py"),
     os.path.join(fixture, "include")],
    capture_output=True, text=True)
got = [l for l in run.stdout.splitlines() if not l.startswith("check_dependency_order:")]
with open(os.path.join(fixture, "expected.txt"), encoding="utf-8") as fh:
    want = fh.read().splitlines()
ok = True
if run.returncode != 1:
    print(f"expected exit status 1, got {run.returncode}\n{run.stdout}{run.stderr}")
    ok = False
for line in want:
    if line not in got:
        print(f"not reported: {line}")
        ok = False
for line in got:
    if line not in want:
        print(f"reported but allowed: {line}")
        ok = False
print(f"check_dependency_order self-test: {len(got)} of {len(want)} expected violations, "
      + ("as expected" if ok else "FAILED"))
sys.exit(0 if ok else 1)

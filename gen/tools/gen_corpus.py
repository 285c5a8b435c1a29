#!/usr/bin/env python3
"""Runs arbor-gen over every URDF of the repository with many option sets and keeps, per run, the
header, the messages and the exit status: two generators (before and after a change) give two
folders that `diff -r` compares. Paths are relative to the repository root, so that worktrees
compare too. About 3000 runs (a few minutes).

    gen/tools/gen_corpus.py ARBOR_GEN OUT_DIR

Each run is OUT_DIR/<key>.{cmd,out,err,rc}, <key> a hash of its command line: a new URDF or
option set adds files without renaming the others. Every URDF under examples/robots and
tests/gen/data is run with the option sets below; the good ones also with --lock of each joint,
--tip and --root at each link.
"""
import glob
import hashlib
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

exe, out = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
root = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))
os.chdir(root)
os.makedirs(out, exist_ok=True)
urdfs = sorted(glob.glob('examples/robots/*.urdf') +
               glob.glob('tests/gen/data/**/*.urdf', recursive=True))
every = ['', '--summary', '--lock-mimic', '--strict-inertia', '--fix-inertia', '--snap 1e-9',
         '--snap 1e-5', '--snap 1e-3', '--snap 0.05', '--summary --snap 1e-5',
         '--lock-mimic --fix-inertia --snap 1e-4', '--summary --lock-mimic --snap 1e-3',
         '--name Foo --namespace a::b']
runs = []
for u in urdfs:
    runs += [f"'{u}' -o - {o}" for o in every]
    if '/bad/' in u:
        continue
    try:
        tree = ET.parse(u).getroot()
    except ET.ParseError:
        continue
    joints = [j.get('name') for j in tree.findall('joint')]
    links = [l.get('name') for l in tree.findall('link')]
    for j in joints:
        runs += [f"'{u}' -o - --lock {j}={v}" for v in ('0', '0.05', '-0.3')]
        runs += [f"'{u}' -o - --lock {j}=0.01 --lock-mimic",
                 f"'{u}' -o - --lock {j}=0.02 --snap 1e-3 --summary"]
    for l in links:
        runs += [f"'{u}' -o - --tip {l}", f"'{u}' -o - --tip {l} --lock-mimic",
                 f"'{u}' -o - --root {l}", f"'{u}' -o - --root {l} --summary"]
    if len(links) > 2:
        two = f"--tip {links[-1]} --tip {links[len(links) // 2]}"
        runs += [f"'{u}' -o - {two}", f"'{u}' -o - {two} --snap 1e-3 --fix-inertia"]
for cmd in runs:
    p = subprocess.run(f"'{exe}' {cmd}", shell=True, capture_output=True)
    base = os.path.join(out, hashlib.sha1(cmd.encode()).hexdigest()[:16])
    with open(base + '.cmd', 'w') as f:
        f.write(cmd + '\n')
    with open(base + '.out', 'wb') as f:
        f.write(p.stdout)
    with open(base + '.err', 'wb') as f:
        f.write(p.stderr)
    with open(base + '.rc', 'w') as f:
        f.write(f'{p.returncode}\n')
print(f'{len(runs)} runs in {out}')

#!/usr/bin/env python3
"""'replica config check' resolves what the kiosk resolves: over a corpus of site files, each the
shipped deploy/replica.toml (set to simulated sensors, headless, a small frame, no recording) with
one key given a wrong value of some kind (wrong type, out of range, a missing file, a folder, a
file of another kind, a junk string), the keys it leaves commented out included,
the check says ok exactly when 'replica run --kiosk' starts, and when it does not, the kiosk exits
78 (EX_CONFIG) with the check's lines, each naming the file, the line and the key.

    site_mutations.py REPLICA SHIPPED_TOML WORKDIR
"""
import os
import re
import shutil
import subprocess
import sys
import time

replica, shipped, work = sys.argv[1], sys.argv[2], sys.argv[3]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)

# The base: the shipped file as a test machine can start it.
BASE = {
    ("run", "hal"): '"sim"',
    ("display", "output"): '"headless"',
    ("display", "size"): '"96x60"',
    ("recording", "enabled"): "false",
    ("render", "warm_up"): "false",
}


def parse(text):
    """(section, key) -> (line index, value text) for every 'key = value' line."""
    keys, section = {}, None
    for i, line in enumerate(text.splitlines()):
        m = re.match(r"\s*\[(\w+)\]", line)
        if m:
            section = m.group(1)
            continue
        m = re.match(r"\s*(\w+)\s*=\s*(.*?)\s*(#.*)?$", line)
        if m and section:
            keys[(section, m.group(1))] = (i, m.group(2))
            continue
        # A key the shipped file leaves commented out ("# dir = ..."): mutated by uncommenting it.
        m = re.match(r"#\s*(\w+)\s*=\s*(\"[^\"]*\"|[-+0-9.eE]+|true|false)\s*$", line)
        if m and section and (section, m.group(1)) not in keys:
            keys[(section, m.group(1))] = (i, m.group(2))
    return keys


def with_value(lines, keys, section, key, value):
    out = list(lines)
    i, _ = keys[(section, key)]
    out[i] = f"{key} = {value}"
    return out


def wrong_values(value):
    """Wrong values of every kind for a key whose shipped value is 'value'."""
    kinds = [("junk string", '"j#nk value!"')]
    if value.startswith('"'):
        kinds += [("wrong type", "42"), ("missing file", '"/nonexistent/replica/file.json"'),
                  ("empty", '""'), ("a folder", '"/tmp"'), ("a file of another kind", f'"{shipped}"')]
    elif value in ("true", "false"):
        kinds += [("wrong type", "1")]
    elif value.startswith("["):
        kinds += [("short array", "[1.0, 2.0]"), ("out of range", "[1e9, 0.0, 0.0]")]
    else:  # a number
        kinds += [("out of range", "1e15"), ("not finite", "inf")]
    return kinds


text = open(shipped).read()
lines = text.splitlines()
keys = parse(text)
for (section, key), value in BASE.items():
    lines = with_value(lines, keys, section, key, value)

cases = []
for (section, key), (_, value) in sorted(keys.items()):
    for kind, wrong in wrong_values(value):
        cases.append((f"{section}.{key}", kind, with_value(lines, keys, section, key, wrong)))
cases.append(("base", "none", lines))

failures, accepted, refused = [], 0, 0
started = time.monotonic()
for n, (name, kind, body) in enumerate(cases):
    site = os.path.join(work, f"case{n:03d}.toml")
    with open(site, "w") as f:
        f.write("\n".join(body) + "\n")
    check = subprocess.run([replica, "config", "check", site], capture_output=True, text=True)
    run = subprocess.run([replica, "run", "--kiosk", "--config", site, "--frames", "1"],
                         capture_output=True, text=True, timeout=600)
    ok = check.returncode == 0
    what = f"{name} = {kind} ({site})"
    print(f"{what}: check exit {check.returncode}, kiosk exit {run.returncode}", flush=True)
    if ok != (run.returncode == 0):
        failures.append(f"{what}: config check exit {check.returncode}, kiosk exit "
                        f"{run.returncode}\n  check: {check.stderr.strip()}\n  kiosk: "
                        f"{run.stderr.strip()[-600:]}")
        continue
    if ok:
        accepted += 1
        continue
    refused += 1
    if run.returncode != 78:
        failures.append(f"{what}: the kiosk refused with exit {run.returncode}, not 78")
    problems = [l for l in check.stderr.splitlines() if l.strip()]
    missing = [l for l in problems if l not in run.stderr]
    if missing:
        failures.append(f"{what}: the kiosk did not say {missing[0]!r}:\n  {run.stderr.strip()}")
    if not any(re.match(re.escape(site) + r":\d+: \w+\.\w+: ", l) for l in problems):
        failures.append(f"{what}: no line names the file, line and key: {problems}")

print(f"{len(cases)} site files in {time.monotonic() - started:.0f} s: {accepted} accepted by "
      f"both, {refused} refused by both")
for f in failures:
    print("FAIL:", f, file=sys.stderr)
sys.exit(1 if failures else 0)

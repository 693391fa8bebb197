#!/usr/bin/env python3
# Runs every leaf command of replica with bad inputs (missing files, directories, empty and junk
# files, a bad JSON and CSV, empty strings, words, -1 and NaN for every option's value, a missing
# value, an unknown option, extra positionals) and lists each non-zero exit that printed nothing on
# standard error, or more than one line. Slow (about 2000 cases, 15-30 minutes on 2 cores), so
# not a ctest; run by hand after adding commands or options. The data folder is copied first
# (commands with a default output write into it) and the commands run inside WORK.
#   hunt_bad_args.py REPLICA SOURCE_DIR WORK [COMMAND...]   (e.g. 'display flare' probe: only those)
# The cases it found are in hostile_input.sh; its counts are in the commit that added it.
import os, re, subprocess, sys, json, shutil
R = os.path.abspath(sys.argv[1])
W = os.path.abspath(sys.argv[3])
os.makedirs(W, exist_ok=True)
if not os.path.isdir(os.path.join(W, "data")):
    shutil.copytree(os.path.join(sys.argv[2], "data"), os.path.join(W, "data"))
os.environ["REPLICA_DATA_DIR"] = os.path.join(W, "data")
LEAVES = ["run", "replay", "inspect", "render", "booth build", "booth generate", "scene generate",
          "display fit", "display inverse", "display forward", "display study", "display flare",
          "display patches", "display synth", "recover", "color de2000", "spectral eval",
          "spectral fit", "spectral metamers", "probe", "calibrate tracker", "calibrate stand",
          "config check"]
if len(sys.argv) > 4:
    LEAVES = [l for l in LEAVES if l in sys.argv[4:]]
d = os.path.join(W, "adir"); os.makedirs(d, exist_ok=True)
empty = os.path.join(W, "empty.txt"); open(empty, "w").close()
junk = os.path.join(W, "junk.bin"); open(junk, "wb").write(bytes(range(256)) * 4)
badjson = os.path.join(W, "bad.json"); open(badjson, "w").write('{"a": ')
badcsv = os.path.join(W, "bad.csv"); open(badcsv, "w").write("a,b\n1\n")
VALUES = {"missing": os.path.join(W, "no/such/file"), "dir": d, "empty": empty, "junk": junk,
          "badjson": badjson, "badcsv": badcsv, "emptystr": "", "word": "abc", "neg": "-1",
          "nan": "nan", "devnull": "/dev/null"}

def options(cmd):
    out = subprocess.run([R] + cmd.split() + ["--help"], capture_output=True, text=True).stdout
    opts = []
    for line in out.splitlines():
        m = re.match(r"^\s{2}((?:-\w,)?--[\w-]+|[a-z][\w-]*)\s+([A-Z]+)?(\S*)", line)
        if not m or m.group(1) in ("-h,--help",):
            continue
        name = m.group(1).split(",")[-1]
        kind = m.group(2) or "FLAG"
        if kind not in ("TEXT", "INT", "FLOAT", "UINT", "FLAG"):
            kind = "TEXT"
        opts.append((name, kind, "REQUIRED" in line))
    return opts

cases = []
for leaf in LEAVES:
    opts = options(leaf)
    base = leaf.split()
    cases.append((leaf, base))
    cases.append((leaf, base + ["--bogus-option"]))
    cases.append((leaf, base + ["extra-positional-1", "extra-positional-2", "extra-3", "x4"]))
    for name, kind, req in opts:
        base = leaf.split()
        if leaf == "run" and name not in ("--frames", "--size"):
            base = base + ["--frames", "1", "--size", "32x20"]
        if kind == "FLAG":
            if name.startswith("--"):
                cases.append((leaf, base + [name + "=abc"]))
            continue
        for vname, v in VALUES.items():
            if name.startswith("--"):
                cases.append((leaf, base + [name, v]))
            else:
                cases.append((leaf, base + [v]))
        if name.startswith("--"):
            cases.append((leaf, base + [name]))  # missing value
    # positionals of the two-file commands
    if leaf == "recover":
        for v in VALUES.values():
            cases.append((leaf, base + [v, os.path.join(W, "out.mcap")]))
seen = set()
uniq = []
for c in cases:
    k = tuple(c[1])
    if k not in seen:
        seen.add(k); uniq.append(c)
silent, multi, hung, ok0, good = [], [], [], 0, 0
prev = {}
if os.path.exists(os.path.join(W, "cases.txt")):
    for line in open(os.path.join(W, "cases.txt")):
        parts = line.split(" ", 2)
        if parts[0] == "HUNG":
            continue
        a = json.loads(parts[2].split(" :: ")[0])
        prev[tuple(a)] = line
log = open(os.path.join(W, "cases.txt"), "a")
for leaf, args in uniq:
    argv = [R, "--log-level", "error"] + args
    if tuple(args) in prev:
        line = prev[tuple(args)]
        rc, n = int(line.split()[0]), int(line.split()[1])
        err = eval(line.split(" :: ", 1)[1])
        if rc == 0: ok0 += 1
        elif n == 0: silent.append((args, rc, ""))
        elif n > 1: multi.append((args, rc, err))
        else: good += 1
        continue
    try:
        p = subprocess.run(argv, capture_output=True, timeout=8, stdin=subprocess.DEVNULL, cwd=W)
        p.stdout = p.stdout.decode("utf-8", "replace"); p.stderr = p.stderr.decode("utf-8", "replace")
    except subprocess.TimeoutExpired:
        hung.append(args); log.write(f"HUNG {args}\n"); continue
    err = [l for l in p.stderr.splitlines() if l.strip()]
    log.write(f"{p.returncode} {len(err)} {json.dumps(args)} :: {err[:3]}\n")
    if p.returncode == 0:
        ok0 += 1
    elif len(err) == 0:
        silent.append((args, p.returncode, p.stdout[-300:]))
    elif len(err) > 1:
        multi.append((args, p.returncode, err[:4]))
    else:
        good += 1
print(f"cases {len(uniq)}: exit 0 {ok0}, one line {good}, silent {len(silent)}, several lines {len(multi)}, hung {len(hung)}")
for a, rc, out in silent:
    print("SILENT", rc, a, "stdout:", out.replace("\n", " | ")[:200])
for a, rc, e in multi:
    print("MULTI", rc, a, e)
for a in hung:
    print("HUNG", a)

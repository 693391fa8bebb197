#!/usr/bin/env bash
# 'replica calibrate tracker|stand' end to end on synthetic readings with a known answer: the
# tracker fit recovers the pose within the noise and reports the residual the noise predicts
# (sigma * sqrt((3n - 6) / n)); a swapped pair and collinear points are refused; the stand fit
# recovers the hinge; the site file keeps its other sections; and 'replica run --site' uses the
# transform, records it, and replays to the same frames.
set -euo pipefail
replica="$1"
work="$2"
rm -rf "$work" && mkdir -p "$work"
printf '# booth 7\n[display]\nprofile = "panel.json"\n' > "$work/site.toml"
python3 - "$work" <<'PY'
import math, random, sys
work = sys.argv[1]
rng = random.Random(7)
ax = [0.3, 1.0, -0.2]; n = math.sqrt(sum(a * a for a in ax)); ax = [a / n for a in ax]
ang = 2.5
c, s = math.cos(ang), math.sin(ang)
x, y, z = ax
R = [[c + x*x*(1-c), x*y*(1-c) - z*s, x*z*(1-c) + y*s],
     [y*x*(1-c) + z*s, c + y*y*(1-c), y*z*(1-c) - x*s],
     [z*x*(1-c) - y*s, z*y*(1-c) + x*s, c + z*z*(1-c)]]
t = [0.12, 0.42, -0.05]
sigma = 0.002
def row(q, noisy=True):
    d = [q[i] - t[i] for i in range(3)]
    p = [sum(R[j][i] * d[j] for j in range(3)) for i in range(3)]  # R^T (q - t)
    if noisy:
        p = [v + rng.gauss(0.0, sigma) for v in p]
    return q + p
pts = [[rng.uniform(-0.3, 0.3), 0.45 + rng.uniform(-0.3, 0.3), 0.6 + rng.uniform(-0.3, 0.3)]
       for _ in range(12)]
rows = [row(q) for q in pts]
with open(f"{work}/marker.csv", "w") as f:
    f.write("booth_x,booth_y,booth_z,tracker_x,tracker_y,tracker_z\n")
    for r in rows:
        f.write(",".join(f"{v:.6f}" for v in r) + "\n")
swapped = [list(r) for r in rows]
swapped[2][:3], swapped[7][:3] = rows[7][:3], rows[2][:3]
with open(f"{work}/swapped.csv", "w") as f:
    for r in swapped:
        f.write(",".join(f"{v:.6f}" for v in r) + "\n")
with open(f"{work}/line.csv", "w") as f:
    for k in range(5):
        q = [0.1 * k, 0.4 + 0.05 * k, 0.5]
        f.write(",".join(f"{v:.6f}" for v in row(q, False)) + "\n")
with open(f"{work}/truth.txt", "w") as f:
    f.write(repr((R, t, sigma, len(rows))))
# Stand: hinge (y 0.18, z -0.07), top edge 0.035 + 0.324 m from it; tilts 0, 20, 40 degrees.
g = 9.80665
with open(f"{work}/tilts.csv", "w") as f:
    f.write("ax,ay,az,top_y,top_z\n")
    for deg in (0.0, 20.0, 40.0):
        a = math.radians(deg)
        L = 0.035 + 0.324
        # The accelerometer reads the reaction to gravity: +g cos along panel y, +g sin along z.
        f.write(f"0.0,{g*math.cos(a):.6f},{g*math.sin(a):.6f},{0.18 + L*math.cos(a):.6f},{-0.07 - L*math.sin(a):.6f}\n")
PY
"$replica" calibrate tracker --points "$work/marker.csv" --site "$work/site.toml" \
    > "$work/tracker.out" 2> "$work/tracker.log"
set +e
"$replica" calibrate tracker --points "$work/swapped.csv" --site "$work/site.toml" \
    > /dev/null 2> "$work/swapped.log"
swapped=$?
"$replica" calibrate tracker --points "$work/line.csv" --site "$work/site.toml" \
    > /dev/null 2> "$work/line.log"
line=$?
set -e
"$replica" calibrate stand --points "$work/tilts.csv" --site "$work/site.toml" \
    --panel-width 0.518 --panel-height 0.324 > "$work/stand.out" 2> "$work/stand.log"
python3 - "$work" "$swapped" "$line" <<'PY'
import math, re, sys, tomllib
work, swapped, line = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
R, t, sigma, n = eval(open(f"{work}/truth.txt").read())
site = tomllib.load(open(f"{work}/site.toml", "rb"))
fail = []
if site.get("display", {}).get("profile") != "panel.json":
    fail.append("the [display] section was lost")
T = site["tracker"]["T_booth_tracker"]
rot = T["rotation"]
err_t = math.dist(T["translation"], t)
# Angle between the fitted and the true rotation: acos((trace(R^T Rfit) - 1) / 2).
tr = sum(R[j][i] * rot[3 * j + i] for i in range(3) for j in range(3))
err_r = math.acos(max(-1.0, min(1.0, (tr - 1.0) / 2.0)))
rms = site["tracker"]["calibration_rms_m"]
want = sigma * math.sqrt((3 * n - 6) / n)
if err_t > 0.004 or err_r > 0.01:
    fail.append(f"pose off by {err_t*1e3:.2f} mm, {math.degrees(err_r):.3f} deg")
if not 0.6 * want < rms < 1.4 * want:
    fail.append(f"RMS {rms*1e3:.2f} mm, noise predicts {want*1e3:.2f} mm")
if swapped != 1 or "RMS residual" not in open(f"{work}/swapped.log").read():
    fail.append(f"swapped pair: exit {swapped}")
if line != 1 or "one line" not in open(f"{work}/line.log").read():
    fail.append(f"collinear points: exit {line}")
st = site["stand"]
if (abs(st["hinge_m"][1] - 0.18) > 1e-4 or abs(st["hinge_m"][2] + 0.07) > 1e-4
        or abs(st["hinge_to_panel_m"] - 0.035) > 1e-4):
    fail.append(f"stand {st}")
if fail:
    print("FAIL: " + "; ".join(fail), file=sys.stderr)
    sys.exit(1)
print(f"ok: T_booth_tracker from {n} points with {sigma*1e3:.0f} mm noise: RMS {rms*1e3:.2f} mm "
      f"(noise predicts {want*1e3:.2f}), pose off by {err_t*1e3:.2f} mm and "
      f"{math.degrees(err_r):.3f} deg; swapped pair and collinear points refused; stand recovered")
PY
# The run uses it, records it and replays to the same frames.
"$replica" run --hal sim --output headless --frames 30 --rate 20 --size 48x30 --fast \
    --site "$work/site.toml" --record "$work/run.mcap" --digests "$work/run.json" \
    > /dev/null 2> "$work/run.log"
grep -q "T_booth_tracker" "$work/run.log"
"$replica" replay "$work/run.mcap" --clock fast --digests "$work/replay.json" > /dev/null 2>&1
cmp -s "$work/run.json" "$work/replay.json" || { echo "FAIL: --site run does not replay" >&2; exit 1; }
"$replica" run --hal sim --output headless --frames 30 --rate 20 --size 48x30 --fast \
    --digests "$work/plain.json" > /dev/null 2>&1
if cmp -s "$work/run.json" "$work/plain.json"; then
    echo "FAIL: the calibrated tracker pose changed nothing" >&2
    exit 1
fi

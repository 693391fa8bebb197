#!/usr/bin/python3
"""Pools runs of replica_bench_cost_model: per setting the median of the runs' tilt-moving CPU
medians, then the least squares fit t0 + L lights + H horizon directions + S specular samples
(the columns the scene varies), with R^2, the residuals' RMS and each setting's runs, median and
fitted time. One run on a shared 2-core machine moves a setting's median by 20 %; several runs,
pooled, are what settingCost (pipeline/tuning/planner.cpp) takes.
Usage: cost_model_pool.py SCENE RUN.txt [RUN.txt ...]"""
import re
import statistics
import sys


def rows_of(scene, paths):
    rows = {}
    for path in paths:
        current = None
        with open(path, encoding="utf-8") as f:
            for line in f:
                head = re.match(r"(\S+) fit \(", line)
                if head:
                    current = head.group(1)
                row = re.match(r"\| (\d+) \| (\d+) \| (\d+) \| ([\d.]+) \|", line)
                if row and current == scene:
                    key = tuple(int(v) for v in row.groups()[:3])
                    rows.setdefault(key, []).append(float(row.group(4)))
    return rows


def least_squares(x, y):
    n = len(x[0])
    a = [[sum(r[i] * r[j] for r in x) for j in range(n)] + [sum(r[i] * v for r, v in zip(x, y))]
         for i in range(n)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(a[r][c]))
        a[c], a[p] = a[p], a[c]
        for r in range(n):
            if r != c:
                f = a[r][c] / a[c][c]
                a[r] = [u - f * v for u, v in zip(a[r], a[c])]
    return [a[i][n] / a[i][i] for i in range(n)]


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    scene = sys.argv[1]
    rows = rows_of(scene, sys.argv[2:])
    if not rows:
        sys.exit(f"no rows for {scene}")
    keys = sorted(rows)
    y = [statistics.median(rows[k]) for k in keys]
    relief = any(k[2] for k in keys)
    glossy = any(k[1] for k in keys)
    x = [[1.0, k[0]] + ([k[2]] if relief else []) + ([k[1]] if glossy else []) for k in keys]
    beta = least_squares(x, y)
    fitted = [sum(b * v for b, v in zip(beta, r)) for r in x]
    mean = sum(y) / len(y)
    ss_res = sum((m - f) ** 2 for m, f in zip(y, fitted))
    ss_tot = sum((m - mean) ** 2 for m in y)
    names = ["t0", "per light"] + (["per direction"] if relief else []) + (
        ["per sample"] if glossy else [])
    print(f"{scene}: {len(sys.argv) - 2} runs; " +
          ", ".join(f"{n} {b:.4f}" for n, b in zip(names, beta)) +
          f"; R^2 {1 - ss_res / ss_tot:.3f}, residual RMS {(ss_res / len(y)) ** 0.5:.2f} ms")
    print("| lights | samples | dirs | runs, ms | median ms | fitted ms |\n|---|---|---|---|---|---|")
    for k, m, f in zip(keys, y, fitted):
        runs = " ".join(f"{v:.1f}" for v in rows[k])
        print(f"| {k[0]} | {k[1]} | {k[2]} | {runs} | {m:.1f} | {f:.1f} |")


if __name__ == "__main__":
    main()

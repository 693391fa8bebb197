#!/usr/bin/python3
"""Plots 'replica display study --sensed' (the ablation of the simulated spectrometer) as
docs/sensed_ablation.png. Usage: plot_sensed.py REPLICA_BINARY OUT.png [extra study options]"""
import json
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

binary, out = sys.argv[1], sys.argv[2]
extra = sys.argv[3:]
doc = json.loads(subprocess.run([binary, "display", "study", "--sensed", "--json", *extra],
                                check=True, capture_output=True, text=True).stdout)
rows = doc["rows"]
configs = list(dict.fromkeys(r["instrument"].strip() for r in rows))
lights = list(dict.fromkeys(r["light"] for r in rows))
fig, ax = plt.subplots(figsize=(10, 5.5))
width = 0.8 / len(lights)
colours = ["tab:blue", "tab:green", "tab:orange"]
for li, light in enumerate(lights):
    mine = [r for r in rows if r["light"] == light]
    xs = [i + (li - (len(lights) - 1) / 2) * width for i in range(len(configs))]
    ax.bar(xs, [r["render"]["mean"] for r in mine], width, color=colours[li % 3],
           label=f"{light}: mean")
    ax.plot(xs, [r["render"]["max"] for r in mine], "v", color=colours[li % 3],
            label=f"{light}: max")
ax.set_xticks(range(len(configs)))
ax.set_xticklabels(configs, rotation=25, ha="right", fontsize=8)
ax.set_ylabel("CIEDE2000, rendered vs real surface under the real light")
ax.set_title(f"ColorChecker through the simulated USB2000+ ({doc['mode']} mode, adaptive_k6, "
             f"{doc['draws']} draws, seed {doc['seed']})", fontsize=10)
ax.set_yscale("log")
ax.set_ylim(5e-4, 2.0)
ax.grid(axis="y", which="both", alpha=0.3)
ax.legend(fontsize=8, ncol=3, loc="upper right")
fig.tight_layout()
fig.savefig(out, dpi=110)

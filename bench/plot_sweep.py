#!/usr/bin/env python3
"""Plots the grid's density sweep (sweep/<scene>/<kind>/grid/<option>) against
the BVH of the same run (trace/<scene>/<kind>/bvh): time per ray and device
memory against the cell count, and prints the table as Markdown.

    python3 bench/plot_sweep.py bench/results/latest.json -o docs/grid-sweep.png

Reads Google Benchmark JSON (bench/run.sh writes it); medians over
repetitions. Needs matplotlib (Debian: python3-matplotlib, in scripts/setup.sh)
for the plot only; the table is printed without it.
"""
import argparse
import json
import statistics
from collections import defaultdict

SUFFIXES = ("manual_time", "real_time", "process_time")


def load(path):
    """{(scene, kind, option): {rays, cells, device_bytes, build_ms}} for the
    sweep; option "bvh" for the BVH rows."""
    with open(path) as f:
        data = json.load(f)
    reps = defaultdict(list)
    for b in data.get("benchmarks", []):
        if b.get("run_type") == "aggregate" or b.get("error_occurred"):
            continue
        parts = [p for p in b.get("run_name", b["name"]).split("/") if p not in SUFFIXES]
        if parts[0] == "sweep" and len(parts) == 5:
            key = (parts[1], parts[2], parts[4])
        elif parts[0] == "trace" and len(parts) == 4 and parts[3] == "bvh":
            key = (parts[1], parts[2], "bvh")
        else:
            continue
        reps[key].append(b)
    table = {}
    for key, runs in reps.items():
        table[key] = {m: statistics.median(r[m] for r in runs) for m in ("rays", "cells", "device_bytes", "build_ms")
                      if all(m in r for r in runs)}
    return table, data.get("context", {})


def option_order(option):
    name, _, value = option.partition("=")
    if name == "lambda":
        return (0, float(value))
    if name == "res":
        return (1, int(value.split("x")[0]))
    if name == "macro":
        return (2, int(value))
    return (3, 0)


def markdown(table):
    scenes = sorted({k[0] for k in table}, key=["bunny", "sponza", "sibenik", "teapot-stadium"].index)
    kinds = [k for k in ("primary", "diffuse") if any(key[1] == k for key in table)]
    lines = ["| scene | grid | cells | MiB | build ms | " + " | ".join(f"{k} ns/ray (vs bvh)" for k in kinds) + " |",
             "|---|---|--:|--:|--:|" + "--:|" * len(kinds)]
    for scene in scenes:
        options = sorted({k[2] for k in table if k[0] == scene and k[2] != "bvh"}, key=option_order) + ["bvh"]
        for option in options:
            row = next((table[(scene, k, option)] for k in kinds if (scene, k, option) in table), None)
            if row is None:
                continue
            cells = f"{row['cells']:,.0f}" if option != "bvh" else "–"
            cols = []
            for k in kinds:
                r, bvh = table.get((scene, k, option)), table.get((scene, k, "bvh"))
                if not r or not r.get("rays"):
                    cols.append("–")
                    continue
                ns = 1e9 / r["rays"]
                ratio = f" ({r['rays'] / bvh['rays']:.2f}×)" if bvh and bvh.get("rays") and option != "bvh" else ""
                cols.append(f"{ns:,.0f}{ratio}")
            lines.append(f"| {scene} | {option} | {cells} | {row['device_bytes'] / 2**20:.1f} | {row['build_ms']:.0f} | "
                         + " | ".join(cols) + " |")
    return "\n".join(lines)


def plot(table, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scenes = sorted({k[0] for k in table}, key=["bunny", "sponza", "sibenik", "teapot-stadium"].index)
    kinds = [k for k in ("primary", "diffuse") if any(key[1] == k for key in table)]
    fig, axes = plt.subplots(2, len(kinds), figsize=(6.5 * len(kinds), 9), squeeze=False)
    colours = dict(zip(scenes, plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    for col, kind in enumerate(kinds):
        time_ax, mem_ax = axes[0][col], axes[1][col]
        for scene in scenes:
            c = colours[scene]
            for family, marker, style in (("lambda", "o", "-"), ("res", "s", ":")):
                rows = sorted((option_order(k[2]), table[k]) for k in table
                              if k[0] == scene and k[1] == kind and k[2].startswith(family + "=") and table[k].get("rays"))
                if not rows:
                    continue
                cells = [r["cells"] for _, r in rows]
                label = f"{scene} ({'λ' if family == 'lambda' else 'n³'})"
                time_ax.plot(cells, [1e9 / r["rays"] for _, r in rows], style, marker=marker, color=c, label=label)
                mem_ax.plot(cells, [r["device_bytes"] / 2**20 for _, r in rows], style, marker=marker, color=c,
                            label=label)
            bvh = table.get((scene, kind, "bvh"))
            if bvh and bvh.get("rays"):
                time_ax.axhline(1e9 / bvh["rays"], color=c, linestyle="--", linewidth=1)
                mem_ax.axhline(bvh["device_bytes"] / 2**20, color=c, linestyle="--", linewidth=1)
        time_ax.set(xscale="log", yscale="log", xlabel="cells", ylabel="ns per ray (device time)",
                    title=f"{kind} rays: grid time per ray (dashed: BVH, same run)")
        mem_ax.set(xscale="log", yscale="log", xlabel="cells", ylabel="device MiB (structure + triangles)",
                   title="grid device memory (dashed: BVH)")
        for ax in (time_ax, mem_ax):
            ax.grid(True, which="both", alpha=0.3)
        time_ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("json")
    parser.add_argument("-o", "--output", help="PNG to write")
    args = parser.parse_args()
    table, _ = load(args.json)
    print(markdown(table))
    if args.output:
        plot(table, args.output)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Plots `rtcl bench` results (bench.json, schema rtcl-bench/1;
docs/benchmarks.md):

  PREFIX-mrays.png  Mrays/s (kernel time, median with min-max bars) per
                    structure per scene, one panel per ray set and device;
  PREFIX-build.png  build scaling against primitive count, one line per
                    structure and scene family (soup, surface, ...) and
                    one for Embree's build when the run has its baseline:
                    host build time, the peak memory the build adds per
                    primitive (build_peak_bytes) and the primary rays'
                    rate (run e.g. --scene soup:count=1000000,...,
                    soup:count=33554432; docs/benchmarks.md, "Build
                    times");
  PREFIX-embree.png rtcl / Embree per structure per scene (the cell's
                    "embree" ratio: single-ray kernels against rtcIntersect1
                    / rtcOccluded1, packet kernels against rtcIntersect8 /
                    rtcOccluded8), written when the run has the baseline.

    /usr/bin/python3 bench/plot_bench.py bench-results/bench.json [more.json ...] -o docs/bench

Several JSON files (several machines, or runs at several `--precision`
levels) merge: their cells are plotted side by side, each device named with
its machine's CPU, a structure at another level than robust named with it,
and ratios against Embree's robust mode (`--embree-robust`) marked so.
Needs matplotlib (Debian: python3-matplotlib).
"""
import argparse
import json
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(paths):
    """Cells of every file, each with 'device_label' and 'scene_primitives'
    added, and Embree's builds as cells of structure 'embree'."""
    cells = []
    for path in paths:
        with open(path) as f:
            data = json.load(f)
        if data.get("schema") != "rtcl-bench/1":
            raise SystemExit(f"{path}: not an rtcl bench file (schema {data.get('schema')!r})")
        cpu = data["host"]["cpu"]
        devices = data["devices"]
        prims = {s["name"]: s["triangles"] + s["spheres"] for s in data["scenes"]}
        for cell in data["cells"]:
            d = devices[cell["device"]]
            cell = dict(cell)
            cell["device_label"] = d["name"] if d["type"] != "cpu" else f"{d['platform']} on {cpu}"
            cell["scene_primitives"] = prims.get(cell["scene"], 0)
            # runs at other precision levels (--precision) plot as structures of their own
            if cell.get("precision", "robust") != "robust":
                cell["accel"] = f"{cell['accel']} ({cell['precision']})"
            if (data.get("embree") or {}).get("flags") == "robust" and cell.get("embree"):
                cell["accel"] = f"{cell['accel']} vs robust Embree"
            cells.append(cell)
        embree = data.get("embree") or {}
        for b in embree.get("baselines", []):
            if not b["packets"]:
                robust = " (robust)" if embree.get("flags") == "robust" else ""
                cells.append({"device_label": f"host, {cpu}", "accel": f"Embree {embree['version']}{robust}",
                              "scene": b["scene"], "rays": b["rays"], "build_ms": b["build_ms"],
                              "build_peak_bytes": b.get("build_peak_bytes", 0),
                              "rate": b["mrays_per_s"]["trace"]["median"],
                              "scene_primitives": prims.get(b["scene"], 0), "baseline": True})
    return cells


def plot_panels(cells, path, value, ylabel, title, one=False):
    """Bars per structure per scene, one panel per (device, ray set);
    value(cell) -> (median, low error, high error)."""
    order = {"primary": 0, "shadow": 1, "diffuse": 2}
    panels = sorted({(c["device_label"], c["rays"]) for c in cells}, key=lambda p: (p[0], order.get(p[1], 3), p[1]))
    fig, axes = plt.subplots(len(panels), 1, figsize=(10, 3.2 * len(panels)), squeeze=False)
    for ax, (device, rays) in zip(axes[:, 0], panels):
        mine = [c for c in cells if c["device_label"] == device and c["rays"] == rays]
        scenes = list(dict.fromkeys(c["scene"] for c in mine))
        accels = list(dict.fromkeys(c["accel"] for c in mine))
        width = 0.8 / max(1, len(accels))
        for a, accel in enumerate(accels):
            xs, ys, lo, hi = [], [], [], []
            for s, scene in enumerate(scenes):
                for c in mine:
                    if c["scene"] == scene and c["accel"] == accel:
                        y, low, high = value(c)
                        xs.append(s + (a - (len(accels) - 1) / 2) * width)
                        ys.append(y)
                        lo.append(low)
                        hi.append(high)
            ax.bar(xs, ys, width, yerr=[lo, hi], capsize=2, label=accel)
        if one:
            ax.axhline(1.0, color="black", linewidth=0.8)
        ax.set_xticks(range(len(scenes)))
        ax.set_xticklabels(scenes, fontsize=8)
        ax.set_ylabel(ylabel)
        ax.set_title(f"{rays} rays, {device}{title}", fontsize=9)
        ax.legend(fontsize=7, ncol=4)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"written: {path}")


def plot_rates(cells, path):
    def rate(c):
        r = c["mrays_per_s"]["kernel"]
        return r["median"], r["median"] - r["min"], r["max"] - r["median"]

    plot_panels([c for c in cells if not c.get("baseline")], path, rate, "Mrays/s (kernel)", "")


def plot_build(cells, path):
    """Build time, peak build memory per primitive and primary-ray rate
    against primitive count: one line per (device, structure, scene family),
    the family being the scene's name before ':' (soup, surface, ...)."""
    points = defaultdict(dict)
    rates = defaultdict(dict)
    for c in cells:
        key = (c["device_label"], c["accel"], c["scene"].split(":")[0])
        prims = c["scene_primitives"]
        peak = c.get("build_peak_bytes", 0) / prims if prims else 0.0
        points[key][c["scene"]] = (prims, c["build_ms"], peak)
        if c["rays"] == "primary":
            rate = c["rate"] if c.get("baseline") else c["mrays_per_s"]["kernel"]["median"]
            rates[key][c["scene"]] = (prims, rate)
    fig, axes = plt.subplots(1, 3, figsize=(16, 6))
    for key, by_scene in sorted(points.items()):
        device, accel, family = key
        label = f"{accel}, {family} ({device})"
        xy = sorted(by_scene.values())
        axes[0].plot([p[0] for p in xy], [p[1] for p in xy], marker="o", label=label)
        peaks = [p for p in xy if p[2] > 0]
        axes[1].plot([p[0] for p in peaks], [p[2] for p in peaks], marker="o", label=label)
        r = sorted(rates[key].values())
        axes[2].plot([p[0] for p in r], [p[1] for p in r], marker="o", label=label)
    for ax, ylabel, log in ((axes[0], "host build time (ms)", True),
                            (axes[1], "peak build memory (bytes / primitive)", False),
                            (axes[2], "primary rays (Mrays/s)", True)):
        ax.set_xscale("log")
        if log:
            ax.set_yscale("log")
        ax.set_xlabel("primitives")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    rows = (len(labels) + 2) // 3
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=7)
    fig.tight_layout(rect=(0, min(0.5, 0.035 * rows + 0.02), 1, 1))
    fig.savefig(path, dpi=110)
    print(f"written: {path}")


def plot_embree(cells, path):
    cells = [c for c in cells if not c.get("baseline") and c.get("embree")]
    if cells:
        plot_panels(cells, path, lambda c: (c["embree"]["ratio"], 0.0, 0.0), "rtcl / Embree",
                    ", against Embree on the host", one=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("json", nargs="+", help="bench.json files written by `rtcl bench`")
    parser.add_argument("-o", "--output", default="bench", help="prefix of the PNG files (default: bench)")
    args = parser.parse_args()
    cells = load(args.json)
    if not cells:
        raise SystemExit("no cells in " + ", ".join(args.json))
    plot_rates(cells, args.output + "-mrays.png")
    plot_build(cells, args.output + "-build.png")
    plot_embree(cells, args.output + "-embree.png")


if __name__ == "__main__":
    main()

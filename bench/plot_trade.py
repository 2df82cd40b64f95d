#!/usr/bin/env python3
"""Time against error for every knob of the image-level trade
(trade/<scene>/..., bench/trade_bench.cpp): prints a Markdown table per
scene, then the goals: the time the low-discrepancy samplers need to reach
independent (random) sampling's error, and the time uniform sampling (Sobol,
every pixel) needs to reach each selective / wavelet-guided point's error,
both interpolated log-log between measured spp; plots RMSE and 1 - SSIM
against frame time.

    python3 bench/plot_trade.py trade.json -o docs/trade.png

Reads Google Benchmark JSON; frame times are medians over repetitions (the
errors repeat exactly: the same seeds). Needs matplotlib for the plot only.
"""
import argparse
import json
import math
import statistics
from collections import defaultdict


def config_of(name):
    """'trade/cornell/ray/sobol/spp:16/manual_time' -> ('cornell', 'ray/sobol/spp:16')."""
    parts = [p for p in name.split("/") if not p.startswith(("iterations:", "repeats:", "manual_time"))]
    return parts[1], "/".join(parts[2:])


def load(path):
    with open(path) as f:
        data = json.load(f)
    times = defaultdict(list)
    value = {}
    for b in data.get("benchmarks", []):
        if b.get("run_type") == "aggregate" or b.get("error_occurred"):
            continue
        name = b.get("run_name", b["name"])
        if not name.startswith("trade/"):
            continue
        key = config_of(name)
        times[key].append(b["frame_ms"])
        value[key] = (b["rmse"], b["ssim"], b["traced"])
    out = defaultdict(dict)
    for (scene, config), t in times.items():
        rmse, ssim, traced = value[(scene, config)]
        out[scene][config] = {"ms": statistics.median(t), "rmse": rmse, "ssim": ssim, "traced": traced}
    return out


def spp_of(config):
    for p in config.split("/"):
        if p.startswith("spp:"):
            return int(p[4:])
    return None


def curve(points, prefix):
    """[(ms, rmse, 1 - ssim)] of the plain configs 'prefix/spp:n', by spp."""
    out = []
    for config, v in points.items():
        parts = config.split("/")
        if "/".join(parts[:-1]) == prefix and parts[-1].startswith("spp:"):
            out.append((spp_of(config), v["ms"], v["rmse"], 1.0 - v["ssim"]))
    return [(ms, r, s) for _, ms, r, s in sorted(out)]


def time_to_reach(points, target, metric):
    """(ms, bound) at which the curve's error (metric 1: rmse, 2: 1 - ssim)
    falls to target, log-log between the measured points around it; bound
    "" for an interpolated time, "<=" when the first point already reaches
    it (the time is an upper bound), None when no point does."""
    for (t0, *e0), (t1, *e1) in zip(points, points[1:]):
        a, b = e0[metric - 1], e1[metric - 1]
        if a >= target >= b and a > b > 0 and target > 0:
            f = (math.log(a) - math.log(target)) / (math.log(a) - math.log(b))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0))), ""
    if points and points[0][metric] <= target:
        return points[0][0], "<="
    return None


def reach_cells(points, target, metric, ms):
    """Table cells: the time to reach target and the ratio ms / that time."""
    r = time_to_reach(points, target, metric)
    if r is None:
        return ["never", "–"]
    t, bound = r
    return [f"{bound} {t:.1f}".strip(), f"{'>=' if bound else ''} {ms / t:.2f}".strip()]


def table(scene, points):
    print(f"\n#### {scene}\n")
    print("| configuration | ms | traced | RMSE | SSIM |")
    print("|---|--:|--:|--:|--:|")
    for config in sorted(points, key=lambda c: (c.split("/")[0], c.split("/")[1] if "/" in c else "", spp_of(c) or 0, c)):
        v = points[config]
        print(f"| {config} | {v['ms']:.1f} | {100 * v['traced']:.0f}% | {v['rmse']:.4f} | {v['ssim']:.4f} |")


def goals(scene, points):
    print(f"\n{scene}: time to reach random's error (ratio to random's time)\n")
    print("| random spp | random ms | RMSE | stratified ms (ratio) | sobol ms (ratio) |")
    print("|--:|--:|--:|--:|--:|")
    random = curve(points, "ray/random")
    others = {s: curve(points, "ray/" + s) for s in ("stratified", "sobol")}
    for config, v in sorted(points.items(), key=lambda kv: spp_of(kv[0]) or 0):
        if not config.startswith("ray/random/spp:") or config.count("/") != 2 or spp_of(config) == 1:
            continue
        cells = []
        for s in ("stratified", "sobol"):
            r = time_to_reach(others[s], v["rmse"], 1)
            cells.append("never" if r is None else f"{r[1]} {r[0]:.1f} ({r[0] / v['ms']:.2f})".strip())
        print(f"| {spp_of(config)} | {v['ms']:.1f} | {v['rmse']:.4f} | {cells[0]} | {cells[1]} |")
    uniform = curve(points, "ray/sobol")
    print(f"\n{scene}: selective and wavelet-guided points against uniform sampling (Sobol, every pixel): the time "
          "uniform sampling needs for the same error, and the ratio (goal: <= 0.5)\n")
    print("| configuration | ms | traced | RMSE | uniform ms at that RMSE | ratio | SSIM | uniform ms at that SSIM | ratio |")
    print("|---|--:|--:|--:|--:|--:|--:|--:|--:|")
    for config, v in sorted(points.items(), key=lambda kv: (kv[0].split("/")[0], spp_of(kv[0]) or 0, kv[0])):
        if not config.startswith(("selective/", "wavelet/")):
            continue
        cells = []
        for metric, target in ((1, v["rmse"]), (2, 1.0 - v["ssim"])):
            cells += reach_cells(uniform, target, metric, v["ms"])
        print(f"| {config} | {v['ms']:.1f} | {100 * v['traced']:.0f}% | {v['rmse']:.4f} | {cells[0]} | {cells[1]} | "
              f"{v['ssim']:.4f} | {cells[2]} | {cells[3]} |")


def plot(data, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = sorted(data)
    fig, axes = plt.subplots(len(scenes), 2, figsize=(11, 4.5 * len(scenes)), squeeze=False)
    for row, scene in enumerate(scenes):
        points = data[scene]
        series = defaultdict(list)
        for config, v in points.items():
            parts = config.split("/")
            if parts[0] == "ray" and len(parts) == 3:
                label = "ray " + parts[1]
            elif parts[0] in ("selective", "wavelet") and len(parts) == 3:
                label = f"{parts[0]} {parts[1].replace(':', ' ')}"
            else:
                label = "other knobs"
            series[label].append((v["ms"], v["rmse"], 1.0 - v["ssim"], config))
        for col, (metric, name) in enumerate(((1, "RMSE"), (2, "1 - SSIM"))):
            ax = axes[row][col]
            for label, pts in sorted(series.items()):
                # Along the knob: spp for ray, threshold or budget otherwise.
                pts.sort(key=lambda p: (spp_of(p[3]) or 0, p[3]) if label.startswith("ray") else p[3])
                style = "o" if label == "other knobs" else ("o-" if label.startswith("ray") else "s--")
                ax.plot([p[0] for p in pts], [p[metric] for p in pts], style, label=label, markersize=4)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("frame time, ms")
            ax.set_ylabel(name)
            ax.set_title(f"{scene}: {name} against time")
            ax.grid(True, which="both", alpha=0.3)
        axes[row][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("json")
    parser.add_argument("-o", "--output", help="plot file (PNG)")
    args = parser.parse_args()
    data = load(args.json)
    for scene in sorted(data):
        table(scene, data[scene])
        goals(scene, data[scene])
    if args.output:
        plot(data, args.output)


if __name__ == "__main__":
    main()

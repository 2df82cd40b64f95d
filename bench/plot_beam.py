#!/usr/bin/env python3
"""Beam tracing against the ray tracer (bench/beam_bench.cpp): prints the
Markdown table (median frame time over repetitions, error, beam and fragment
counts) and plots error against time, the ray tracer's spp as a line and the
beam tracer's depth orders as points.

    python3 bench/plot_beam.py beam.json -o docs/beam-trade.png \
        --images DIR --strip docs/beam-images.png

With --images (the directory of $RTCL_BENCH_BEAM_IMAGES) and --strip, the
images beam-exact, beam-key, ray-spp1 and ray-spp64 side by side.

Reads Google Benchmark JSON. Needs matplotlib for the plot only.
"""
import argparse
import json
import statistics
from collections import defaultdict


def load(path):
    with open(path) as f:
        data = json.load(f)
    times, last = defaultdict(list), {}
    for b in data.get("benchmarks", []):
        if b.get("run_type") == "aggregate" or b.get("error_occurred"):
            continue
        name = b.get("run_name", b["name"]).replace("/manual_time", "")
        if not (name.startswith("beam/") or name.startswith("ray/cornell_mirror")):
            continue
        times[name].append(b["frame_ms"])
        last[name] = b
    return {n: (statistics.median(t), last[n]) for n, t in times.items()}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("json")
    ap.add_argument("-o", "--output", help="PNG of error against time")
    ap.add_argument("--images", help="directory of the benchmark's images")
    ap.add_argument("--strip", help="PNG of the images side by side")
    args = ap.parse_args()
    rows = load(args.json)
    print("| configuration | frame ms (median) | RMSE vs reference | beams (tile + reflected) | fragments | rays |")
    print("|---|---:|---:|---:|---:|---:|")
    for name in sorted(rows, key=lambda n: (not n.startswith("beam"), rows[n][0])):
        ms, b = rows[name]
        beams = f"{int(b['tile_beams'])} + {int(b['reflected_beams'])}" if "tile_beams" in b else ""
        frags = f"{int(b['fragments'])}" if "fragments" in b else ""
        rays = f"{int(b['rays'])}" if "rays" in b else f"{int(b.get('shadow_rays', 0))} shadow"
        print(f"| {name} | {ms:.1f} | {b['rmse']:.4f} | {beams} | {frags} | {rays} |")
    if args.images and args.strip:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        names = ["beam-exact", "beam-key", "ray-spp1", "ray-spp64"]
        fig, axes = plt.subplots(1, len(names), figsize=(3 * len(names), 3.3))
        for ax, n in zip(axes, names):
            ax.imshow(plt.imread(f"{args.images}/{n}.png"))
            ax.set_title(n, fontsize=9)
            ax.axis("off")
        fig.tight_layout()
        fig.savefig(args.strip, dpi=100)
    if not args.output:
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    ray = sorted((int(n.split("spp:")[1]), v) for n, v in rows.items() if n.startswith("ray/"))
    ax.plot([v[0] for _, v in ray], [v[1]["rmse"] for _, v in ray], "o-", label="ray tracer")
    for spp, v in ray:
        ax.annotate(f"{spp} spp", (v[0], v[1]["rmse"]), textcoords="offset points", xytext=(4, 4), fontsize=8)
    for n, v in rows.items():
        if n.startswith("beam/"):
            ax.plot([v[0]], [v[1]["rmse"]], "s", label="beam, " + n.split("/")[-1] + " order")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("frame time, ms (median)")
    ax.set_ylabel("RMSE of display values vs reference")
    ax.set_title("Cornell box with mirrors")
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)


if __name__ == "__main__":
    main()

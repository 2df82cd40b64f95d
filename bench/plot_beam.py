#!/usr/bin/env python3
"""Beam tracing against the ray tracer (bench/beam_bench.cpp): prints one
Markdown table per scene (median frame time and candidate-cull time over
repetitions, errors, beam and fragment counts) and plots error against time per
scene, the ray tracer's spp as a line and the beam tracer as a point.

    python3 bench/plot_beam.py beam.json -o docs/beam-trade.png \
        --images DIR --strip docs/beam-images.png

With --images (the directory of $RTCL_BENCH_BEAM_IMAGES) and --strip, one
row per scene: the reference, the beam tracer, the ray tracer at 1 and 64 spp.

Reads Google Benchmark JSON. Needs matplotlib for the plots only.
"""
import argparse
import json
import statistics
from collections import defaultdict

SCENES = ["cornell_glass", "cornell_glass_ior1", "sibenik_mirror"]


def load(path):
    with open(path) as f:
        data = json.load(f)
    times, culls, last = defaultdict(list), defaultdict(list), {}
    for b in data.get("benchmarks", []):
        if b.get("run_type") == "aggregate" or b.get("error_occurred"):
            continue
        name = b.get("run_name", b["name"]).replace("/manual_time", "").replace("/iterations:1", "")
        if not (name.startswith("beam/") or name.startswith("ray/")):
            continue
        times[name].append(b["frame_ms"])
        if "cull_ms" in b:
            culls[name].append(b["cull_ms"])
        last[name] = b
    for n, c in culls.items():
        last[n]["cull_ms"] = statistics.median(c)
    return {n: (statistics.median(t), last[n]) for n, t in times.items()}


def scene_of(name):
    return name.split("/")[1]


def table(rows, scene):
    glass = any("rmse_glass" in b for n, (_, b) in rows.items() if scene_of(n) == scene)
    head = "| configuration | frame ms (median) | RMSE vs reference |"
    head += " RMSE through the glass |" if glass else ""
    head += " beams (tile + reflected + refracted) | fragments | cull ms | rays |"
    print(head)
    print("|---" + "|---:" * (head.count("|") - 2) + "|")
    names = [n for n in rows if scene_of(n) == scene]
    for name in sorted(names, key=lambda n: (not n.startswith("beam"), rows[n][0])):
        ms, b = rows[name]
        cells = [name, f"{ms:.1f}", f"{b['rmse']:.4f}"]
        if glass:
            cells.append(f"{b['rmse_glass']:.4f}" if "rmse_glass" in b else "")
        if "tile_beams" in b:
            cells.append(f"{int(b['tile_beams'])} + {int(b['reflected_beams'])} + {int(b['refracted_beams'])}"
                         f" ({int(b['levels'])} levels)")
            cells.append(f"{int(b['fragments']):,}")
            cells.append(f"{b['cull_ms']:.1f}")
            cells.append(f"{int(b['shadow_rays']):,} shadow")
        else:
            cells += ["", "", "", f"{int(b['rays']):,}"]
        print("| " + " | ".join(cells) + " |")
    print()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("json")
    ap.add_argument("-o", "--output", help="PNG of error against time")
    ap.add_argument("--images", help="directory of the benchmark's images")
    ap.add_argument("--strip", help="PNG of the images side by side")
    args = ap.parse_args()
    rows = load(args.json)
    scenes = [s for s in SCENES if any(scene_of(n) == s for n in rows)]
    for scene in scenes:
        print(f"**{scene}**\n")
        table(rows, scene)
    if not (args.output or args.strip):
        return
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    if args.images and args.strip:
        names = ["reference", "beam", "ray-spp1", "ray-spp64"]
        fig, axes = plt.subplots(len(scenes), len(names), figsize=(3 * len(names), 3.3 * len(scenes)), squeeze=False)
        for row, scene in zip(axes, scenes):
            for ax, n in zip(row, names):
                ax.imshow(plt.imread(f"{args.images}/{scene}-{n}.png"))
                ax.set_title(f"{scene} {n}", fontsize=9)
                ax.axis("off")
        fig.tight_layout()
        fig.savefig(args.strip, dpi=100)
    if not args.output:
        return
    fig, axes = plt.subplots(1, len(scenes), figsize=(6 * len(scenes), 4), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        ray = sorted((int(n.split("spp:")[1]), v) for n, v in rows.items()
                     if n.startswith("ray/") and scene_of(n) == scene)
        for key, style, label in [("rmse", "o-", "ray tracer"), ("rmse_glass", "o--", "ray tracer, through glass")]:
            pts = [(v[0], v[1][key]) for _, v in ray if key in v[1]]
            if not pts:
                continue
            ax.plot([p[0] for p in pts], [p[1] for p in pts], style, label=label)
            for spp, v in ray:
                if key == "rmse":
                    ax.annotate(f"{spp} spp", (v[0], v[1][key]), textcoords="offset points", xytext=(4, 4),
                                fontsize=8)
        beam = rows.get(f"beam/{scene}")
        if beam:
            ax.plot([beam[0]], [beam[1]["rmse"]], "s", label="beam tracer")
            if "rmse_glass" in beam[1]:
                ax.plot([beam[0]], [beam[1]["rmse_glass"]], "D", label="beam tracer, through glass")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("frame time, ms (median)")
        ax.set_ylabel("RMSE of display values vs reference")
        ax.set_title(scene)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)


if __name__ == "__main__":
    main()

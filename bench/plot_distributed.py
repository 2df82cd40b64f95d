#!/usr/bin/env python3
"""Time against error of the distributed ray tracer per sampler and spp
(distributed/cornell/<sampler>/spp:<n>, bench/distributed_bench.cpp): prints
the Markdown table and, for each sampler, the time at which it reaches the
error of independent (random) sampling at the largest spp, interpolated
log-log between its measured points; plots error against time.

    python3 bench/plot_distributed.py dist.json -o docs/distributed-trade.png

Reads Google Benchmark JSON; medians of frame time over repetitions (the
error is the same in every repetition: the same seeds). Needs matplotlib for
the plot only.
"""
import argparse
import json
import math
import statistics
from collections import defaultdict


def load(path):
    """{sampler: {spp: (median frame ms, rmse)}} for 1 light sample, and
    {(sampler, spp, light samples): (median frame ms, rmse)} for more."""
    with open(path) as f:
        data = json.load(f)
    reps = defaultdict(list)
    rmse = {}
    for b in data.get("benchmarks", []):
        if b.get("run_type") == "aggregate" or b.get("error_occurred"):
            continue
        parts = b.get("run_name", b["name"]).split("/")
        if parts[0] != "distributed" or len(parts) < 4:
            continue
        sampler, spp = parts[2], int(parts[3].split(":")[1])
        light = int(parts[4].split(":")[1]) if len(parts) > 4 and parts[4].startswith("light:") else 1
        reps[(sampler, spp, light)].append(b["frame_ms"])
        rmse[(sampler, spp, light)] = b["rmse"]
    out, lights = defaultdict(dict), {}
    for (sampler, spp, light), times in reps.items():
        value = (statistics.median(times), rmse[(sampler, spp, light)])
        if light == 1:
            out[sampler][spp] = value
        else:
            lights[(sampler, spp, light)] = value
    return out, lights


def time_to_reach(points, target):
    """Frame ms at which error falls to `target`, log-log between the two
    measured points around it; None when never reached."""
    pts = sorted(points.values())
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if e0 >= target >= e1 and e0 > e1:
            f = math.log(e0 / target) / math.log(e0 / e1)
            return t0 * (t1 / t0) ** f
    return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("json")
    ap.add_argument("-o", "--output")
    args = ap.parse_args()
    data, lights = load(args.json)
    samplers = [s for s in ("random", "stratified", "sobol") if s in data]
    spps = sorted({spp for s in samplers for spp in data[s]})
    print("| spp | " + " | ".join(f"{s} ms | {s} RMSE" for s in samplers) + " |")
    print("|--:|" + "--:|--:|" * len(samplers))
    for spp in spps:
        cells = []
        for s in samplers:
            t, e = data[s].get(spp, (float("nan"), float("nan")))
            cells += [f"{t:.1f}", f"{e:.4f}"]
        print(f"| {spp} | " + " | ".join(cells) + " |")
    if lights:
        print("\n| sampler | spp | light samples | ms | RMSE |\n|---|--:|--:|--:|--:|")
        for (sampler, spp, light), (t, e) in sorted(lights.items()):
            print(f"| {sampler} | {spp} | {light} | {t:.1f} | {e:.4f} |")
    if "random" in data:
        top = max(data["random"])
        t_ref, e_ref = data["random"][top]
        print(f"\nrandom at {top} spp: RMSE {e_ref:.4f} in {t_ref:.1f} ms")
        for s in samplers:
            t = time_to_reach(data[s], e_ref)
            print(f"{s}: reaches it in " + (f"{t:.1f} ms ({t / t_ref:.2f} of random's time)" if t else "(not reached)"))
    if args.output:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4))
        for s in samplers:
            pts = sorted(data[s].items())
            ax.loglog([p[1][0] for p in pts], [p[1][1] for p in pts], "o-", label=s)
            for spp, (t, e) in pts:
                ax.annotate(str(spp), (t, e), textcoords="offset points", xytext=(4, 4), fontsize=7)
        ax.set_xlabel("frame time, ms (median)")
        ax.set_ylabel("RMSE of display values vs 1024 spp")
        ax.set_title("Cornell box, soft shadows + glossy + lens: time vs error")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.output, dpi=110)


if __name__ == "__main__":
    main()

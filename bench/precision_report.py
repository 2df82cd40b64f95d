#!/usr/bin/python3
"""The precision levels' speed/accuracy trade from an rtcl_bench run.

Usage: precision_report.py RESULTS.json [-o OUT.md] [--plot OUT.png]

Reads the precision/... benchmarks of rtcl_bench's Google Benchmark JSON
(bench/precision_bench.cpp) and writes Markdown tables: per scene, level and
structure the primary-ray Mrays/s (median of the repetitions, with the ratio
to the same structure's robust level in the same run) and the error rates
against the double-precision reference; leaks on closed meshes; the renderer
against the double-precision reference renderer. With --plot, a PNG of
Mrays/s against the error rate (python3-matplotlib).
"""

import argparse
import json
import statistics
from collections import defaultdict

LEVELS = ["fast", "robust", "exact"]
SUFFIXES = ("manual_time", "real_time", "process_time")


def base_name(run_name):
    return "/".join(p for p in run_name.split("/") if p not in SUFFIXES and ":" not in p)


def load(path):
    """{name parts tuple: {counter: median}}"""
    with open(path) as f:
        data = json.load(f)
    runs = defaultdict(lambda: defaultdict(list))
    for b in data.get("benchmarks", []):
        if b.get("run_type") == "aggregate" or b.get("error_occurred"):
            continue
        parts = tuple(base_name(b.get("run_name", b["name"])).split("/"))
        if parts[0] != "precision":
            continue
        for k, v in b.items():
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                runs[parts][k].append(float(v))
    return {key: {k: statistics.median(v) for k, v in metrics.items()} for key, metrics in runs.items()}, data.get("context", {})


def pct(x):
    return f"{100.0 * x:.3f}%" if x else "0"


def scene_table(results):
    rows = ["| scene | structure | level | Mrays/s | vs robust | wrong prim | false hit | missed hit | t error ulps (mean / max) |",
            "|---|---|---|--:|--:|--:|--:|--:|--:|"]
    scenes = sorted({k[1] for k in results if len(k) == 4 and k[1] not in ("closed", "render")}, key=str)
    for scene in scenes:
        accels = sorted({k[3] for k in results if len(k) == 4 and k[1] == scene})
        for accel in accels:
            robust = results.get(("precision", scene, "robust", accel), {}).get("rays")
            for level in LEVELS:
                m = results.get(("precision", scene, level, accel))
                if not m:
                    continue
                rate = m.get("rays", 0.0)
                ratio = f"{rate / robust:.2f}×" if robust else "–"
                rows.append(f"| {scene} | {accel} | {level} | {rate / 1e6:.2f} | {ratio} | {pct(m.get('wrong_prim', 0))} | "
                            f"{pct(m.get('false_hit', 0))} | {pct(m.get('missed_hit', 0))} | "
                            f"{m.get('t_ulps_mean', 0):.2f} / {m.get('t_ulps_max', 0):.0f} |")
    return rows


def closed_table(results):
    rows = ["| closed mesh | rays | " + " | ".join(LEVELS) + " |", "|---|--:|" + "--:|" * len(LEVELS)]
    meshes = sorted({(k[2], k[4]) for k in results if len(k) == 5 and k[1] == "closed"})
    for mesh, accel in meshes:
        cells, count = [], 0
        for level in LEVELS:
            m = results.get(("precision", "closed", mesh, level, accel), {})
            count = int(m.get("checked_rays", count))
            cells.append(f"{int(m.get('leaks', 0))} leaks" if m else "–")
        rows.append(f"| {mesh} ({accel}) | {count} | " + " | ".join(cells) + " |")
    return rows


def render_table(results):
    rows = ["| default scene | level | image RMSE vs reference | smooth pixels off by > 0.05 | self-hits of mirror rays |",
            "|---|---|--:|--:|--:|"]
    cases = sorted({k[2] for k in results if len(k) == 4 and k[1] == "render"})
    for case in cases:
        for level in LEVELS:
            m = results.get(("precision", "render", case, level))
            if m:
                rows.append(f"| {case} | {level} | {m.get('rmse', 0):.4f} | {int(m.get('smooth_pixels_off', 0))} | "
                            f"{pct(m.get('self_hits', 0))} |")
    return rows


def plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    markers = {"fast": "o", "robust": "s", "exact": "^"}
    scenes = sorted({k[1] for k in results if len(k) == 4 and k[1] not in ("closed", "render")})
    for scene in scenes:
        for level in LEVELS:
            xs, ys = [], []
            for key, m in results.items():
                if len(key) == 4 and key[1] == scene and key[2] == level:
                    err = m.get("wrong_prim", 0) + m.get("false_hit", 0) + m.get("missed_hit", 0)
                    # leaks of the same structure and level on the closed meshes
                    closed = [v for k, v in results.items() if len(k) == 5 and k[1] == "closed" and k[3] == level and k[4] == key[3]]
                    leaks = sum(v.get("leaks", 0) for v in closed) / max(1.0, sum(v.get("checked_rays", 0) for v in closed))
                    xs.append(max(err + leaks, 1e-6))
                    ys.append(m.get("rays", 0) / 1e6)
            ax.scatter(xs, ys, marker=markers[level], label=f"{scene} {level}")
    ax.set_xscale("log")
    ax.set_xlabel("error rate: wrong primitive + false + missed hits, plus closed-mesh leak rate (1e-6 = none)")
    ax.set_ylabel("primary rays, Mrays/s")
    ax.set_title("rtcl precision levels: speed against error (PoCL)")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("results")
    ap.add_argument("-o", "--output")
    ap.add_argument("--plot")
    args = ap.parse_args()
    results, context = load(args.results)
    lines = ["### Precision levels: speed and errors", "",
             f"Device: {context.get('rtcl_device', '?')}; primary rays at {context.get('image_size', '?')}²; "
             "errors against the double-precision reference on a subset of the same rays.", ""]
    lines += scene_table(results) + ["", "Closed meshes, rays from inside at every vertex and edge midpoint:", ""]
    lines += closed_table(results) + ["", "Renderer (default scene, 96², depth 5) against the double-precision reference renderer:", ""]
    lines += render_table(results)
    text = "\n".join(lines) + "\n"
    if args.output:
        with open(args.output, "w") as f:
            f.write(text)
    print(text)
    if args.plot:
        plot(results, args.plot)


if __name__ == "__main__":
    main()

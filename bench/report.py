#!/usr/bin/env python3
"""Markdown tables from an rtcl_bench run (Google Benchmark JSON output).

Usage: report.py RESULTS.json [-o OUT.md]

Reads the file written by rtcl_bench --benchmark_out=RESULTS.json
--benchmark_out_format=json and prints, per ray kind, scene x structure ->
Mrays/s with the ratio to Embree (default build quality) measured in the same
run; then build time and bytes per triangle. Every figure is the median over
the run's repetitions. Benchmark names it understands:
  trace/<scene>/<kind>/<accel>      rtcl structure on the OpenCL device
  embree/<scene>/<kind>[/high]      Embree 3, default or high build quality
  build/<scene>/<accel|embree|embree-high>
Python 3 standard library only.
"""

import argparse
import json
import statistics
import sys

KINDS = [
    ("primary", "Primary rays (closest hit)"),
    ("shadow", "Shadow rays (any hit)"),
    ("diffuse", "Diffuse-bounce rays (closest hit)"),
]
YARDSTICK = "embree"
# Google Benchmark appends these to a name; they are not part of ours.
SUFFIXES = ("manual_time", "real_time", "process_time")


def base_name(run_name):
    parts = [p for p in run_name.split("/") if p not in SUFFIXES and ":" not in p]
    return "/".join(parts)


def parse(name):
    """(group, scene, kind, structure) or None for names of other suites."""
    parts = name.split("/")
    if parts[0] == "trace" and len(parts) == 4:
        return "trace", parts[1], parts[2], parts[3]
    if parts[0] == "embree" and len(parts) in (3, 4):
        return "trace", parts[1], parts[2], "embree" if len(parts) == 3 else "embree-" + parts[3]
    if parts[0] == "build" and len(parts) == 3:
        return "build", parts[1], None, parts[2]
    return None


def load(path):
    """{(group, scene, kind, structure): {metric: median}}, errors, context."""
    with open(path) as f:
        data = json.load(f)
    runs, medians, errors = {}, {}, {}
    for b in data.get("benchmarks", []):
        key = parse(base_name(b.get("run_name", b["name"])))
        if key is None:
            continue
        if b.get("error_occurred"):
            errors[key] = b.get("error_message", "error")
            continue
        if b.get("run_type") == "aggregate":
            if b.get("aggregate_name") == "median":
                medians[key] = b
            continue
        runs.setdefault(key, []).append(b)
    table = {}
    for key, reps in runs.items():
        metrics = {}
        for field in reps[0]:
            values = [r[field] for r in reps if isinstance(r.get(field), (int, float)) and not isinstance(r.get(field), bool)]
            if len(values) == len(reps):
                metrics[field] = statistics.median(values)
        metrics["repetitions"] = len(reps)
        table[key] = metrics
    for key, b in medians.items():  # only aggregates were written (--benchmark_report_aggregates_only)
        if key not in table:
            table[key] = dict(b, repetitions=b.get("repetitions", 1))
    return table, errors, data.get("context", {})


def ordered(values, first):
    seen = []
    for v in values:
        if v not in seen:
            seen.append(v)
    head = [v for v in first if v in seen]
    return head + [v for v in seen if v not in head]


def fmt_rate(mrays):
    if mrays >= 100:
        return f"{mrays:.0f}"
    if mrays >= 1:
        return f"{mrays:.2f}"
    return f"{mrays:.3g}"


def fmt_ratio(r):
    return f"{r:.2f}×" if r >= 0.01 else f"{r:.2g}×"


def trace_table(table, errors, kind, title, scenes, structures, subset_limit):
    has_ref = any(k[:3] == ("trace", s, kind) and k[3] == YARDSTICK for s in scenes for k in table)
    explain = "Mrays/s (ratio to Embree's rays/s, same run)" if has_ref else "Mrays/s (Embree not in this run)"
    lines = [f"### {title}", "", explain + ". Median of the run's repetitions.", ""]
    head = ["scene", "rays", "hit %"] + structures
    lines.append("| " + " | ".join(head) + " |")
    lines.append("|" + "|".join(["---"] + ["--:"] * (len(head) - 1)) + "|")
    notes = set()
    for scene in scenes:
        ref = table.get(("trace", scene, kind, YARDSTICK))
        rows = [table[k] for k in table if k[:3] == ("trace", scene, kind) and "ray_count" in table[k]]
        if not rows and not any(k[:3] == ("trace", scene, kind) for k in errors):
            continue
        full = max(rows, key=lambda r: r["ray_count"]) if rows else None  # the whole set, not a subset
        rays = int(full["ray_count"]) if full else 0
        hit = f"{100 * full['hit_fraction']:.0f}" if full and "hit_fraction" in full else ""
        cells = [scene, f"{rays:,}" if rays else "", hit]
        for s in structures:
            key = ("trace", scene, kind, s)
            if key in errors:
                cells.append("error")
                notes.add(f"{scene}/{s}: {errors[key]}")
                continue
            row = table.get(key)
            if row is None or "rays" not in row:
                cells.append("–")
                continue
            mrays = row["rays"] / 1e6
            cell = fmt_rate(mrays)
            if ref and "rays" in ref and s != YARDSTICK:
                cell += f" ({fmt_ratio(row['rays'] / ref['rays'])})"
            if rays and int(row.get("ray_count", rays)) < rays:
                cell += "¹"
                notes.add(f"¹ on a subset: every k-th ray of the set, at most {subset_limit} "
                          "(brute force is O(rays × triangles))")
            if row.get("agree", 1.0) < 0.999:
                cell += " ⚠"
                notes.add(f"⚠ {scene}/{s}: only {100 * row['agree']:.2f}% of hits agree with the reference")
            cells.append(cell)
        lines.append("| " + " | ".join(cells) + " |")
    if notes:
        lines.append("")
        lines.extend(sorted(notes))
    return lines


def build_table(table, errors, scenes, structures):
    lines = ["### Build", "",
             "Build time in ms (ratio to Embree's default build, same run) and structure bytes per triangle. "
             "rtcl: host build + flatten, without upload; Embree: geometry setup + rtcCommitScene "
             "(TBB, same thread count).", ""]
    head = ["scene", "triangles"] + [f"{s} ms" for s in structures] + [f"{s} B/tri" for s in structures]
    lines.append("| " + " | ".join(head) + " |")
    lines.append("|" + "|".join(["---"] + ["--:"] * (len(head) - 1)) + "|")
    notes = []
    for scene in scenes:
        rows = {s: table.get(("build", scene, None, s)) for s in structures}
        if not any(rows.values()):
            continue
        tris = next((int(r["triangles"]) for r in rows.values() if r and "triangles" in r), 0)
        ref = rows.get(YARDSTICK)
        times, sizes = [], []
        for s in structures:
            r = rows[s]
            if ("build", scene, None, s) in errors:
                notes.append(f"{scene}/{s}: {errors[('build', scene, None, s)]}")
            if not r:
                times.append("–")
                sizes.append("–")
                continue
            t = r.get("build_ms", r.get("real_time", 0.0))
            cell = f"{t:.1f}"
            if ref and s != YARDSTICK and ref.get("build_ms"):
                cell += f" ({fmt_ratio(t / ref['build_ms'])})"
            times.append(cell)
            sizes.append(f"{r['bytes_per_tri']:.1f}" if "bytes_per_tri" in r else "–")
        lines.append("| " + " | ".join([scene, f"{tris:,}"] + times + sizes) + " |")
    if notes:
        lines.append("")
        lines.extend(notes)
    return lines


def report(path):
    table, errors, context = load(path)
    keys = list(table) + list(errors)
    scenes = ordered([k[1] for k in keys], ["bunny", "dragon", "sponza", "sibenik"])
    structures = ordered([k[3] for k in keys], ["embree", "embree-high"])
    trace_structures = [s for s in structures if any(k[0] == "trace" and k[3] == s for k in keys)]
    build_structures = [s for s in structures if any(k[0] == "build" and k[3] == s for k in keys)]
    lines = ["## Benchmark results", ""]
    embree_threads = context.get("host_threads") if any(k[3].startswith(YARDSTICK) for k in keys) else None
    info = [("rtcl device", context.get("rtcl_device")), ("Embree", context.get("embree")),
            ("Embree threads", embree_threads), ("reference hits", context.get("reference")),
            ("image side (pixels)", context.get("image_size")),
            ("date", context.get("date")), ("host", context.get("host_name"))]
    lines.append("; ".join(f"{k}: {v}" for k, v in info if v))
    lines.append("")
    lines.append("Absolute figures drift between runs on a shared machine; compare ratios taken in one run.")
    lines.append("")
    for kind, title in KINDS:
        if any(k[0] == "trace" and k[2] == kind for k in keys):
            lines += trace_table(table, errors, kind, title, scenes, trace_structures,
                                 context.get("brute_rays", "$RTCL_BENCH_BRUTE_RAYS")) + [""]
    if build_structures:
        lines += build_table(table, errors, scenes, build_structures) + [""]
    return "\n".join(lines).rstrip("\n") + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", help="Google Benchmark JSON written by rtcl_bench")
    parser.add_argument("-o", "--output", help="also write the Markdown here")
    args = parser.parse_args()
    try:
        text = report(args.results)
    except (OSError, ValueError, KeyError) as e:
        sys.exit(f"report.py: {args.results}: {e}")
    sys.stdout.write(text)
    if args.output:
        with open(args.output, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()

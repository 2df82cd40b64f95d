#!/usr/bin/env python3
"""The build-scaling table of docs/benchmarks.md ("Build times") from
`rtcl bench` results (bench.json, schema rtcl-bench/1), one file per
process (bench/scaling.sh runs them): per scene and structure the host
build time, the peak memory the build adds per triangle (build_peak_bytes)
and the primary rays' rate, beside Embree's build of the same scene when
the file has the baseline (its builds paired with the structure's), and
the ratios rtcl / Embree.

    /usr/bin/python3 bench/scaling_table.py scaling/*/bench.json
"""
import argparse
import json


def median(xs):
    xs = sorted(xs)
    return 0.5 * (xs[(len(xs) - 1) // 2] + xs[len(xs) // 2])


def fmt(x, digits=0):
    return f"{x:,.{digits}f}" if x else "-"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("json", nargs="+", help="bench.json files written by `rtcl bench`")
    args = parser.parse_args()
    rows = []
    for path in args.json:
        with open(path) as f:
            data = json.load(f)
        if data.get("schema") != "rtcl-bench/1":
            raise SystemExit(f"{path}: not an rtcl bench file (schema {data.get('schema')!r})")
        prims = {s["name"]: s["triangles"] + s["spheres"] for s in data["scenes"]}
        embree = {b["scene"]: b for b in (data.get("embree") or {}).get("baselines", [])
                  if not b["packets"] and b["rays"] == "primary"}
        for c in data["cells"]:
            if c["rays"] != "primary":
                continue
            n = prims.get(c["scene"], 0) or 1
            e = embree.get(c["scene"])
            paired = c.get("embree") or {}
            rows.append({
                "scene": c["scene"], "n": n, "accel": c["accel"], "build": c["build_ms"],
                "peak": c.get("build_peak_bytes", 0) / n, "rate": c["mrays_per_s"]["kernel"]["median"],
                "ok": "ok" if c["check"]["ok"] else f"DISAGREES {c['check']['disagreeing']}/{c['check']['rays']}",
                # Embree's builds paired with the structure's (the ratio bench.md gives), else its own
                "e_build": (median(paired["build_ms_runs"]) if paired.get("build_ms_runs")
                            else e["build_ms"] if e else 0.0), "e_peak": e.get("build_peak_bytes", 0) / n if e else 0.0,
                "e_rate": e["mrays_per_s"]["trace"]["median"] if e else 0.0})
    rows.sort(key=lambda r: (r["scene"].split(":")[0], r["n"], r["accel"]))
    print("| scene | triangles | structure | build ms | peak B/tri | Mrays/s | Embree build ms | Embree peak B/tri "
          "| Embree Mrays/s | build / Embree | peak / Embree | check |")
    print("|---|--:|---|--:|--:|--:|--:|--:|--:|--:|--:|---|")
    for r in rows:
        build_ratio = f"{r['build'] / r['e_build']:.2f}×" if r["e_build"] else "-"
        peak_ratio = f"{r['peak'] / r['e_peak']:.2f}×" if r["e_peak"] and r["peak"] else "-"
        print(f"| {r['scene'].split(':')[0]} | {r['n']:,} | {r['accel']} | {fmt(r['build'])} | {fmt(r['peak'], 1)} "
              f"| {fmt(r['rate'], 3)} | {fmt(r['e_build'])} | {fmt(r['e_peak'], 1)} | {fmt(r['e_rate'], 3)} "
              f"| {build_ratio} | {peak_ratio} | {r['ok']} |")


if __name__ == "__main__":
    main()

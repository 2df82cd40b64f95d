#!/usr/bin/python3
"""Parallel efficiency and tile-size cost of `rtcl render` under mpirun on
this host, and the numbers behind the 8- and 64-rank model
(docs/rendering.md).

  flock /tmp/rtcl-bench.lock nice -n -20 /usr/bin/python3 bench/mpi_scaling.py [--build build] [--repeats 3]

Each rank gets its share of the cores: POCL_MAX_PTHREAD_COUNT = cores / N
(PoCL's worker threads), processes unbound (--bind-to none: Open MPI would
otherwise pin a single rank to one core). T(N, t) is the time from the first
tile handed out to the last tile in (the figure `rtcl render` prints as "in
X s" under mpirun) with N ranks of t PoCL threads each, the median of
--repeats runs interleaved over the configurations. Two efficiencies:
per core, T(1, 1) / (N T(N, 1)) (N ranks of one core against one rank of
one core), and on the whole machine, T(1, cores) / T(cores, 1) (the same
cores as one rank or as one rank per core: the cost of going through MPI).
The single-process render (no mpirun, all cores) is the baseline of both.
Per-tile costs come from the ranks' own Renderer::render times and rank 0's
hand-out-to-return times.
"""
import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

SUMMARY = re.compile(r"rays in ([0-9.]+) s")
SERVED = re.compile(r"rank 0 served (\d+) tiles from other ranks in ([0-9.]+) ms")
TILES = re.compile(r"(\d+) tiles of (\d+) px")
RANK = re.compile(r"rank (\d+) \(host [^,]*, device .*?\): .*?(\d+) tiles: rendering ([0-9.]+) ms \(slowest tile "
                  r"([0-9.]+) ms\), handed out to returned ([0-9.]+) ms")


def run(cmd, env):
    out = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"mpi_scaling: {' '.join(cmd)} failed ({out.returncode}):\n{out.stderr}")
    return out.stdout


def render(rtcl, ranks, threads, tile, args, workdir):
    env = dict(os.environ, POCL_MAX_PTHREAD_COUNT=str(threads))
    out_file = os.path.join(workdir, "scaling.png")
    base = [rtcl, "render", "-q", "-o", out_file] + args
    if ranks == 0:  # the single-process render, no MPI
        text = run(base, env)
        return {"seconds": float(SUMMARY.search(text).group(1))}
    mpirun = [shutil.which("mpirun"), "--allow-run-as-root", "--oversubscribe", "--bind-to", "none",
              "-x", "POCL_MAX_PTHREAD_COUNT", "-x", "POCL_CACHE_DIR", "-np", str(ranks)]
    text = run(mpirun + base + ["--tile", str(tile)], env)
    result = {"seconds": float(SUMMARY.search(text).group(1)), "tiles": int(TILES.search(text).group(1)),
              "ranks": []}
    served = SERVED.search(text)
    result["serve_ms_per_tile"] = float(served.group(2)) / int(served.group(1)) if int(served.group(1)) else 0.0
    for m in RANK.finditer(text):
        result["ranks"].append({"rank": int(m.group(1)), "tiles": int(m.group(2)), "render_ms": float(m.group(3)),
                                "slowest_ms": float(m.group(4)), "round_trip_ms": float(m.group(5))})
    return result


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", default="build")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--width", type=int, default=384)
    p.add_argument("--spp", type=int, default=4)
    p.add_argument("--tile", type=int, default=64)
    p.add_argument("--tiles", default="8,16,32,64,128", help="tile sizes of the tile-cost table (one rank per core)")
    p.add_argument("--cores", type=int, default=os.cpu_count())
    o = p.parse_args()
    rtcl = os.path.abspath(os.path.join(o.build, "rtcl"))
    os.environ.setdefault("POCL_CACHE_DIR", os.path.abspath(os.path.join(o.build, "pocl-cache-bench")))
    args = ["--width", str(o.width), "--spp", str(o.spp)]
    with tempfile.TemporaryDirectory() as work:
        render(rtcl, 1, o.cores, o.tile, args, work)  # warm PoCL's kernel cache
        # (ranks, PoCL threads per rank); ranks 0: the single process
        configs = [(0, o.cores), (1, o.cores), (1, 1), (o.cores, 1)]
        runs = {c: [] for c in configs}
        for _ in range(o.repeats):
            for c in configs:
                runs[c].append(render(rtcl, c[0], c[1], o.tile, args, work))
        med = {c: statistics.median(r["seconds"] for r in rs) for c, rs in runs.items()}
        single, one_core, machine = med[(0, o.cores)], med[(1, 1)], med[(1, o.cores)]
        print(f"default scene, {o.width}x{o.width}, {o.spp} spp, depth 5, tile {o.tile}; {o.cores} cores; "
              f"median of {o.repeats}\n")
        print("| ranks | PoCL threads per rank | T (s) | efficiency per core | efficiency on the machine | "
              "single process / T |")
        print("|---|---:|---:|---:|---:|---:|")
        for c in configs:
            n, t = c
            per_core = f"{one_core / (n * med[c]):.2f}" if n > 0 and t == 1 else ""
            on_machine = f"{machine / med[c]:.2f}" if n * t == o.cores else ""
            print(f"| {'single process' if n == 0 else n} | {t} | {med[c]:.3f} | {per_core} | {on_machine} | "
                  f"{single / med[c]:.2f} |")
        # Per-tile figures of the runs with one rank per core: render time on
        # rank 1, and rank 0's hand-out-to-return time of rank 1's tiles less
        # rank 1's own render time (messages, waiting for rank 0's poll).
        split = runs[(o.cores, 1)]
        remote = [r for run_ in split for r in run_["ranks"] if r["rank"] == 1 and r["tiles"] > 0]
        render_per_tile = statistics.median(r["render_ms"] / r["tiles"] for r in remote) if remote else 0.0
        comm_per_tile = statistics.median((r["round_trip_ms"] - r["render_ms"]) / r["tiles"] for r in remote) if remote else 0.0
        tiles = split[0]["tiles"]
        serve = statistics.median(r["serve_ms_per_tile"] for r in split)
        print(f"\nN = {o.cores}: {tiles} tiles; rank 1 per tile: rendering {render_per_tile:.2f} ms, "
              f"communication and hand-out {comm_per_tile:.3f} ms; rank 0's main thread per remote tile "
              f"{serve:.4f} ms (medians)\n")

        sizes = [int(t) for t in o.tiles.split(",")]
        sweep = {t: [] for t in sizes}
        model = {}
        for _ in range(o.repeats):
            for t in sizes:
                sweep[t].append(render(rtcl, o.cores, 1, t, args, work))
        print(f"| tile (px) | tiles | T (s), {o.cores} ranks | relative to the best | rank 1 ms per tile: rendering | "
              "communication | rank 0 serving |")
        print("|---:|---:|---:|---:|---:|---:|---:|")
        best = min(statistics.median(r["seconds"] for r in rs) for rs in sweep.values())
        for t in sizes:
            rs = sweep[t]
            m = statistics.median(r["seconds"] for r in rs)
            rem = [x for r in rs for x in r["ranks"] if x["rank"] == 1 and x["tiles"] > 0]
            rt = statistics.median(x["render_ms"] / x["tiles"] for x in rem) if rem else float("nan")
            ct = statistics.median((x["round_trip_ms"] - x["render_ms"]) / x["tiles"] for x in rem) if rem else float("nan")
            sv = statistics.median(r["serve_ms_per_tile"] for r in rs)
            slowest = statistics.median(max(x["slowest_ms"] for x in r["ranks"]) for r in rs)
            model[t] = {"tiles": rs[0]["tiles"], "t": rt, "o": ct, "q": sv, "t_max": slowest}
            print(f"| {t} | {rs[0]['tiles']} | {m:.3f} | {m / best:.2f} | {rt:.2f} | {ct:.3f} | {sv:.4f} |")
        # The model (docs/rendering.md): n tiles of mean
        # render time t and overhead o per tile, shared by N ranks of one
        # core each, plus the tail of the slowest tile; rank 0 serves one
        # tile in q, so it cannot finish in less than n q.
        print("\nModel, same image, N ranks of one core each (setup and scene broadcast not included):\n")
        print("| tile (px) | N | predicted T (ms) | predicted efficiency | rank 0 busy serving |")
        print("|---:|---:|---:|---:|---:|")
        for t in sizes:
            c = model[t]
            for n in (2, 8, 64):
                work = c["tiles"] * c["t"]
                T = max(c["tiles"] * (c["t"] + c["o"]) / n + c["t_max"], c["tiles"] * c["q"])
                print(f"| {t} | {n} | {T:.0f} | {work / (n * T):.2f} | {c['tiles'] * c['q'] / T:.1%} |")


if __name__ == "__main__":
    main()

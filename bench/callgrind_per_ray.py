#!/usr/bin/env python3
"""Per-ray event counts of rtcl's single-ray BVH kernels and of Embree, from
callgrind runs of rtcl_kernel_ab, one scene and one ray set per run:

  for set in primary shadow diffuse; do
    RTCL_BENCH_RES=256 AB_SETS=$set valgrind --tool=callgrind --branch-sim=yes \
        --cache-sim=yes --callgrind-out-file=cg.sponza.$set \
        ./build/bench/rtcl_kernel_ab sponza 1 kernels
  done
  python3 bench/callgrind_per_ray.py cg.sponza.primary cg.sponza.shadow cg.sponza.diffuse

Embree: the inclusive events of rtcIntersect1 / rtcOccluded1 over their
calls (one per ray; rtcl_kernel_ab traces the set once with Embree). rtcl:
the inclusive events of the PoCL work-group function of the trace kernel
(the kernel's whole work, work-item loop included) and of its traversal
function alone, over the calls of begin_trace in the same kernel object
(one per ray traced: kernels/shared/trace.h). rtcl_kernel_ab also traces
the scene's primary rays once with the closest-hit kernel to spawn the
shadow and diffuse rays; for a diffuse run that trace shares the kernel,
so its share is taken out with the per-ray events of the same scene's
primary run, which must be among the files (same image size).

Events (callgrind's models, not this host's counters): Ir instructions, Bc
/ Bcm conditional branches / those its simple predictor mispredicts, D1mr
first-level data read misses (32 KiB, 8-way), DLmr last-level data read
misses (the size --LL gives: --LL=524288,8,64 models this host's 512 KiB
second-level cache, whose misses go to the 32 MiB third level); "-" where
the run did not simulate them.
"""
import collections
import re
import sys

EVENTS = ("Ir", "Bc", "Bcm", "D1mr", "DLmr")


class Run:
    """One callgrind file: inclusive events and calls per (object, function)."""

    def __init__(self, path):
        self.path = path
        lines = open(path).read().splitlines()
        self.events = next(l.split()[1:] for l in lines if l.startswith("events:"))
        # rtcl_kernel_ab SCENES ROUNDS VERSIONS...: the scenes, as a key
        self.scenes = next((l.split()[2] for l in lines if l.startswith("cmd:") and len(l.split()) > 2), path)
        positions = next((len(l.split()) - 1 for l in lines if l.startswith("positions:")), 1)
        objects, functions = {}, {}
        callee_object = None
        self.calls = collections.defaultdict(int)
        self.cost = collections.defaultdict(collections.Counter)
        for i, line in enumerate(lines):
            m = re.match(r"c?ob=\((\d+)\)(?: (.*))?$", line)
            if m:
                if m.group(2):
                    objects[m.group(1)] = m.group(2)
                if line.startswith("cob="):
                    callee_object = objects[m.group(1)]
                else:
                    current_object = objects[m.group(1)]
                continue
            m = re.match(r"c?fn=\((\d+)\)(?: (.*))?$", line)
            if m and m.group(2):
                functions[m.group(1)] = m.group(2)
            if line.startswith("fn="):
                callee_object = None
            if not line.startswith("cfn="):
                continue
            key = (callee_object or current_object, functions[m.group(1)])
            callee_object = None
            j = i + 1
            while not lines[j].startswith("calls="):
                j += 1
            self.calls[key] += int(lines[j].split("=")[1].split()[0])
            costs = lines[j + 1].split()[positions:]  # trailing zeros may be left out
            for event, value in zip(self.events, costs):
                self.cost[key][event] += int(value)

    def embree(self):
        """(API, rays, events) of Embree's single-ray call."""
        for (obj, name), calls in self.calls.items():
            if name in ("rtcIntersect1", "rtcOccluded1") and calls:
                return name, calls, self.cost[(obj, name)]
        sys.exit(f"{self.path}: no rtcIntersect1 / rtcOccluded1 calls (rtcl_kernel_ab built without Embree?)")

    def kernel(self, query):
        """(rays, whole kernel events, traversal events) of the trace_<query>_ kernels."""
        rays, whole, traversal = 0, collections.Counter(), collections.Counter()
        for (obj, name), calls in self.calls.items():
            if f"/trace_{query}_" not in obj:
                continue
            if name == "begin_trace":
                rays += calls
            elif name.startswith("_pocl_kernel_trace_") and name.endswith("_workgroup"):
                whole.update(self.cost[(obj, name)])
            elif name.endswith("_traverse"):
                traversal.update(self.cost[(obj, name)])
        if rays == 0:
            sys.exit(f"{self.path}: no begin_trace calls in a trace_{query} kernel (inlined by this PoCL?)")
        return rays, whole, traversal


def per_ray(events, rays):
    return {e: events[e] / rays for e in EVENTS}


def main():
    paths = sys.argv[1:]
    if not paths:
        sys.exit(__doc__)
    runs = [Run(p) for p in paths]
    # primary runs: every closest-hit ray they trace is a primary ray
    primary = {}
    for run in runs:
        api, rays, _ = run.embree()
        closest_rays, whole, traversal = run.kernel("closest")
        if api == "rtcIntersect1" and closest_rays % rays == 0:
            primary[(run.scenes, rays)] = (per_ray(whole, closest_rays), per_ray(traversal, closest_rays))
    print("| file | side | rays | " + " | ".join(f"{e}/ray" for e in EVENTS) + " |")
    print("|---|---|--:|" + "--:|" * len(EVENTS))
    for run in runs:
        api, rays, embree_events = run.embree()
        rows = [(f"Embree {api}", rays, per_ray(embree_events, rays))]
        query = "any" if api == "rtcOccluded1" else "closest"
        traced, whole, traversal = run.kernel(query)
        whole_per_ray, traversal_per_ray = per_ray(whole, traced), per_ray(traversal, traced)
        if query == "closest" and traced % rays:
            # a diffuse run: one spawning trace of the primary rays, then this set's launches
            spawn = next((n for scenes, n in primary if scenes == run.scenes and (traced - n) % rays == 0), None)
            if spawn is None or traced <= spawn:
                sys.exit(f"{run.path}: a secondary set; give the same scene's primary run too")
            spawned_by = primary[(run.scenes, spawn)]
            for mine, theirs, events in ((whole_per_ray, spawned_by[0], whole),
                                         (traversal_per_ray, spawned_by[1], traversal)):
                for e in EVENTS:
                    mine[e] = (events[e] - spawn * theirs[e]) / (traced - spawn)
            traced -= spawn
        rows.append(("rtcl kernel", traced, whole_per_ray))
        rows.append(("rtcl traversal", traced, traversal_per_ray))
        for side, n, values in rows:
            cells = " | ".join(f"{values[e]:.1f}" if e in run.events else "-" for e in EVENTS)
            print(f"| {run.path} | {side} | {n} | {cells} |")


if __name__ == "__main__":
    main()

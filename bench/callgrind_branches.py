#!/usr/bin/env python3
"""The conditional branches of rtcl's trace kernels that callgrind's branch
model mispredicts most, instruction by instruction, from a callgrind run of
rtcl_kernel_ab with --dump-instr=yes:

  mkdir -p pocl-cache
  POCL_CACHE_DIR=pocl-cache RTCL_BENCH_RES=192 AB_SETS=diffuse AB_NO_EMBREE=1 \\
      valgrind --tool=callgrind --branch-sim=yes --dump-instr=yes \\
      --callgrind-out-file=cg.sponza.diffuse ./build/bench/rtcl_kernel_ab sponza 1 kernels
  python3 bench/callgrind_branches.py cg.sponza.diffuse [FUNCTION_SUFFIX [QUERY [TOP]]]

FUNCTION_SUFFIX (default `_traverse`) picks the functions of the kernel
objects of QUERY (`closest`, the default, or `any`: PoCL's cached
trace_QUERY_*.so, which must still be in POCL_CACHE_DIR). For the TOP
(default 20) branch instructions by mispredicts it prints the instruction
and the two before it, as objdump disassembles that object, so that each
site can be matched with the kernel's source, and its executions (Bc),
mispredicts (Bcm, callgrind's simple predictor, not this host's), their
rate and their share of the functions' mispredicts. A diffuse run also
holds the trace of the primary rays that spawned the set; shares and rates
mix both.
"""
import collections
import re
import subprocess
import sys


def position(token, last):
    """A callgrind position: absolute (decimal or 0x hex), +N / -N relative, or * (the same)."""
    if token == "*":
        return last
    if token[0] in "+-":
        return last + int(token, 0)
    return int(token, 0)


def branch_costs(path, suffix, query):
    """{(object, address): [Bc, Bcm]} over the functions ending in suffix in trace_<query>_ objects."""
    objects, functions = {}, {}
    events, width = None, 1
    obj = fn = None
    in_call = False
    last = [0, 0]
    costs = collections.defaultdict(lambda: [0, 0])
    try:
        lines = open(path).read().splitlines()
    except OSError as e:
        sys.exit(f"{path}: cannot read ({e.strerror})")
    if not any(l.startswith("positions:") and l.split()[1:2] == ["instr"] for l in lines):
        sys.exit(f"{path}: positions are not instruction addresses (run callgrind with --dump-instr=yes)")
    for line in lines:
        if line.startswith("events:"):
            events = line.split()[1:]
            continue
        if line.startswith("positions:"):
            width = len(line.split()) - 1
            continue
        m = re.match(r"(c?)(ob|fn)=\((\d+)\)(?: (.*))?$", line)
        if m:
            table = objects if m.group(2) == "ob" else functions
            if m.group(4):
                table[m.group(3)] = m.group(4)
            if not m.group(1):
                if m.group(2) == "ob":
                    obj = table[m.group(3)]
                else:
                    fn = table[m.group(3)]
            continue
        if line.startswith("calls="):
            in_call = True  # the next cost line is the call's inclusive cost
            continue
        if not line or line[0] not in "0123456789+-*":
            continue
        tokens = line.split()
        for k in range(width):
            last[k] = position(tokens[k], last[k])
        if in_call:
            in_call = False
            continue
        if not (obj and fn and fn.endswith(suffix) and f"/trace_{query}_" in obj):
            continue
        values = dict(zip(events, map(int, tokens[width:])))
        if values.get("Bc"):
            cell = costs[(obj, last[0])]
            cell[0] += values["Bc"]
            cell[1] += values.get("Bcm", 0)
    if events is None or "Bcm" not in events:
        sys.exit(f"{path}: no Bcm events (run callgrind with --branch-sim=yes)")
    return costs


def disassembly(obj):
    """[(address, text)] of the object's code, in address order."""
    out = subprocess.run(["objdump", "-d", "--no-show-raw-insn", obj], capture_output=True, text=True, check=True)
    lines = []
    for line in out.stdout.splitlines():
        m = re.match(r"\s*([0-9a-f]+):\s+(.*)$", line)
        if m:
            lines.append((int(m.group(1), 16), " ".join(m.group(2).split())))
    return lines


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    path = sys.argv[1]
    suffix = sys.argv[2] if len(sys.argv) > 2 else "_traverse"
    query = sys.argv[3] if len(sys.argv) > 3 else "closest"
    top = int(sys.argv[4]) if len(sys.argv) > 4 else 20
    costs = branch_costs(path, suffix, query)
    if not costs:
        sys.exit(f"{path}: no branches in functions *{suffix} of trace_{query}_ kernels (run with --dump-instr=yes)")
    total = sum(bcm for _, bcm in costs.values())
    code = {obj: disassembly(obj) for obj in {obj for obj, _ in costs}}
    print(f"{path}: {total} mispredicted conditional branches in *{suffix} (trace_{query}_ kernels)\n")
    print("| address | instructions (the branch last) | Bc | Bcm | rate | share |")
    print("|---|---|--:|--:|--:|--:|")
    for (obj, address), (bc, bcm) in sorted(costs.items(), key=lambda kv: -kv[1][1])[:top]:
        lines = code[obj]
        at = next((i for i, (a, _) in enumerate(lines) if a == address), None)
        text = " ; ".join(t for _, t in lines[max(0, at - 2):at + 1]) if at is not None else "?"
        print(f"| {address:#x} | `{text}` | {bc} | {bcm} | {bcm / bc:.2f} | {100 * bcm / total:.1f}% |")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""The Python module against rtcl's C++ host-array path, Embree and Open3D
(docs/python.md, "Performance"; docs/benchmarks.md).

Per scene (bunny, dragon, sponza), the benchmark camera's size x size
primary rays (bench/support/scene_catalog.cpp, ray_sets.cpp) and, from
their hits, one shadow ray towards the scene's light and one diffuse ray
each, built here as ray_sets.cpp builds them. Timed in Python, numpy
conversion included (median of --repeat calls after one warm-up call):
cast_rays (camera rays: plain, coherent=True, and in a scene with an
instance, which traces two levels; diffuse rays) and test_occlusions
(shadow rays). The plain cast_rays on camera rays and test_occlusions on
the shadow rays take turns, call by call, with the library's own C++
host-array call on the same rays (Accel::trace, closest hit and any hit,
on Ray records into Hit records, packed once, outside the timing: the
module's internal rtcl._HostArrayBaseline), so that each Python / C++
ratio compares calls made back to back. From the same session,
`rtcl bench --accel bvh --embree-threads 2`: Embree's rtcIntersect1 /
rtcOccluded1 on 2 threads (the count is printed) on the same three ray
sets.
Then --points points uniform over the bunny's box grown by 10% per side:
compute_distance and compute_closest_points against Open3D's (Debian's
python3-open3d; its ray queries miss every ray on Debian 12, its point
queries work), interleaved call by call; compute_signed_distance and
compute_occupancy beside them.

  /usr/bin/python3 bench/python_bench.py [--build build] [--scene bunny,dragon,sponza]
      [--size 1024] [--repeat 5] [--rounds 1] [--points 1000000] [--no-cpp] [--no-open3d] [--json FILE]

Run it on a quiet machine: it reports rates, and other work on the cores
changes them. --rounds N takes every timing N times in turn and reports
the median of the rounds. The module is imported from BUILD/python unless PYTHONPATH
already finds one.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

# The threads Embree traces on (rtcl bench --embree-threads): the issue's
# baseline is Embree on 2 threads, whatever the machine has.
EMBREE_THREADS = 2

# bench/support/scene_catalog.cpp: file, camera (eye, target, up, vertical
# fov in degrees), point light.
SCENES = {
    "bunny": ("stanford_bunny/bunny.obj", ((-0.0168, 0.110, 0.36), (-0.0168, 0.110, -0.0015), (0, 1, 0), 30.0),
              (0.15, 0.35, 0.30)),
    "dragon": ("stanford_dragon_100k/dragon.obj", ((0.0, 5.5, 28.0), (0.0, 4.97, 0.0), (0, 1, 0), 30.0),
               (-10.0, 20.0, 20.0)),
    "sponza": ("sponza/sponza.obj", ((13.0, 2.0, 0.0), (-10.0, 4.0, 0.0), (0, 1, 0), 60.0), (0.0, 13.0, 1.0)),
}


def load_obj(path):
    """Vertices (float32) and triangles (uint32) of an OBJ file's v and f
    lines, polygons fanned."""
    vertices, faces = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                vertices.append(line.split()[1:4])
            elif line.startswith("f "):
                refs = [int(r.split("/")[0]) for r in line.split()[1:]]
                refs = [r - 1 if r > 0 else len(vertices) + r for r in refs]
                faces.extend((refs[0], refs[k], refs[k + 1]) for k in range(1, len(refs) - 1))
    return np.array(vertices, np.float32), np.array(faces, np.uint32)


def primary_rays(camera, size):
    """ray_sets.cpp's primary_rays in float32: unit directions through the
    pixel centres, rows from the top; (size * size, 6)."""
    eye, target, up, fov = camera
    f32 = np.float32
    eye, target, up = (np.array(x, f32) for x in (eye, target, up))
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, forward)
    half_h = f32(np.tan(f32(0.5) * np.radians(f32(fov))))
    half_w = half_h
    k = np.arange(size, dtype=f32) + f32(0.5)
    sx = (f32(2.0) * k / f32(size) - f32(1.0)) * half_w
    sy = (f32(1.0) - f32(2.0) * k / f32(size)) * half_h
    d = forward[None, None, :] + sx[None, :, None] * right + sy[:, None, None] * true_up
    d /= np.linalg.norm(d, axis=2, keepdims=True)
    rays = np.empty((size, size, 6), f32)
    rays[..., :3], rays[..., 3:] = eye, d
    return rays.reshape(-1, 6)


def rtcl_hash(x):
    x = x.astype(np.uint32)
    x ^= x >> np.uint32(16)
    x *= np.uint32(0x7FEB352D)
    x ^= x >> np.uint32(15)
    x *= np.uint32(0x846CA68B)
    x ^= x >> np.uint32(16)
    return x


def secondary_rays(vertices, triangles, primary, hits, light):
    """ray_sets.cpp's secondary_rays: from each primary hit, a shadow ray to
    the light (t in [0, 1]) and a cosine-distributed diffuse ray (hashed from
    the pixel index), leaving the surface along the facing normal."""
    f32 = np.float32
    index = np.nonzero(hits["primitive_ids"] != np.uint32(0xFFFFFFFF))[0]
    prim = hits["primitive_ids"][index]
    v0, v1, v2 = (vertices[triangles[prim, k]] for k in range(3))
    uv = hits["primitive_uvs"][index]
    p = (f32(1.0) - uv[:, :1] - uv[:, 1:]) * v0 + uv[:, :1] * v1 + uv[:, 1:] * v2
    n = np.cross(v1 - v0, v2 - v0)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    flip = np.einsum("ij,ij->i", n, primary[index, 3:]) > 0
    n[flip] = -n[flip]
    extent = np.max(vertices.max(axis=0) - vertices.min(axis=0))
    offset = f32(1e-4) * np.maximum(np.max(np.abs(p), axis=1), f32(1e-2) * extent)
    origin = p + offset[:, None] * n
    shadow = np.zeros((len(index), 6), f32)
    shadow[:, :3], shadow[:, 3:] = origin, np.asarray(light, f32) - origin
    pixel = index.astype(np.uint32)
    u1 = (rtcl_hash(np.uint32(2) * pixel + np.uint32(0x9E3779B9)) >> np.uint32(8)).astype(f32) * f32(2.0 ** -24)
    u2 = (rtcl_hash(np.uint32(2) * pixel + np.uint32(0x9E3779BA)) >> np.uint32(8)).astype(f32) * f32(2.0 ** -24)
    # Orthonormal basis (Duff et al. 2017) and Malley's method.
    sign = np.copysign(f32(1.0), n[:, 2])
    a = f32(-1.0) / (sign + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t1 = np.stack([f32(1.0) + sign * n[:, 0] * n[:, 0] * a, sign * b, -sign * n[:, 0]], axis=1)
    t2 = np.stack([b, sign + n[:, 1] * n[:, 1] * a, -n[:, 1]], axis=1)
    r, phi = np.sqrt(u1), f32(6.28318530718) * u2
    d = (r * np.cos(phi))[:, None] * t1 + (r * np.sin(phi))[:, None] * t2 + \
        np.sqrt(np.maximum(f32(0.0), f32(1.0) - u1))[:, None] * n
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    diffuse = np.empty_like(shadow)
    diffuse[:, :3], diffuse[:, 3:] = origin, d
    return shadow, diffuse


def median_ms(call, repeat):
    call()  # warm-up: kernel builds, first touch of the buffers
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        call()
        times.append((time.perf_counter() - start) * 1e3)
    return float(np.median(times))


def paired_ms(call_a, call_b, repeat):
    """Median ms of two calls taking turns, call by call (one warm-up
    pair; the order alternates pair by pair), and the median of the pairs'
    ratios b / a: each ratio compares two calls made back to back, so a
    change in the machine's load falls on both."""
    call_a()
    call_b()
    a, b = [], []
    for k in range(repeat):
        for first in ((call_a, a), (call_b, b))[:: 1 if k % 2 == 0 else -1]:
            start = time.perf_counter()
            first[0]()
            first[1].append((time.perf_counter() - start) * 1e3)
    return float(np.median(a)), float(np.median(b)), float(np.median([y / x for x, y in zip(a, b)]))


def interleaved_ms(calls, repeat):
    """Median ms of each call, the calls taking turns (one warm-up round)."""
    times = [[] for _ in calls]
    for round_ in range(repeat + 1):
        for k, call in enumerate(calls):
            start = time.perf_counter()
            call()
            if round_ > 0:
                times[k].append((time.perf_counter() - start) * 1e3)
    return [float(np.median(t)) for t in times]


def rtcl_bench(build, scenes, size, repeat, scenes_dir):
    """`rtcl bench --accel bvh --embree-threads EMBREE_THREADS` on the three
    ray sets: Embree's (api, threads, Mrays/s) per (scene, ray set)."""
    exe = build / "rtcl"
    if not exe.exists():
        print(f"python_bench: {exe} not built", file=sys.stderr)
        return {}
    with tempfile.TemporaryDirectory() as out:
        subprocess.run([str(exe), "bench", "--accel", "bvh", "--scene", ",".join(scenes), "--rays",
                        "primary,shadow,diffuse", "--size", str(size), "--repeat", str(repeat), "--check-rays", "0",
                        "--embree-threads", str(EMBREE_THREADS),
                        "--device", "0", "--scenes-dir", str(scenes_dir), "-o", out], check=True, capture_output=True, text=True)
        report = json.loads((Path(out) / "bench.json").read_text())
    rates = {}
    for b in (report.get("embree") or {}).get("baselines", []):
        if not b.get("packets"):
            rates[(b["scene"], b["rays"])] = (b["api"], b["threads"], b["mrays_per_s"]["trace"]["median"])
    for c in report["cells"]:
        rates[(c["scene"], c["rays"], "rtcl")] = c["mrays_per_s"]["kernel"]["median"]
    return rates


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default=str(REPO / "build"), help="build directory (module, rtcl, benchmarks)")
    parser.add_argument("--scenes-dir", default=os.environ.get("RTCL_SCENES_DIR", str(REPO.parent / "shared" / "scenes")))
    parser.add_argument("--scene", default="bunny,dragon,sponza")
    parser.add_argument("--size", type=int, default=1024, help="camera rays: size x size")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--rounds", type=int, default=1,
                        help="every timing taken this many times in turn")
    parser.add_argument("--points", type=int, default=1_000_000)
    parser.add_argument("--no-cpp", action="store_true", help="leave out rtcl bench (the Embree figures)")
    parser.add_argument("--no-open3d", action="store_true")
    parser.add_argument("--json", help="also write the figures to this file")
    args = parser.parse_args()
    build = Path(args.build)
    sys.path.insert(0, str(build / "python"))
    import rtcl

    scenes = args.scene.split(",")
    for s in scenes:
        if s not in SCENES:
            parser.error(f"--scene {s}: unknown (known: {', '.join(SCENES)})")
    device = rtcl.devices()[0]["name"]
    n = args.size * args.size
    print(f"device: {device}; {args.size} x {args.size} camera rays per scene; medians of {args.repeat} calls\n")
    results = {"device": device, "size": args.size, "repeat": args.repeat, "embree_threads_requested": EMBREE_THREADS,
               "rays": {}, "points": {}}

    prepared = {}
    for name in scenes:
        file, camera, light = SCENES[name]
        v, f = load_obj(Path(args.scenes_dir) / file)
        scene = rtcl.RaycastingScene()
        scene.add_triangles(v, f)
        camera_rays = primary_rays(camera, args.size)
        hits = scene.cast_rays(camera_rays)  # builds the structure
        shadow, diffuse = secondary_rays(v, f, camera_rays, hits, light)
        # The same mesh in a scene with instances: the mesh where its
        # vertices are and one copy out of view, traced through two levels.
        instanced = rtcl.RaycastingScene()
        instanced.add_triangles(v, f)
        away = np.eye(4)
        away[:3, 3] = 100.0 * (v.max(axis=0) - v.min(axis=0))
        instanced.add_instance(0, away)
        # The library's C++ host-array call on the same camera rays, timed
        # in this process, call by call with cast_rays.
        # And its any-hit call on the shadow rays (t in [0, 1]), call by
        # call with test_occlusions.
        baselines = {"primary": rtcl._HostArrayBaseline(scene, camera_rays).trace,
                     "shadow": rtcl._HostArrayBaseline(scene, shadow, 0.0, 1.0).occluded}
        prepared[name] = (scene, instanced, camera_rays, shadow, diffuse, baselines)
        print(f"{name}: {len(f)} triangles, {len(shadow)} shadow and diffuse rays", flush=True)

    mrays = lambda count, ms: count / (ms * 1e3)
    rounds = []
    for _ in range(args.rounds):
        python_rates, cpp = {}, {}
        for name, (scene, instanced, camera_rays, shadow, diffuse, baselines) in prepared.items():
            python_ms, cpp_ms, ratio = paired_ms(lambda: scene.cast_rays(camera_rays), baselines["primary"],
                                                 args.repeat)
            shadow_ms, shadow_cpp_ms, shadow_ratio = paired_ms(lambda: scene.test_occlusions(shadow, 0.0, 1.0),
                                                               baselines["shadow"], args.repeat)
            cpp[name] = {"primary": {"host": mrays(n, cpp_ms), "ratio": ratio},
                         "shadow": {"host": mrays(len(shadow), shadow_cpp_ms), "ratio": shadow_ratio}}
            python_rates[name] = {
                "primary": mrays(n, python_ms),
                "primary coherent": mrays(n, median_ms(lambda: scene.cast_rays(camera_rays, coherent=True),
                                                       args.repeat)),
                "primary instanced": mrays(n, median_ms(lambda: instanced.cast_rays(camera_rays), args.repeat)),
                "shadow": mrays(len(shadow), shadow_ms),
                "diffuse": mrays(len(diffuse), median_ms(lambda: scene.cast_rays(diffuse), args.repeat)),
            }
        rounds.append((python_rates, cpp))
    embree = {} if args.no_cpp else rtcl_bench(build, scenes, args.size, args.repeat, args.scenes_dir)
    median = lambda xs: float(np.median(xs)) if xs else None
    python_rates = {name: {rays: median([r[0][name][rays] for r in rounds]) for rays in rounds[0][0][name]}
                    for name in scenes}
    paired = ("primary", "shadow")  # the ray sets timed in turn with the C++ host-array call
    hosts = {(name, kind): [r[1][name][kind]["host"] for r in rounds] for name in scenes for kind in paired}
    threads = sorted({b[1] for b in embree.values() if isinstance(b, tuple)})
    results["embree_threads"] = threads
    if not args.no_cpp:
        print(f"\nEmbree (rtcl bench --embree-threads {EMBREE_THREADS}): "
              f"{', '.join(map(str, threads)) or 'no'} thread(s) as reported")
    print(f"\n{args.rounds} round(s): rates are medians over the rounds; Python/C++ (primary cast_rays and "
          "shadow test_occlusions against the C++ host-array call, closest hit and any hit, taking turns call "
          "by call) the median over the rounds of each round's median pair ratio")

    embree_head = f"Embree ({'/'.join(map(str, threads)) or EMBREE_THREADS} threads)"
    print(f"\n| scene | rays | Python Mrays/s | C++ host arrays | Python/C++ | {embree_head} | Python/Embree |")
    print("|---|---|---|---|---|---|---|")
    for name in scenes:
        for rays, rate in python_rates[name].items():
            kind = rays.split()[0]
            host = median(hosts[(name, kind)]) if kind in paired else None
            if host and rays in paired:
                ratio = median([r[1][name][kind]["ratio"] for r in rounds])
            elif host:  # coherent and instanced camera rays against the plain C++ call
                ratio = median([r[0][name][rays] / r[1][name][kind]["host"] for r in rounds])
            else:
                ratio = None
            base = embree.get((name, kind))
            cells = [name, rays + (" (test_occlusions)" if kind == "shadow" else " (cast_rays)"), f"{rate:.2f}",
                     f"{host:.2f}" if host else "-", f"{ratio:.2f}" if host else "-",
                     f"{base[2]:.2f} {base[0]}" if base else "-", f"{rate / base[2]:.2f}" if base else "-"]
            print("| " + " | ".join(cells) + " |")
            results["rays"][f"{name} {rays}"] = {"python": rate, "cpp_host": host, "python_over_cpp": ratio,
                                                 "embree": base[2] if base else None,
                                                 "embree_threads": base[1] if base else None}

    if args.rounds > 1:
        for name in scenes:
            for kind in paired:
                each = [r[1][name][kind]["ratio"] for r in rounds]
                print(f"{name} {kind} Python/C++ by round: " + ", ".join(f"{x:.2f}" for x in each))
                results["rays"][f"{name} {kind}"]["ratio_by_round"] = each

    # Point queries on the bunny.
    v, f = load_obj(Path(args.scenes_dir) / SCENES["bunny"][0])
    lo, hi = v.min(axis=0), v.max(axis=0)
    points = np.random.default_rng(1).uniform(lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo),
                                              (args.points, 3)).astype(np.float32)
    scene = rtcl.RaycastingScene()
    scene.add_triangles(v, f)
    ours = [lambda: scene.compute_distance(points), lambda: scene.compute_closest_points(points)]
    names = ["compute_distance", "compute_closest_points"]
    print(f"\nbunny, {args.points} points over its box + 10%: Mpoints/s\n")
    print("| query | rtcl | Open3D | rtcl/Open3D |")
    print("|---|---|---|---|")
    if args.no_open3d:
        times = [median_ms(call, args.repeat) for call in ours]
        o3d_times = [None, None]
    else:
        import open3d as o3d
        ref = o3d.t.geometry.RaycastingScene()
        ref.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f))
        tensor = o3d.core.Tensor(points)
        theirs = [lambda: ref.compute_distance(tensor).numpy(),
                  lambda: {k: x.numpy() for k, x in ref.compute_closest_points(tensor).items()}]
        both = interleaved_ms([ours[0], theirs[0], ours[1], theirs[1]], args.repeat)
        times, o3d_times = both[0::2], both[1::2]
    for query, ms, o3d_ms in zip(names, times, o3d_times):
        rate = args.points / (ms * 1e3)
        other = args.points / (o3d_ms * 1e3) if o3d_ms else None
        print(f"| {query} | {rate:.3f} | {f'{other:.3f}' if other else '-'} | "
              f"{f'{rate / other:.2f}' if other else '-'} |")
        results["points"][query] = {"rtcl": rate, "open3d": other}
    for query, call in [("compute_signed_distance", lambda: scene.compute_signed_distance(points)),
                        ("compute_signed_distance nsamples=3",
                         lambda: scene.compute_signed_distance(points, nsamples=3)),
                        ("compute_occupancy", lambda: scene.compute_occupancy(points))]:
        rate = args.points / (median_ms(call, args.repeat) * 1e3)
        print(f"| {query} | {rate:.3f} | - | - |")
        results["points"][query] = {"rtcl": rate}
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=2) + "\n")


if __name__ == "__main__":
    main()

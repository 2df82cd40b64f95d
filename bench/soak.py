#!/usr/bin/python3
"""Soak run: memory stays flat over a long run (docs/benchmarks.md, "Soak").

Not a test and not in CI: it takes minutes to tens of minutes. Two phases,
each one process, run one after the other:

  render  `rtcl render --builtin forest --frames 0:F-1 -v`: F small images
          (--width, 1 sample a pixel) of the forest of 10,000 bunny
          instances in one process (one renderer; each frame re-places the
          moving instances and rebuilds the top level).
  rays    `rtcl_billion_rays_bench --rays R --batch B`: R rays through the
          host-array API in batches of B (bench/rays/billion_rays_bench.cpp).

While each phase runs, the process's resident memory (VmRSS of
/proc/PID/status) is sampled every --interval seconds; the device buffers
rtcl holds (Device::allocated_bytes) come from the process's own reports:
the render's `-v` line after each frame, the bench's JSON line after each
batch. A phase's first sample is its first after warm-up (render: once
--warmup-frames frames are written; rays: after the first batch), its last
sample the last before its last frame or batch is reported (not the
teardown); device bytes are compared between the same two reports. Its
memory is flat when the last sample is at most --tolerance (a fraction,
default 0.05) above or below the first, for host RSS and for device bytes
alike.

Exit status: 0 when both phases ran and are flat; 1 when a phase's memory
is not flat; 2 when a phase failed (its own exit status and output tail are
printed). A summary goes to stdout and, with the samples, to --out
(soak.json, render_samples.csv, rays_samples.csv).

  /usr/bin/python3 bench/soak.py [--build build] [--frames 1000] [--rays 1e9] [--batch 16777216]
                                 [--width 64] [--interval 1] [--tolerance 0.05] [--out DIR]
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FRAME_DEVICE = re.compile(r"^rtcl render: (.*): ([0-9.]+) MiB of device buffers held$")


def rss_bytes(pid):
    """VmRSS of a live process in bytes, or None once it has gone."""
    try:
        with open(f"/proc/{pid}/status") as status:
            for line in status:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        return None
    return None


WARMING, RUNNING, DONE = 0, 1, 2


def run_sampled(cmd, env, log_path, interval, stage):
    """Runs cmd with stdout and stderr into log_path, sampling its RSS.

    stage(log_text) says where the run is: WARMING (before the reference),
    RUNNING, or DONE (its last frame or batch reported: tearing down).
    The RSS is read before the log, so that a sample marked RUNNING was
    taken before the last report. Returns (exit status, samples as
    (seconds, rss bytes, stage) tuples, seconds).
    """
    samples = []
    start = time.monotonic()
    with open(log_path, "w") as log:
        proc = subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT)
        while proc.poll() is None:
            seconds, rss = time.monotonic() - start, rss_bytes(proc.pid)
            with open(log_path) as text:
                now = stage(text.read())
            if rss is not None:
                samples.append((seconds, rss, now))
            time.sleep(interval)
    return proc.returncode, samples, time.monotonic() - start


def frame_stage(text, warmup, frames):
    done = sum(1 for line in text.splitlines() if FRAME_DEVICE.match(line))
    return WARMING if done < warmup else RUNNING if done < frames else DONE


BATCH_ROW = re.compile(r"^\| [0-9]+ \| [0-9]+ \|", re.M)


def batch_stage(text, batches):
    done = len(BATCH_ROW.findall(text))
    return WARMING if done < 1 else RUNNING if done < batches else DONE


def change(first, last):
    """Relative change from first to last (0 when both are 0)."""
    if first == 0:
        return 0.0 if last == 0 else float("inf")
    return (last - first) / first


def verdict(name, samples, device_first, device_last, tolerance):
    """The phase's figures and whether it is flat."""
    warm = [s for s in samples if s[2] == RUNNING]
    if len(warm) < 2:
        return {"phase": name, "flat": False,
                "reason": "fewer than 2 samples between warm-up and the last report (run longer or sample more often)"}
    first, last = warm[0], warm[-1]
    peak = max(s[1] for s in samples)
    rss_change = change(first[1], last[1])
    device_change = change(device_first, device_last)
    flat = abs(rss_change) <= tolerance and abs(device_change) <= tolerance
    return {
        "phase": name, "samples": len(samples), "warm_samples": len(warm),
        "rss_first_bytes": first[1], "rss_first_s": round(first[0], 1),
        "rss_last_bytes": last[1], "rss_last_s": round(last[0], 1),
        "rss_peak_bytes": peak, "rss_change": rss_change,
        "device_first_bytes": device_first, "device_last_bytes": device_last, "device_change": device_change,
        "tolerance": tolerance, "flat": flat,
    }


def write_samples(path, samples):
    with open(path, "w") as out:
        out.write("seconds,rss_bytes,stage\n")
        for s, rss, stage in samples:
            out.write(f"{s:.2f},{rss},{('warming', 'running', 'done')[stage]}\n")


def mib(n):
    return n / 1048576.0


def report(result):
    if "rss_first_bytes" not in result:
        print(f"{result['phase']}: NOT FLAT: {result['reason']}")
        return
    print(f"{result['phase']}: host RSS {mib(result['rss_first_bytes']):.1f} MiB at {result['rss_first_s']} s -> "
          f"{mib(result['rss_last_bytes']):.1f} MiB at {result['rss_last_s']} s ({100 * result['rss_change']:+.2f}%), "
          f"peak {mib(result['rss_peak_bytes']):.1f} MiB; device buffers {mib(result['device_first_bytes']):.2f} -> "
          f"{mib(result['device_last_bytes']):.2f} MiB ({100 * result['device_change']:+.2f}%): "
          f"{'flat' if result['flat'] else 'NOT FLAT'} (tolerance {100 * result['tolerance']:.1f}%)")


def fail(message):
    """A phase that could not run or failed: exit status 2."""
    print(f"soak.py: {message}", file=sys.stderr)
    sys.exit(2)


def positive_count(text):
    value = float(text)
    if value < 1 or value != int(value):
        raise argparse.ArgumentTypeError(f"'{text}': expected a whole number >= 1")
    return int(value)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default=os.path.join(REPO, "build"), help="the build directory (rtcl, bench)")
    parser.add_argument("--frames", type=positive_count, default=1000)
    parser.add_argument("--warmup-frames", type=positive_count, default=10)
    parser.add_argument("--width", type=positive_count, default=64)
    parser.add_argument("--rays", type=positive_count, default=10**9)
    parser.add_argument("--batch", type=positive_count, default=1 << 24)
    parser.add_argument("--interval", type=float, default=1.0, help="seconds between samples")
    parser.add_argument("--tolerance", type=float, default=0.05)
    parser.add_argument("--out", help="directory for the frames, logs and samples (default: a new temporary one)")
    parser.add_argument("--phases", default="render,rays", help="render, rays or both (comma-separated)")
    args = parser.parse_args()
    if args.warmup_frames >= args.frames:
        parser.error(f"--warmup-frames {args.warmup_frames}: must be below --frames {args.frames}")
    if not (0 < args.interval <= 60):
        parser.error(f"--interval {args.interval}: expected seconds in (0, 60]")
    phases = args.phases.split(",")
    if not phases or any(p not in ("render", "rays") for p in phases):
        parser.error(f"--phases {args.phases}: expected render, rays or render,rays")
    out = args.out or tempfile.mkdtemp(prefix="rtcl-soak-")
    os.makedirs(out, exist_ok=True)
    env = dict(os.environ)
    env.setdefault("RTCL_SCENES_DIR", os.path.normpath(os.path.join(REPO, "..", "shared", "scenes")))
    rtcl = os.path.join(args.build, "rtcl")
    bench = os.path.join(args.build, "bench", "rtcl_billion_rays_bench")
    for phase, binary in (("render", rtcl), ("rays", bench)):
        if phase in phases and not os.access(binary, os.X_OK):
            fail(f"--build {args.build}: no {binary} (build the targets rtcl and rtcl_billion_rays_bench)")
    print(f"soak: output in {out}; scenes from {env['RTCL_SCENES_DIR']}", flush=True)

    results = []
    if "render" in phases:
        frames_dir = os.path.join(out, "frames")
        os.makedirs(frames_dir, exist_ok=True)
        cmd = [rtcl, "render", "--builtin", "forest", "--frames", f"0:{args.frames - 1}", "--width", str(args.width),
               "--spp", "1", "-v", "-o", os.path.join(frames_dir, "frame_%04d.png")]
        print("soak: " + " ".join(cmd), flush=True)
        log_path = os.path.join(out, "render.log")
        rc, samples, seconds = run_sampled(
            cmd, env, log_path, args.interval,
            lambda text: frame_stage(text, args.warmup_frames, args.frames))
        write_samples(os.path.join(out, "render_samples.csv"), samples)
        with open(log_path) as log:
            device = [float(m.group(2)) * 1048576 for m in map(FRAME_DEVICE.match, log.read().splitlines()) if m]
        if rc != 0 or len(device) != args.frames:
            with open(log_path) as log:
                print(log.read()[-3000:])
            fail(f"the render phase failed (exit status {rc}, {len(device)} of {args.frames} frames)")
        result = verdict("render", samples, int(device[args.warmup_frames - 1]), int(device[-1]), args.tolerance)
        result.update({"frames": args.frames, "seconds": round(seconds, 1), "command": " ".join(cmd)})
        results.append(result)
        report(result)
    if "rays" in phases:
        json_path = os.path.join(out, "rays.jsonl")
        batches = (args.rays + min(args.batch, args.rays) - 1) // min(args.batch, args.rays)
        cmd = [bench, "--rays", str(args.rays), "--batch", str(args.batch), "--json", json_path,
               "--tolerance", str(args.tolerance)]
        print("soak: " + " ".join(cmd), flush=True)
        log_path = os.path.join(out, "rays.log")
        rc, samples, seconds = run_sampled(cmd, env, log_path, args.interval,
                                           lambda text: batch_stage(text, batches))
        write_samples(os.path.join(out, "rays_samples.csv"), samples)
        if rc not in (0, 3):  # 3: the bench's own verdict, memory not flat (judged here as well)
            with open(log_path) as log:
                print(log.read()[-3000:])
            fail(f"the rays phase failed (exit status {rc})")
        with open(json_path) as lines:
            records = [json.loads(line) for line in lines if line.strip()]
        rows = [b for b in records if not b.get("summary")]
        result = verdict("rays", samples, rows[0]["device_bytes"], rows[-1]["device_bytes"], args.tolerance)
        rates = [b["mrays_per_s"] for b in rows]
        summary = next(b for b in records if b.get("summary"))
        result.update({"rays": args.rays, "batch": args.batch, "batches": len(rows), "seconds": round(seconds, 1),
                       "mrays_per_s_mean": summary["mean_mrays_per_s"], "mrays_per_s_min": min(rates),
                       "mrays_per_s_max": max(rates), "bench_rss_first_bytes": rows[0]["host_rss_bytes"],
                       "bench_rss_last_bytes": rows[-1]["host_rss_bytes"], "bench_flat": summary["flat"],
                       "command": " ".join(cmd)})
        result["flat"] = result["flat"] and summary["flat"]
        results.append(result)
        report(result)
        print(f"rays: {result['batches']} batches, {result['mrays_per_s_mean']:.2f} Mrays/s over all "
              f"(batches {result['mrays_per_s_min']:.2f} .. {result['mrays_per_s_max']:.2f}); bench's own first/last "
              f"batch RSS {mib(result['bench_rss_first_bytes']):.1f} / {mib(result['bench_rss_last_bytes']):.1f} MiB")
    with open(os.path.join(out, "soak.json"), "w") as summary_file:
        json.dump(results, summary_file, indent=1)
    flat = all(r["flat"] for r in results)
    print(f"soak: memory {'flat' if flat else 'NOT FLAT'} in {', '.join(r['phase'] for r in results)}")
    return 0 if flat else 1


if __name__ == "__main__":
    sys.exit(main())

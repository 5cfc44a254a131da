#!/usr/bin/env python3
"""The application's frame interval through the layer: hello_xr -g Vulkan2 on the Fovea
runtime (realtime pacing), pass-through against path tracing with a scene, one session per
variant, the variants interleaved and repeated. Prints one Markdown table row per run.

  eval "$(./x env)"; python3 layer/scripts/frame_interval.py --display small --frames 2500 --reps 3

Variants (--variants, comma-separated): `pass` (no scene), `host` / `gpu` (`cornell`,
FOVEA_LAYER_COMPOSITOR), optionally suffixed `:PRIORITY` (FOVEA_LAYER_RENDER_PRIORITY: `idle`
or a nice value), e.g. `gpu:idle,gpu:19`. Interval: consecutive `wait_return_ns` of
`layer_timing.jsonl` after the first 10 frames where both frames were replaced (pass-through:
all); `xrEndFrame`: `cpu_ms.end_frame` of those replaced frames (pass-through: all); CPU per
frame: the process's threads' CPU time (/proc, sampled every 0.25 s) over the frames, split
into the application's threads (its Vulkan device's included) and the lowered ones (the render
thread and its device's), which does not depend on the machine's load as much. The load
average (1 min) is read before and after each run: other work on the machine shows in every
figure, so compare the variants within one repetition.

--split adds a line per run with xrEndFrame's steps, median / mean in microseconds, over the same
frames: the layer's own work before the call down (`end_frame_layer`), of it the composition's
`vkQueueSubmit` (`submit_ms`), the rest of it, the call down the chain, and after xrEndFrame
returned until the application's next xrWaitFrame (the application's own work there; before the
timing log had its own thread, also the record written on the application's thread); and the
frames whose submission took over 1 ms, with how many of them lost their core during it
(`submit_preemptions`).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time


def loadavg():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def percentile(values, q):
    s = sorted(values)
    return s[min(len(s) - 1, int(q * len(s)))]


def thread_cpu(pid):
    """CPU seconds per thread of `pid` so far: {tid: (seconds, lowered)}, lowered = SCHED_IDLE or
    nicer than the process's main thread (the render thread and the device threads it created;
    relative, so that the split holds when the whole run is started under `nice`)."""
    out = {}
    tick = os.sysconf("SC_CLK_TCK")
    try:
        tids = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return out
    for tid in tids:
        try:
            with open(f"/proc/{pid}/task/{tid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue  # the thread ended meanwhile
        # Fields from 3 (state) on: utime 14, stime 15, nice 19, policy 41 (proc(5)).
        out[tid] = ((int(fields[11]) + int(fields[12])) / tick, int(fields[38]) == 5, int(fields[16]))
    main_nice = out[str(pid)][2] if str(pid) in out else 0
    return {tid: (cpu, idle or nice > main_nice) for tid, (cpu, idle, nice) in out.items()}


def summarise(path):
    records = [json.loads(line) for line in open(path) if line.strip()][10:]
    replacing = any(r["replaced"] for r in records)
    kept = [r for r in records if r["replaced"] or not replacing]
    interval = [(b["wait_return_ns"] - a["wait_return_ns"]) / 1e6 for a, b in zip(records, records[1:])
                if not replacing or (a["replaced"] and b["replaced"])]
    end = [r["cpu_ms"]["end_frame"] for r in kept]
    layer = [r["cpu_ms"]["end_frame_layer"] for r in kept]
    submit = [r.get("submit_ms", 0.0) for r in kept]
    frames = {r["frame"]: r for r in records}
    after = [(frames[r["frame"] + 1]["wait_call_ns"] - r["end_return_ns"]) / 1e6 for r in kept if r["frame"] + 1 in frames]
    slow = [r for r in kept if r.get("submit_ms", 0.0) > 1.0]
    if not interval or not end:
        raise SystemExit(f"{path}: too few frames to measure ({len(records)} records after the first 10)")
    return {
        "interval_median": statistics.median(interval), "interval_mean": statistics.mean(interval),
        "interval_p95": percentile(interval, 0.95), "end_median": statistics.median(end),
        "end_mean": statistics.mean(end), "frames": len(records), "replaced": sum(r["replaced"] for r in records),
        "traced": len({r["traced_frame"] for r in records if r["replaced"]}),
        "host_readbacks": sum(r.get("host_readbacks", 0) for r in kept),
        "split": {"layer": layer, "submit": submit, "layer_rest": [a - b for a, b in zip(layer, submit)],
                  "down": [a - b for a, b in zip(end, layer)], "after": after},
        "slow_submits": len(slow), # (not recorded by older builds)
        "slow_preempted": sum(1 for r in slow if r["submit_preemptions"] > 0)
        if all("submit_preemptions" in r for r in slow) else "not recorded",
    }


def run(variant, args, rep):
    kind, _, priority = variant.partition(":")
    if kind not in ("pass", "host", "gpu"):
        raise SystemExit(f"--variants: unknown variant {variant!r} (pass, host, gpu, optionally :idle or :NICE)")
    out = os.path.abspath(os.path.join(args.out, f"{args.display}-{variant.replace(':', '-')}-{rep}"))
    os.makedirs(out, exist_ok=True)
    for name in ("layer_timing.jsonl", "timing.jsonl"):
        if os.path.exists(os.path.join(out, name)):
            os.remove(os.path.join(out, name))
    env = dict(os.environ)
    env.update({
        "XR_RUNTIME_JSON": os.path.join(args.build, "runtime/fovea_runtime.json"),
        "FOVEA_EXIT_AFTER_FRAMES": str(args.frames), "FOVEA_RUNTIME_OUT": out,
        "FOVEA_RUNTIME_PNG_EVERY": "1000000", "FOVEA_DISPLAY": args.display,
        "XDG_CONFIG_HOME": os.path.join(out, "no-config"),
        "XR_API_LAYER_PATH": os.path.join(args.build, "layer/explicit"),
        "XR_ENABLE_API_LAYERS": "XR_APILAYER_FOVEA_path_tracing", "FOVEA_LAYER_OUT": out,
        "FOVEA_SCENE": "" if kind == "pass" else "cornell",
    })
    for k in ("FOVEA_LAYER_SCENE", "FOVEA_LAYER_COMPOSITOR", "FOVEA_LAYER_RENDER_PRIORITY", "FOVEA_LAYER_RENDER"):
        env.pop(k, None)
    if kind != "pass":
        env["FOVEA_LAYER_COMPOSITOR"] = kind
    if priority:
        env["FOVEA_LAYER_RENDER_PRIORITY"] = priority
    load_before = loadavg()
    with open(os.path.join(out, "hello_xr.log"), "w") as log:
        # hello_xr quits at the end of its input: the pipe stays open until it exits.
        p = subprocess.Popen(["hello_xr", "-g", "Vulkan2"], env=env, stdin=subprocess.PIPE, stdout=log,
                             stderr=subprocess.STDOUT)
        # The threads' CPU time, sampled until the process exits (a thread's last sample stands
        # for it: Linux forgets ended threads' times).
        cpu = {}
        try:
            deadline = time.monotonic() + args.timeout
            while p.poll() is None:
                if time.monotonic() > deadline:
                    raise subprocess.TimeoutExpired(p.args, args.timeout)
                cpu.update(thread_cpu(p.pid))
                time.sleep(0.25)
            code = p.returncode
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()
            raise SystemExit(f"{variant}: hello_xr did not exit within {args.timeout} s (log: {out}/hello_xr.log)")
        finally:
            p.stdin.close()
    if code != 0:
        raise SystemExit(f"{variant}: hello_xr exited with {code} (log: {out}/hello_xr.log)")
    s = summarise(os.path.join(out, "layer_timing.jsonl"))
    s["load"] = (load_before, loadavg())
    s["cpu_app"] = sum(c for c, lowered in cpu.values() if not lowered) * 1e3 / args.frames
    s["cpu_render"] = sum(c for c, lowered in cpu.values() if lowered) * 1e3 / args.frames
    return s


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--display", default="small")
    ap.add_argument("--frames", type=int, default=2500)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--variants", default="pass,gpu")
    ap.add_argument("--build", default="build/release")
    ap.add_argument("--out", default="out/interval")
    ap.add_argument("--timeout", type=float, default=1800)
    ap.add_argument("--split", action="store_true", help="also print xrEndFrame's steps per run")
    args = ap.parse_args()
    variants = args.variants.split(",")
    print(f"| {args.display}, {args.frames} frames | rep | interval median / mean / p95 (ms) "
          "| xrEndFrame median / mean (ms) | CPU per frame: application / render (ms) "
          "| replaced / traced | host read-backs | load avg before → after |")
    print("|---|---|---|---|---|---|---|---|")
    for rep in range(1, args.reps + 1):
        for v in variants:
            t0 = time.monotonic()
            s = run(v, args, rep)
            print(f"| {v} | {rep} | {s['interval_median']:.2f} / {s['interval_mean']:.2f} / {s['interval_p95']:.2f} "
                  f"| {s['end_median']:.3f} / {s['end_mean']:.3f} | {s['cpu_app']:.2f} / {s['cpu_render']:.2f} "
                  f"| {s['replaced']}/{s['traced']} "
                  f"| {s['host_readbacks']} | {s['load'][0]:.1f} → {s['load'][1]:.1f} |", flush=True)
            if args.split:
                us = {k: f"{statistics.median(x) * 1e3:.1f} / {statistics.mean(x) * 1e3:.1f}" if x else "–"
                      for k, x in s["split"].items()}
                print(f"|   split (us, median / mean) | {rep} | layer {us['layer']}: submit {us['submit']}, rest "
                      f"{us['layer_rest']} | down {us['down']} | after the return {us['after']} "
                      f"| submits > 1 ms: {s['slow_submits']}, preempted in them: {s['slow_preempted']} | | |",
                      flush=True)
            print(f"  ({v}, repetition {rep}: {time.monotonic() - t0:.0f} s)", file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()

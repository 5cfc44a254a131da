#!/usr/bin/env python3
"""Where a traced frame goes after the GPU, before and after it stayed on the device.

Two programs, each in its old and its new way, measured in one run on one device:

* `fovea render --display fove0`: every frame read back (`--png-every 1`, what every frame
  did before frames stayed on the device) against only the last frame and the flicker
  window (`--png-every 0`). Per frame: the frame's CPU time (`cpu_ms.total`, the gaze read,
  recording, submission and fence wait; no output work), the read-back's CPU time and the
  bytes read back (report.json `output`).
* The API layer under hello_xr -g Vulkan2 on the project's runtime: traced frames read back
  and written by the host into the composition's slots (`FOVEA_LAYER_HANDOVER=host`) against
  the slots written by the layer's device in memory it shares with the application's device
  (`shared`). Per traced frame: the hand-over's CPU time (`cpu_ms.readback`), the bytes that
  crossed the host (`host_bytes`); per displayed frame: the age of the traced frame shown
  (`traced_age_ns`, display time minus the display time it was traced for).

Writes DIR/handover.json and .csv, DIR/handover.png and .svg (matplotlib), and, with
--markdown PAGE, a block of PAGE between `<!-- kept: handover -->` markers (the sweep report
keeps it when it regenerates the page). Progress goes to stderr on a terminal.
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

LAYER = "XR_APILAYER_FOVEA_path_tracing"
BEGIN, END = "<!-- kept: handover -->", "<!-- /kept: handover -->"


def progress(msg):
    if sys.stderr.isatty():
        sys.stderr.write(f"\r\033[K{msg}")
        sys.stderr.flush()


def median(values):
    return statistics.median(values) if values else None


def run_render(fovea, out, display, frames, png_every, env):
    cmd = [fovea, "render", "--display", display, "--frames", str(frames), "--png-every", str(png_every),
           "--out", out, "--quiet"]
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "report.json")) as f:
        r = json.load(f)
    o = r["output"]
    variant = "every frame read back" if png_every else "frames stay on the device"
    return {"program": "fovea render", "display": display,
            "variant": f"{variant} ({o['frames_read_back']} of {r['frames']} read back)", "command": " ".join(cmd[1:]),
            "frame_cpu_ms": r["cpu_ms"]["total"], "handover_cpu_ms": o["readback_cpu_ms"] or 0.0,
            "host_bytes": o["host_bytes_per_frame"], "age_ms": None,
            "device": f"{r['device']['name']} ({r['device']['driver']})"}


def run_layer(build, out, display, frames, handover, env):
    e = dict(env)
    e.update({"XR_RUNTIME_JSON": os.path.join(build, "runtime", "fovea_runtime.json"),
              "FOVEA_EXIT_AFTER_FRAMES": str(frames), "FOVEA_RUNTIME_OUT": out,
              "FOVEA_RUNTIME_PNG_EVERY": "1000000", "FOVEA_DISPLAY": display,
              "XDG_CONFIG_HOME": os.path.join(out, "no-config"),
              "XR_API_LAYER_PATH": os.path.join(build, "layer", "explicit"), "XR_ENABLE_API_LAYERS": LAYER,
              "FOVEA_LAYER_OUT": out, "FOVEA_SCENE": "cornell", "FOVEA_LAYER_HANDOVER": handover})
    for k in ("FOVEA_LAYER_SCENE", "FOVEA_LAYER_RENDER", "FOVEA_LAYER_COMPOSITOR"):
        e.pop(k, None)
    # hello_xr ends on a key press: its stdin stays open, the runtime ends the session.
    p = subprocess.Popen(["hello_xr", "-g", "Vulkan2"], env=e, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL)
    try:
        p.wait(timeout=1800)
    finally:
        if p.poll() is None:
            p.kill()
        p.stdin.close()
    if p.returncode != 0:
        raise RuntimeError(f"hello_xr on {display} ({handover}) exited with {p.returncode}; see {out}")
    with open(os.path.join(out, "layer_timing.jsonl")) as f:
        recs = [json.loads(line) for line in f if line.strip()]
    shown = [r for r in recs if r.get("replaced")]
    traced = {r["traced_frame"]: r for r in shown}.values()  # one record per distinct traced frame
    if not shown:
        raise RuntimeError(f"no traced frame was shown on {display} ({handover}) in {frames} frames")
    names = {r["handover"] for r in shown}
    return {"program": "layer", "display": display,
            "variant": "through the host" if handover == "host" else "shared device memory",
            "command": f"hello_xr -g Vulkan2, FOVEA_DISPLAY={display} FOVEA_LAYER_HANDOVER={handover}",
            "handover": sorted(names), "frames": len(recs), "replaced": len(shown), "traced": len(traced),
            "frame_cpu_ms": median([r["render_ms"] for r in traced]),
            "handover_cpu_ms": median([r["cpu_ms"]["readback"] for r in traced]),
            "host_bytes": median([r["host_bytes"] for r in traced]),
            "age_ms": median([r["traced_age_ns"] / 1e6 for r in shown])}


def plot(rows, path_stem):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def label(r):
        return f"{r['program']}\n{r['display']}"

    pairs = {}
    for r in rows:
        pairs.setdefault((r["program"], r["display"]), []).append(r)
    groups = list(pairs.values())
    panels = [("host bytes per frame (MB)", lambda r: r["host_bytes"] / 1e6, groups),
              ("hand-over CPU per frame (ms)", lambda r: r["handover_cpu_ms"], groups),
              ("age of the shown traced frame (ms)", lambda r: r["age_ms"],
               [g for g in groups if g[0]["age_ms"] is not None])]
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    for ax, (title, value, gs) in zip(axes, panels):
        for i, g in enumerate(gs):
            for j, r in enumerate(g):
                v = value(r)
                bar = ax.bar(i + (j - 0.5) * 0.38, v, 0.36, color=("#c0504d" if j == 0 else "#4f81bd"),
                             label=("before" if j == 0 else "after") if i == 0 else None)
                ax.bar_label(bar, labels=[f"{v:.3g}"], fontsize=7)
        ax.set_xticks(range(len(gs)), [label(g[0]) for g in gs], fontsize=8)
        ax.set_title(title, fontsize=10)
        ax.legend(fontsize=8)
    fig.tight_layout()
    for ext in ("png", "svg"):
        fig.savefig(f"{path_stem}.{ext}", dpi=110)


def markdown(rows, device, command, image):
    lines = [BEGIN, "", "## Where a traced frame goes: host bytes, hand-over CPU, age of the shown frame", "",
             f"Measured by `{command}` in one run on {device} (bench/handover.py says what each figure is). "
             "*Before*: `fovea render` reading back every frame (`--png-every 1`, what each frame did before the "
             "frames stayed on the device), the layer writing traced frames through the host "
             "(`FOVEA_LAYER_HANDOVER=host`); *after*: `--png-every 0`, and the layer's device writing them into "
             "memory it shares with the application's device (the default). Medians; the layer's per traced "
             "frame, its age per displayed frame (hello_xr -g Vulkan2 on the project's runtime, `cornell`, "
             "realtime pacing).", "",
             f"![before and after]({image})", "",
             "| program | display | way | frame CPU ms (outside I/O) | hand-over CPU ms | host bytes per frame | "
             "shown frame's age ms |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        age = "–" if r["age_ms"] is None else f"{r['age_ms']:.0f}"
        lines.append(f"| {r['program']} | {r['display']} | {r['variant']} | {r['frame_cpu_ms']:.1f} | "
                     f"{r['handover_cpu_ms']:.2f} | {r['host_bytes']:,.0f} | {age} |")
    lines += ["", "`fovea render`'s frame CPU is the frame alone (`cpu_ms.total`); the layer's is the render "
              "thread's wall time per traced frame (`render_ms`: trace, hand-over). The hand-over CPU is, for "
              "`fovea render`, the read-back of a frame it reads back (`output.readback_cpu_ms`, median over those "
              "frames; the last 8 are read back for the flicker, docs/metrics.md), and for the layer the render "
              "thread's read-back and encoding, or on the shared path its device's encoding and the wait for it "
              "(`cpu_ms.readback`). On lavapipe the device is the CPU, so every GPU stage is CPU time too; on a "
              "discrete GPU the shared path's hand-over is a short kernel and a fence wait, the host path's a "
              "PCIe round trip of the bytes in the table.", "", END]
    return "\n".join(lines) + "\n"


def measure(a):
    fovea = os.path.join(a.build, "tools", "fovea")
    env = dict(os.environ)
    frames = dict(kv.split("=") for kv in a.layer_frames.split(","))
    rows = []
    jobs = [("render", "fove0", 1), ("render", "fove0", 0)]
    for d in a.layer_displays.split(","):
        jobs += [("layer", d, "host"), ("layer", d, "shared")]
    t0 = time.monotonic()
    for i, (what, display, how) in enumerate(jobs):
        progress(f"[{i + 1}/{len(jobs)}] {what} {display} {how} ({time.monotonic() - t0:.0f} s)")
        out = tempfile.mkdtemp(prefix=f"{what}-{display}-", dir=a.out)
        if what == "render":
            rows.append(run_render(fovea, out, display, a.render_frames, how, env))
        else:
            rows.append(run_layer(a.build, out, display, int(frames.get(display, 600)), how, env))
    progress("")
    devices = [r.pop("device") for r in rows if "device" in r]
    device = devices[0] if devices else "the default device"
    return {"device": device, "rows": rows}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build/release", help="the build directory [build/release]")
    ap.add_argument("--out", default="out/handover", help="output directory [out/handover]")
    ap.add_argument("--render-frames", type=int, default=24,
                    help="fovea render's frames on fove0 (the last 8 are read back for the flicker) [24]")
    ap.add_argument("--layer-displays", default="tiny,small,fove0", help="the layer's displays [tiny,small,fove0]")
    ap.add_argument("--layer-frames", default="tiny=900,small=1500,fove0=300",
                    help="hello_xr's frames per display [tiny=900,small=1500,fove0=300]")
    ap.add_argument("--markdown", help="a page to write the measurement's block into (docs/results.md)")
    ap.add_argument("--image-dir", help="where the page's figure goes (default: --out)")
    ap.add_argument("--from", dest="saved", help="draw the figure and the page from a saved handover.json, "
                    "measuring nothing")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    if a.saved:
        with open(a.saved) as f:
            doc = json.load(f)
    else:
        doc = measure(a)
        with open(os.path.join(a.out, "handover.json"), "w") as f:
            json.dump(doc, f, indent=2)
    rows, device = doc["rows"], doc["device"]
    with open(os.path.join(a.out, "handover.csv"), "w", newline="") as f:
        fields = [k for r in rows for k in r if k != "handover"]
        w = csv.DictWriter(f, fieldnames=list(dict.fromkeys(fields)) + ["handover"])
        w.writeheader()
        for r in rows:
            w.writerow({**r, "handover": " ".join(r.get("handover", []))})
    image_dir = a.image_dir or a.out
    os.makedirs(image_dir, exist_ok=True)
    stem = os.path.join(image_dir, "handover")
    plot(rows, stem)
    if a.markdown:
        page = open(a.markdown).read() if os.path.exists(a.markdown) else ""
        rel = os.path.relpath(stem + ".png", os.path.dirname(os.path.abspath(a.markdown)))
        block = markdown(rows, device, "./x handover", rel)
        if BEGIN in page and END in page:
            page = page[:page.index(BEGIN)] + block.rstrip("\n") + page[page.index(END) + len(END):]
        else:
            page = page.rstrip("\n") + "\n\n" + block
        tmp = a.markdown + ".tmp"
        with open(tmp, "w") as f:
            f.write(page)
        os.replace(tmp, a.markdown)
    json.dump(doc, sys.stdout, indent=2)
    print()


if __name__ == "__main__":
    main()

#!/usr/bin/env bash
# The fovea's recovery after a 32° gaze step on every shipped scene, BMFR and no denoiser
# (docs/reconstruction.md, "A 32° gaze step in fovea render"): the table and the plot.
#
#   tools/recovery-curves.sh [OUT]        (from the source tree, after ./x build)
#
# The gaze rests at -16° (horizontal) for 30 frames of 70 Hz, then steps to +16° between two
# samples of a 250 Hz recording, read without prediction (?predict=none): frame 31 is the
# first at +16°. Each render scores the left eye's fovea on the RECOVERY frames from the
# landing (report.json: recovery) against a 256-spp reference of its own light transport;
# the control rests at +16° for all frames (its last frame's fovea HDR-FLIP is "steady").
# Writes OUT/{step,still}.csv, OUT/<scene>-<denoiser>{,-control}/ (the renders),
# OUT/recovery.json (the curves), OUT/figures.json with recovery_<scene>.png/.svg drawn by
# `fovea plot`, and prints the table. Environment: FOVEA (the binary)
# [build/release/tools/fovea]; PRESET [small]; SCENES [the four shipped scenes with
# lighting]; REF_SPP [256]; BEFORE: the OUT of an earlier run (another build), whose curves
# the plots draw dashed as "before". References go through the reference cache: a second
# run reuses them.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/recovery-curves}
FOVEA=${FOVEA:-build/release/tools/fovea}
PRESET=${PRESET:-small}
SCENES=${SCENES:-default cornell glossy-spheres stereo-occluders}
REF_SPP=${REF_SPP:-256}
FRAMES=40
RECOVERY=8
mkdir -p "$OUT"
eval "$(./x env)"

# 250 Hz gaze for 2 s: -16° before 432 ms, +16° from there (frame 30 of 70 Hz is at 428.6 ms,
# frame 31 at 442.9 ms: the step falls between them).
python3 - "$OUT" <<'EOF'
import math, sys
out = sys.argv[1]
s = math.sin(math.radians(16)); c = math.cos(math.radians(16))
def write(name, x_of_t):
    with open(f"{out}/{name}.tmp", "w") as f:
        f.write("t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n")
        for k in range(500):
            t = k * 4_000_000
            f.write(f"{t},combined,{x_of_t(t):.6f},0.000000,{-c:.6f},1,1\n")
    import os; os.replace(f"{out}/{name}.tmp", f"{out}/{name}.csv")
write("step", lambda t: -s if t < 432_000_000 else s)
write("still", lambda t: s)
EOF

for scene in $SCENES; do
  for den in bmfr none; do
    common=(--display "$PRESET" --scene "$scene" --frames "$FRAMES" --denoiser "$den" --reference "$REF_SPP" --png-every 0 --quiet)
    "$FOVEA" render "${common[@]}" --gaze "$OUT/step.csv?predict=none" --recovery-frames "$RECOVERY" \
      --out "$OUT/$scene-$den" >/dev/null
    "$FOVEA" render "${common[@]}" --gaze "$OUT/still.csv?predict=none" --recovery-frames 0 \
      --out "$OUT/$scene-$den-control" >/dev/null
  done
done

python3 - "$OUT" "$SCENES" "${BEFORE:-}" <<'EOF'
import json, os, sys
out, scenes, before_dir = sys.argv[1], sys.argv[2].split(), sys.argv[3]
before = json.load(open(f"{before_dir}/recovery.json")) if before_dir else {}
curves, charts = {}, []
print("| scene | denoiser | " + " | ".join(f"k = {k}" if k == 1 else str(k) for k in range(1, 9)) + " | control | k = 4 / control |")
print("|---|---|" + "---|" * 10)
for si, scene in enumerate(scenes):
    series = []
    for di, den in enumerate(["bmfr", "none"]):
        rep = json.load(open(f"{out}/{scene}-{den}/report.json"))
        ctl = json.load(open(f"{out}/{scene}-{den}-control/report.json"))["summary"]["left"]["fovea_hdr_flip"]
        landing = rep["recovery"]["landings"][0]
        flip = landing["fovea_hdr_flip"]
        curves.setdefault(scene, {})[den] = {"fovea_hdr_flip": flip, "control": ctl}
        print(f"| {scene} | {den} | " + " | ".join(f"{v:.3f}" for v in flip) + f" | {ctl:.3f} | {flip[3] / ctl:.2f} |")
        series.append({"label": f"{den}", "points": [[k + 1, v] for k, v in enumerate(flip)], "line": True,
                       "markers": True, "color": di})
        series.append({"label": f"{den}: still control (steady)", "points": [], "hline": ctl, "color": di})
        series.append({"label": f"{den}: control x 1.1 (the goal)", "points": [], "hline": 1.1 * ctl, "color": di + 2})
        if den in before.get(scene, {}):
            b = before[scene][den]["fovea_hdr_flip"]
            series.append({"label": f"{den}: before", "points": [[k + 1, v] for k, v in enumerate(b)], "line": True,
                           "color": di + 4})
    series.append({"label": "50 ms after the landing (70 Hz)", "points": [], "vlines": [50 / (1000 / 70)], "color": 7})
    charts.append({"file": f"recovery_{scene}", "title": f"Fovea after a 32° gaze step: {scene}",
                   "note": "left eye, fovea HDR-FLIP against a converged reference of the same transport",
                   "x_label": "frames after the landing (70 Hz: 14.3 ms each)",
                   "y_label": "fovea HDR-FLIP (lower is better)", "series": series})
for name, data in (("recovery.json", curves), ("figures.json", {"figure": "charts", "charts": charts})):
    with open(f"{out}/{name}.tmp", "w") as f:
        json.dump(data, f, indent=1)
    os.replace(f"{out}/{name}.tmp", f"{out}/{name}")
EOF
"$FOVEA" plot "$OUT/figures.json" >/dev/null
echo "figures: $OUT/recovery_<scene>.png (.svg)"

#!/usr/bin/env bash
# Whole frame on fove0 (docs/reconstruction-history.md): Visual-Polar (default settings) against
# full-resolution Cartesian, the same reconstruction, back to back, both scored against one
# converged reference of the default scene; prints the table of times, gains and fovea quality.
#
#   tools/fove0-compare.sh [OUT]        (from the source tree, after ./x build)
#
# The reference is a window: each eye's pixels within REF_WINDOW degrees of the gaze the
# render scores (its last frame's, from the default gaze recording), which covers the fovea
# and the 0-6 deg bands with their SSIM/FLIP margin (5 px, 0.53 deg at fove0's centre); the
# first render traces it (`render --reference SPP --reference-window DEG`), the second reads
# it from the cache.
# Environment: FOVEA (the binary) [build/release/tools/fovea]; FRAMES [3]; BUDGET: Visual-Polar's
# --budget [its default]; TRACE: both renders' --trace [auto: ray queries where the device
# has them]; REF_WINDOW [7]
# (degrees; 0: the whole view, rendered first by `fovea reference`); REF_SPP [2048 for a
# window, enough for REF_ERROR on fove0's; 8 for the whole view]: the reference's samples per
# pixel at most (it stops earlier at a per-pixel relative error of REF_ERROR [0.02]); REF_BATCH [2]: the whole view's batch;
# REF_DIR: use reference_{left,right}.exr from there instead (any written by `fovea
# reference` for this scene and view, whole or a window). The reference goes through the
# reference cache (--reference-cache, default $XDG_CACHE_HOME/fovea/references): a second
# run reuses it. Needs python3 for the table.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/fove0-compare}
FOVEA=${FOVEA:-build/release/tools/fovea}
FRAMES=${FRAMES:-3}
PRESET=${PRESET:-fove0}  # another display preset, for trying the script quickly
REF_WINDOW=${REF_WINDOW:-7}
if [[ $REF_WINDOW == 0 ]]; then REF_SPP=${REF_SPP:-8}; else REF_SPP=${REF_SPP:-2048}; fi
REF_BATCH=${REF_BATCH:-2}
REF_ERROR=${REF_ERROR:-0.02}
vp_budget=()
[[ -n ${BUDGET:-} ]] && vp_budget=(--budget "$BUDGET")
TRACE=${TRACE:-auto}
command -v python3 >/dev/null || { echo "fove0-compare: python3 is needed for the table" >&2; exit 2; }
[[ -x $FOVEA ]] || { echo "fove0-compare: no fovea binary at $FOVEA (./x build, or set FOVEA)" >&2; exit 2; }
[[ -n ${VK_ICD_FILENAMES:-} ]] || eval "$(./x env)"
export LP_NUM_THREADS=${LP_NUM_THREADS:-2} FOVEA_SOURCE_DIR=$PWD
mkdir -p "$OUT"
load() { cut -d' ' -f1-3 /proc/loadavg; }

# --reference for the renders: a directory, or a sample count with the window around the gaze.
if [[ -n ${REF_DIR:-} ]]; then
  ref=$REF_DIR
  reference=(--reference "$ref")
elif [[ $REF_WINDOW == 0 ]]; then
  ref=$OUT/reference
  mkdir -p "$ref"
  for eye in left right; do
    echo "reference, $eye eye (load $(load))..." >&2
    "$FOVEA" reference --display "$PRESET" --scene default --eye $eye --spp "$REF_SPP" --batch "$REF_BATCH" \
      --until-pixel-rel-error "$REF_ERROR" --quiet --out "$ref/reference_$eye.exr" | tee "$ref/$eye.stdout.json" >&2
  done
  reference=(--reference "$ref")
else
  ref="window of $REF_WINDOW deg around the scored gaze, up to $REF_SPP spp"
  reference=(--reference "$REF_SPP" --reference-window "$REF_WINDOW" --reference-error "$REF_ERROR")
fi

loads=()
for dist in visual-polar cartesian; do
  echo "$dist, $FRAMES frames (load $(load))..." >&2
  loads+=("$(load)")
  budget=()
  [[ $dist == visual-polar ]] && budget=("${vp_budget[@]}")
  "$FOVEA" render --display "$PRESET" --scene default --frames "$FRAMES" --distribution $dist --png-every 0 --quiet --trace "$TRACE" \
    "${budget[@]}" "${reference[@]}" --out "$OUT/$dist" >/dev/null
done
loads+=("$(load)")

python3 - "$OUT" "$ref" "${loads[@]}" <<'EOF'
import json, math, sys
out, ref, loads = sys.argv[1], sys.argv[2], sys.argv[3:]
rep = {d: json.load(open(f"{out}/{d}/report.json")) for d in ("visual-polar", "cartesian")}
eyes = ("left", "right")

def psnr(values):  # both eyes' PSNRs pooled as their mean squared error
    return -10 * math.log10(sum(10 ** (-v / 10) for v in values) / len(values))

def band(s, lo):
    return next(b for b in s["bands"] if b["e_min"] == lo)

def quality(r):
    s = [r["summary"][e] for e in eyes]
    for x, e in zip(s, eyes):
        lacking = [f"{lo}-{lo + 2} deg" for lo in (0, 2, 4) if band(x, lo)["psnr"] is None]
        lacking += ["the fovea"] if x["fovea_psnr"] is None else []
        if lacking:
            sys.exit(f"fove0-compare: the reference lacks pixels of {', '.join(lacking)} ({e} eye): "
                     "a wider REF_WINDOW, or a REF_DIR around this gaze")
    q = {"fovea PSNR": psnr([x["fovea_psnr"] for x in s]),
         "fovea HDR-FLIP": sum(x["fovea_hdr_flip"] for x in s) / 2}
    for lo in (0, 2, 4):
        q[f"{lo}-{lo + 2} PSNR"] = psnr([band(x, lo)["psnr"] for x in s])
        q[f"{lo}-{lo + 2} HDR-FLIP"] = sum(band(x, lo)["hdr_flip"] for x in s) / 2
    return q

def traced(d):  # who rendered the reference, in how long
    i = rep[d]["metrics"]["reference"]
    return " and ".join(f"{e} {'cached' if i[e]['cached'] else 'rendered in %.0f s' % i[e]['seconds']}" for e in eyes)

ri = rep["cartesian"]["metrics"]["reference"]
print(f"reference: {ref}; left {ri['left']['spp']} spp, per-pixel rel. error {ri['left']['pixel_rel_error']:.4f} "
      f"(key {ri['left']['key']}); right {ri['right']['spp']} spp, {ri['right']['pixel_rel_error']:.4f} "
      f"(key {ri['right']['key']}); by the visual-polar run: {traced('visual-polar')}; "
      f"HDR-FLIP exposures from the {ri['left']['hdr_flip_exposures']['from']}")
print(f"device: {rep['cartesian']['device']['name']} ({rep['cartesian']['device']['driver']}); "
      f"load average (1/5/15 min) before VP, before Cartesian, after: {' | '.join(loads)}")
print(f"visual-polar budget {rep['visual-polar']['config']['budget']}; tracing: {rep['cartesian']['trace']}")
print(f"median of {rep['cartesian']['frames']} frames, both eyes, ms; quality of the last frame, both eyes "
      "(PSNR tone-mapped, pooled by MSE; HDR-FLIP mean), bands in degrees of eccentricity")
cols = ["traced/eye", "trace", "reconstruct", "resolve", "trace+recon", "frame GPU", "frame CPU+GPU"]
qual = list(quality(rep["cartesian"]).keys())
print("| distribution | " + " | ".join(cols + qual) + " |")
print("|---" * (1 + len(cols) + len(qual)) + "|")
row = {}
for d, r in rep.items():
    g = r["gpu_ms"]
    row[d] = {"traced/eye": r["samples_traced_per_eye"], "trace": g["trace"], "reconstruct": g["reconstruct"],
              "resolve": g["resolve"], "trace+recon": g["trace"] + g["reconstruct"], "frame GPU": g["total"],
              "frame CPU+GPU": r["cpu_ms"]["total"]}
    row[d].update(quality(r))
    cells = [f"{row[d][c]:.0f}" for c in cols] + [f"{row[d][c]:.4f}" if "FLIP" in c else f"{row[d][c]:.2f}" for c in qual]
    print(f"| {d} | " + " | ".join(cells) + " |")
vp, ca = row["visual-polar"], row["cartesian"]
print("| Cartesian / VP | " + " | ".join(f"{ca[c] / vp[c]:.2f}x" for c in cols) + " |" +
      " |" * len(qual))
gain = lambda c: ca[c] / vp[c]
print(f"goals (issue 12 item 7): trace+recon {gain('trace+recon'):.2f}x (>= 4: {'met' if gain('trace+recon') >= 4 else 'NOT met'}), "
      f"frame GPU {gain('frame GPU'):.2f}x / CPU+GPU {gain('frame CPU+GPU'):.2f}x "
      f"(>= 3: {'met' if min(gain('frame GPU'), gain('frame CPU+GPU')) >= 3 else 'NOT met'}), "
      f"fovea quality VP - Cartesian: PSNR {vp['fovea PSNR'] - ca['fovea PSNR']:+.2f} dB, "
      f"HDR-FLIP {vp['fovea HDR-FLIP'] - ca['fovea HDR-FLIP']:+.4f} "
      f"({'equal or better' if vp['fovea PSNR'] >= ca['fovea PSNR'] and vp['fovea HDR-FLIP'] <= ca['fovea HDR-FLIP'] else 'worse'})")
EOF

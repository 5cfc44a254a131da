#!/usr/bin/env bash
# Whole frame on fove0 (docs/reconstruction.md): Visual-Polar (default settings) against
# full-resolution Cartesian, the same reconstruction, back to back, both scored against one
# converged reference of the default scene; prints the table of times, gains and fovea quality.
#
#   tools/fove0-compare.sh [OUT]        (from the source tree, after ./x build)
#
# Environment: FOVEA (the binary) [build/release/tools/fovea]; FRAMES [3]; BUDGET: Visual-Polar's
# --budget [its default]; REF_SPP, REF_BATCH
# [8, 2]: the reference's samples per pixel and batch (it also stops at a per-pixel relative
# error of 0.02); REF_DIR: use reference_{left,right}.exr from there instead (any written by
# `fovea reference` for this scene and view). The reference goes through the reference cache
# (--reference-cache, default $XDG_CACHE_HOME/fovea/references): a second run reuses it.
# Needs python3 for the table.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/fove0-compare}
FOVEA=${FOVEA:-build/release/tools/fovea}
FRAMES=${FRAMES:-3}
PRESET=${PRESET:-fove0}  # another display preset, for trying the script quickly
REF_SPP=${REF_SPP:-8}
REF_BATCH=${REF_BATCH:-2}
vp_budget=()
[[ -n ${BUDGET:-} ]] && vp_budget=(--budget "$BUDGET")
command -v python3 >/dev/null || { echo "fove0-compare: python3 is needed for the table" >&2; exit 2; }
[[ -x $FOVEA ]] || { echo "fove0-compare: no fovea binary at $FOVEA (./x build, or set FOVEA)" >&2; exit 2; }
[[ -n ${VK_ICD_FILENAMES:-} ]] || eval "$(./x env)"
export LP_NUM_THREADS=${LP_NUM_THREADS:-2} FOVEA_SOURCE_DIR=$PWD
mkdir -p "$OUT"
load() { cut -d' ' -f1-3 /proc/loadavg; }

ref=${REF_DIR:-$OUT/reference}
if [[ -z ${REF_DIR:-} ]]; then
  mkdir -p "$ref"
  for eye in left right; do
    echo "reference, $eye eye (load $(load))..." >&2
    "$FOVEA" reference --display "$PRESET" --scene default --eye $eye --spp "$REF_SPP" --batch "$REF_BATCH" \
      --until-pixel-rel-error 0.02 --quiet --out "$ref/reference_$eye.exr" | tee "$ref/$eye.stdout.json" >&2
  done
fi

loads=()
for dist in visual-polar cartesian; do
  echo "$dist, $FRAMES frames (load $(load))..." >&2
  loads+=("$(load)")
  budget=()
  [[ $dist == visual-polar ]] && budget=("${vp_budget[@]}")
  "$FOVEA" render --display "$PRESET" --scene default --frames "$FRAMES" --distribution $dist --png-every 0 --quiet \
    "${budget[@]}" --reference "$ref" --out "$OUT/$dist" >/dev/null
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
    q = {"fovea PSNR": psnr([x["fovea_psnr"] for x in s]),
         "fovea HDR-FLIP": sum(x["fovea_hdr_flip"] for x in s) / 2}
    for lo in (0, 2, 4):
        q[f"{lo}-{lo + 2} PSNR"] = psnr([band(x, lo)["psnr"] for x in s])
        q[f"{lo}-{lo + 2} HDR-FLIP"] = sum(band(x, lo)["hdr_flip"] for x in s) / 2
    return q

ri = rep["cartesian"]["metrics"]["reference"]
print(f"reference: {ref}; left {ri['left']['spp']} spp, per-pixel rel. error {ri['left']['pixel_rel_error']:.3f} "
      f"(key {ri['left']['key']}); right {ri['right']['spp']} spp, {ri['right']['pixel_rel_error']:.3f} "
      f"(key {ri['right']['key']})")
print(f"device: {rep['cartesian']['device']['name']} ({rep['cartesian']['device']['driver']}); "
      f"load average (1/5/15 min) before VP, before Cartesian, after: {' | '.join(loads)}")
print(f"visual-polar budget {rep['visual-polar']['config']['budget']}")
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

#!/usr/bin/env bash
# Every measurement of the real-time work (GPU time per stage, speed-up per preset, traversal),
# in one call on whatever Vulkan device the machine has (docs/building.md, "Measuring another
# device"), each step within its share of a deadline:
#   device      the device, the driver and the traversal `--trace auto` takes (a `tiny` render)
#   sweep       data/sweeps/device.json: each display preset, Visual-Polar at budgets 0.1-0.39
#               against full-resolution Cartesian, 16 frames, time only (no references: the
#               images, so the scores, do not depend on the device), and its report: the
#               per-preset speed-up table and every stage's GPU and CPU time
#   frame       one stereo frame per stage, GPU and CPU, fove0 and modern (fovea_bench_frame)
#   traversal   rays per second by ray type, both traversals (and Embree where it was built)
#   trace-cost  trace time per traced sample and the SIMD vectors' use, fove0 and modern
#   bmfr-fit    BMFR's fit at 1280×720 per schedule (workgroup, subgroup reductions), GPU ms:
#               the device's own (reconstruct::bmfr_schedule) against the others
#   tests       the GPU test programs with the validation layer on
# A step that would not finish before the deadline is cut short (the sweep keeps the jobs it
# finished, and resumes when run again with the same OUT) or skipped, and says so.
# OUT/summary.md lists each step's status, wall time and files; everything the programs print
# is kept beside it.
#
#   tools/device-measure.sh OUT              from a source tree, after ./x build
#   DIR/run.sh bash DIR/device-measure.sh OUT  from a bundle made by ./x bundle DIR
# Environment: DEADLINE seconds from the start [420]; QUICK=1: the `tiny` display only, 2
# frames, small batches, no test programs (checks that the script works; CTest runs it so on
# lavapipe); LANES, the device's SIMD width for the trace-cost table [32].
set -uo pipefail
[[ $# -eq 1 ]] || { echo "usage: device-measure.sh OUT" >&2; exit 2; }
OUT=$1
DEADLINE=${DEADLINE:-420} QUICK=${QUICK:-0} LANES=${LANES:-32}
for v in DEADLINE QUICK LANES; do
  [[ ${!v} =~ ^[0-9]+$ ]] || { echo "device-measure: $v=${!v} is not a whole number" >&2; exit 2; }
done
start=$SECONDS

mkdir -p "$OUT" || exit 2
OUT=$(cd "$OUT" && pwd)

# Where the programs are: a bundle's bin/ (the working directory's, or beside this script as
# ./x bundle places it), or a build tree.
here=$(cd "$(dirname "$0")" && pwd)
if [[ -x bin/fovea || -x $here/bin/fovea ]]; then
  [[ -x bin/fovea ]] || cd "$here" || exit 2
  fovea=bin/fovea bench=bin tests=(bin/fovea_{gpu,renderer,reconstruct,pipeline}_tests)
  export FOVEA_SOURCE_DIR=${FOVEA_SOURCE_DIR:-$PWD}
else
  cd "$here/.." || exit 2
  [[ -x build/release/tools/fovea ]] || { echo "device-measure: no bin/fovea here and no build/release (./x build)" >&2; exit 2; }
  [[ -n ${VK_ICD_FILENAMES:-}${VK_DRIVER_FILES:-} || ${FOVEA_VK_DRIVER:-} == loader ]] || eval "$(./x env)"
  export FOVEA_SOURCE_DIR=${FOVEA_SOURCE_DIR:-$PWD}
  fovea=build/release/tools/fovea bench=build/release/bench
  tests=(build/release/tests/{gpu,renderer,reconstruct,pipeline}/fovea_*_tests)
fi
fovea=$PWD/$fovea bench=$PWD/$bench
export XDG_CACHE_HOME=${XDG_CACHE_HOME:-$OUT/cache}  # the renders' shader and reference caches
summary=() failed=0

# step NAME MAX_SECONDS COMMAND...: runs COMMAND with at most MAX_SECONDS, and never past the
# deadline (less 20 s for the report and the summary); its output goes to OUT/NAME.txt.
step() {
  local name=$1 max=$2
  shift 2
  local left=$((DEADLINE - (SECONDS - start) - 20)) t0=$SECONDS rc
  ((left < max)) && max=$left
  if ((max < 5)); then
    summary+=("| $name | skipped: the deadline ($DEADLINE s) was reached | – | – |")
    return 0
  fi
  printf 'device-measure: %s (at most %d s)\n' "$name" "$max" >&2
  timeout --kill-after=10 "$max" "$@" > "$OUT/$name.txt" 2>&1
  rc=$?
  local status="ok"
  ((rc == 124 || rc == 137)) && status="cut short after $max s"
  ((rc != 0 && rc != 124 && rc != 137)) && status="failed (exit $rc)" failed=1
  summary+=("| $name | $status | $((SECONDS - t0)) | $name.txt |")
  return 0
}

if ((QUICK)); then
  displays=(tiny) rays=4096 scenes=cornell
else
  displays=(fove0 modern) rays=1000000 scenes=default,cornell
fi

step device 120 "$fovea" render --display tiny --scene default --frames 2 --png-every 0 --quiet --out "$OUT/device"

# The sweep: the shipped device sweep, or in QUICK mode the same parts on `tiny` alone.
sweep_file=$FOVEA_SOURCE_DIR/data/sweeps/device.json
if ((QUICK)); then
  sweep_file=$OUT/device-quick.json
  printf '%s\n' '[{"scenes": "default", "displays": "tiny", "frames": 2, "png-every": 0,' \
    ' "distribution": "visual-polar", "budget": [0.2, 0.39],' \
    ' "report": {"time": "gpu_ms.total", "section": ["display"],' \
    '            "speedup": {"of": "visual-polar", "over": "cartesian", "at": [0.2, 0.39]}}},' \
    ' {"scenes": "default", "displays": "tiny", "frames": 2, "png-every": 0, "distribution": "cartesian",' \
    ' "raster-filter": "gaussian"}]' \
    > "$sweep_file"
fi
step sweep-plan 30 "$fovea" sweep plan "$sweep_file" --out "$OUT/sweep/plan.jsonl"
# One job at a time: each job's times are its own.
step sweep 300 "$fovea" sweep run "$OUT/sweep/plan.jsonl" --jobs 1
step sweep-report 60 "$fovea" sweep report "$OUT/sweep/plan.jsonl" --out "$OUT/sweep/report" \
  --markdown "$OUT/sweep/results.md"

# The frame's table (issue-style: GPU total, trace, reconstruction, BMFR fit, the frame's CPU
# time, and reading both eyes back apart from it) per preset and distribution.
displays_csv=$(IFS=,; echo "${displays[*]}")
step frame 120 env FOVEA_BENCH_DISPLAYS="$displays_csv" "$bench/fovea_bench_frame" --benchmark_counters_tabular=true
step traversal 90 "$bench/fovea_bench_traversal" --scenes "$scenes" --rays "$rays"
for d in "${displays[@]}"; do
  step "trace-cost-$d" 120 "$bench/fovea_bench_trace_cost" "$d" 1 "$LANES"
done
# QUICK: the device's own schedule only (lavapipe compiles each other variant in seconds).
fits='fit/workgroup:(0|8|64|256)/subgroup:./fp16:0'
((QUICK)) && fits='fit/workgroup:0/'
step bmfr-fit 90 "$bench/fovea_bench_bmfr" --benchmark_filter="$fits" --benchmark_counters_tabular=true

if ((!QUICK)); then
  for t in "${tests[@]}"; do
    [[ -x $t ]] && step "tests-$(basename "$t")" 240 env FOVEA_VK_VALIDATION=1 "$t" --gtest_brief=1
  done
fi

{
  echo "# Device measurements"
  echo
  # report.json's "device" object and the traversal `--trace auto` took, with its reason.
  field() { grep -A8 "\"$1\": {" "$OUT/device/report.json" 2> /dev/null | sed -n "s/.*\"$2\": *\"\(.*\)\",\{0,1\}$/\1/p" | head -1; }
  echo "Device: $(field device name) ($(field device driver)); \`--trace auto\`: $(field trace_choice why)."
  echo "$(date -u +%Y-%m-%dT%H:%M:%SZ), $((SECONDS - start)) s in all."
  echo "The speed-up table and every job's stages: sweep/results.md; the raw reports: sweep/jobs/*/report.json."
  echo
  echo "| step | status | wall s | output |"
  echo "|---|---|---|---|"
  printf '%s\n' "${summary[@]}"
} > "$OUT/summary.md"
cat "$OUT/summary.md"
exit $failed

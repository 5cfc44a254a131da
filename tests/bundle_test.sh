#!/usr/bin/env bash
# tools/bundle.sh on a build: the bundle is moved after it is made, then its fovea must
# resolve every library but glibc's inside it and render with a bare environment (the
# Vulkan driver only from VK_ICD_FILENAMES / VK_DRIVER_FILES, as the caller has it); a
# directory that is not a bundle is never overwritten.
# Usage: tests/bundle_test.sh BUILD_DIR
set -uo pipefail
build=$1
src=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

bash "$src/tools/bundle.sh" "$build" "$work/made" || fail "bundle.sh exited $?"
mv "$work/made" "$work/moved"
b=$work/moved
outside=$(ldd "$b/bin/fovea" | grep -v -E "linux-vdso|ld-linux|/lib(c|m|dl|pthread|rt)\.so|$b/" || true)
[[ -z $outside ]] || fail "libraries from outside the bundle: $outside"
! ldd "$b/bin/fovea" "$b/lib/libXrApiLayer_fovea.so" | grep -q "not found" || fail "unresolved libraries"
for m in "$b"/share/openxr/1/api_layers/explicit.d/*.json "$b"/share/openxr/1/runtime.d/*.json; do
  lib=$(sed -n 's/.*"library_path": *"\([^"]*\)".*/\1/p' "$m")
  [[ -f $(dirname "$m")/$lib ]] || fail "$m: library_path $lib does not resolve"
done

# The driver's compiled shaders come from the caller's cache (the driver's own variable, not
# the bundle's: compiling them again cold took 8 of the render's 9 s, and a machine that has
# run its driver before has them); everything of fovea's own starts from an empty HOME.
shaders=${MESA_SHADER_CACHE_DIR:-${XDG_CACHE_HOME:-${HOME:-$work}/.cache}}
env -i PATH=/usr/bin:/bin HOME="$work" MESA_SHADER_CACHE_DIR="$shaders" ${VK_ICD_FILENAMES:+VK_ICD_FILENAMES=$VK_ICD_FILENAMES} \
  ${VK_DRIVER_FILES:+VK_DRIVER_FILES=$VK_DRIVER_FILES} \
  bash "$b/run.sh" bin/fovea render --display tiny --scene cornell --frames 1 --quiet --out "$work/render" \
  > "$work/render.log" 2>&1 || { cat "$work/render.log"; fail "the bundle's fovea render exited non-zero"; }
[[ -s $work/render/report.json && -s $work/render/frame_0000_sbs.png ]] || fail "render wrote no report or frame"

# The device measurements from the bundle, in their quick form (tiny display, small batches):
# every step runs and the summary names the device. The render's cache (its traversal choice)
# is shared, as a second call on the same machine would find it.
env -i PATH=/usr/bin:/bin HOME="$work" XDG_CACHE_HOME="$work/.cache" MESA_SHADER_CACHE_DIR="$shaders" QUICK=1 \
  ${VK_ICD_FILENAMES:+VK_ICD_FILENAMES=$VK_ICD_FILENAMES} \
  ${VK_DRIVER_FILES:+VK_DRIVER_FILES=$VK_DRIVER_FILES} LP_NUM_THREADS="${LP_NUM_THREADS:-2}" \
  bash "$b/run.sh" bash "$b/device-measure.sh" "$work/measure" > "$work/measure.log" 2>&1 ||
  { cat "$work/measure.log"; fail "device-measure.sh exited non-zero"; }
for s in device sweep-plan sweep sweep-report frame traversal trace-cost-tiny bmfr-fit; do
  grep -q "^| $s | ok |" "$work/measure/summary.md" || { cat "$work/measure/summary.md"; fail "device-measure: step $s not ok"; }
done
grep -q "^Device: llvmpipe" "$work/measure/summary.md" || fail "device-measure: the summary names no device"
grep -q "| display tiny | " "$work/measure/sweep/results.md" || fail "device-measure: no speed-up row for tiny"

mkdir "$work/mine" && touch "$work/mine/keep"
bash "$src/tools/bundle.sh" "$build" "$work/mine" > /dev/null 2>&1
[[ $? -eq 2 && -f $work/mine/keep ]] || fail "a directory that is not a bundle was not refused with exit 2"
echo "bundle: ok ($(du -sh "$b" | cut -f1))"

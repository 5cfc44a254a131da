#!/usr/bin/env bash
# The hostile inputs of the new-user campaign, each run through the `fovea` program given:
# one TSV row per input (what, exit code, the first warning or error line). Makes its inputs
# from the shipped presets and recordings in a temporary directory; a run takes a few
# minutes on lavapipe. Regression tests hold each case (tests/tools/hostile_inputs_cli_test.cpp
# and the modules' own tests); this script gives the table of docs/measurements.md.
# Usage: tools/hostile-inputs.sh FOVEA [OUT.tsv]
set -uo pipefail
fovea=$(realpath "$1") out=$(realpath -m "${2:-/dev/stdout}")
src=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
export FOVEA_SOURCE_DIR=$src
eval "$("$src/x" env)"

display() {  # NAME PYTHON-STATEMENT: the small preset changed by the statement
  python3 -c "import json,sys; d=json.load(open('$src/data/displays/small.json')); $2; json.dump(d, open('$1', 'w'))"
}
display refresh.json 'd["refresh_hz"]=1e-9'
display raster16k.json 'd["width"]=d["height"]=16384'
display raster64k.json 'd["width"]=d["height"]=65536'
display raster8k.json 'd["width"]=d["height"]=8192'
display fov170.json 'd["fov_deg"]={"left":-85,"right":85,"up":53.28,"down":-53.28}'
display ipdneg.json 'd["ipd_m"]=-0.063'
display ipdhuge.json 'd["ipd_m"]=1e30'
display lensk.json 'd["lens"]["k"]=[1e30,0,0,0,0]'
printf 'v nan nan nan\nv 1 0 -3\nv 0 1 -3\nf 1 2 3\n' > nan.obj
gaze_csv() {  # FILE X,Y,Z: 101 samples at 120 Hz, all in that direction
  { echo "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags"
    for i in $(seq 0 100); do echo "$((i * 8333333)),combined,$2,0.95,1"; done; } > "$1"
}
gaze_csv behind.csv 0,0,1
gaze_csv offscreen.csv 0.995,0,0.1
: > empty.jsonl
touch existing_file
gzip -c "$src/data/gaze/hid-ms.hidcap" > full.hidcap.gz
head -c 3000 full.hidcap.gz > trunc.hidcap.gz

row() {  # WHAT TIMEOUT COMMAND...
  local what=$1 limit=$2; shift 2
  timeout "$limit" "$@" > stdout 2> stderr
  local rc=$?
  local said
  said=$( (grep -m1 -iE "warning|error|refus|must|expected|cannot|not |limit|null" stderr || head -1 stderr) | cut -c1-160)
  printf '%s\t%s\t%s\n' "$what" "$rc" "$said"
}
R=(render --frames 2 --quiet --out r)
{
  row "gaze info synthetic:1?seconds=0" 20 "$fovea" gaze info 'synthetic:1?seconds=0'
  row "gaze plot synthetic:1?seconds=0" 20 "$fovea" gaze plot 'synthetic:1?seconds=0' p.png
  row "gaze convert synthetic:1?seconds=0" 10 "$fovea" gaze convert 'synthetic:1?seconds=0' c.csv; rm -f c.csv*
  row "render, refresh 1e-9 Hz, synthetic gaze" 30 "$fovea" "${R[@]}" --display refresh.json --gaze synthetic:1
  row "density, 16384^2 raster" 30 "$fovea" density --display raster16k.json --json
  row "density, 65536^2 raster" 30 "$fovea" density --display raster64k.json --json
  row "lens, 16384^2 raster" 60 "$fovea" lens --display raster16k.json --out l.png --json
  row "render, 16384^2 raster" 90 "$fovea" "${R[@]}" --display raster16k.json
  row "render, 8192^2 raster (the largest accepted)" 300 "$fovea" "${R[@]}" --display raster8k.json --png-every 0
  row "render --out an existing file" 30 "$fovea" render --frames 1 --display tiny --out existing_file
  row "gaze plot into a missing directory" 60 "$fovea" gaze plot "$src/data/gaze/default.csv" missing/dir/p.png
  row "render, display FOV +-85 deg" 30 "$fovea" "${R[@]}" --display fov170.json
  row "render, negative IPD" 60 "$fovea" "${R[@]}" --display ipdneg.json
  row "render, IPD 1e30" 60 "$fovea" "${R[@]}" --display ipdhuge.json
  row "lens, k = 1e30" 30 "$fovea" lens --display lensk.json --out l.png --json
  row "render, OBJ v nan nan nan" 60 "$fovea" "${R[@]}" --display tiny --scene nan.obj
  row "render, gaze behind the viewer" 60 "$fovea" "${R[@]}" --display tiny --gaze behind.csv
  row "latency --records, no records" 30 "$fovea" latency --records empty.jsonl --out lat
  "$fovea" render --display tiny --frames 2 --png-every 0 --quiet --out lr > /dev/null 2>&1
  row "latency --records of a render (no photon times)" 30 "$fovea" latency --records lr/frame_times.jsonl --out lat
  row "reference --spp 16 (one batch)" 120 "$fovea" reference --display tiny --spp 16 --reference-cache off --quiet --out ref.exr
  row "gaze info, CSV 84 deg off to the side" 30 "$fovea" gaze info offscreen.csv
  row "render, CSV gaze 84 deg off to the side" 60 "$fovea" "${R[@]}" --display tiny --gaze offscreen.csv
  row "gaze info, truncated gzip hid-capture:" 30 "$fovea" gaze info hid-capture:trunc.hidcap.gz
  row "gaze info, gzipped HID capture (no prefix)" 30 "$fovea" gaze info full.hidcap.gz
  row "render --gaze data/gaze/hid-ms.hidcap" 60 "$fovea" "${R[@]}" --display tiny --gaze "$src/data/gaze/hid-ms.hidcap"
  row "gaze info with speed=2" 30 "$fovea" gaze info "$src/data/gaze/default.csv?speed=2"
} > "$out"

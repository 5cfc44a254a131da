#!/usr/bin/env bash
# The fuzz findings through the command line: each regression scene and display preset
# must be refused with exit code 2 and a message naming the file (never a crash or a
# raw library message). The inputs listed in REGRESSIONS_DIR/renders-with-warning.txt hold
# a part the loaders replace by a documented default (an unusable texture becomes white):
# those must render (exit 0) with a warning naming the file instead.
# Usage: cli_findings.sh FOVEA REGRESSIONS_DIR
set -uo pipefail
fovea=$1 dir=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail=0 checked=0
check() {  # file, command...
  local file=$1; shift
  "$@" >"$out/stdout" 2>"$out/stderr"
  local status=$?
  checked=$((checked + 1))
  local want=2 said="$file"
  if grep -qxF "$(basename "$file")" "$dir/renders-with-warning.txt" 2>/dev/null; then
    want=0 said="warning: $file"
  fi
  if [[ $status -ne $want ]] || ! grep -qF "$said" "$out/stderr" || grep -q "json.exception" "$out/stderr"; then
    echo "FAIL ($status): $*"; cat "$out/stderr"; fail=1
  else
    echo "ok: $(basename "$file"): $(head -c 200 "$out/stderr")"
  fi
}
for f in "$dir"/gltf/* "$dir"/glb/*; do
  [[ -f $f ]] && check "$f" "$fovea" render --scene "$f" --frames 1 --out "$out/render"
done
# OBJ inputs as the obj harness reads them: up to a line "#mtl" the OBJ, then fuzz.mtl.
for f in "$dir"/obj/*; do
  [[ -f $f ]] || continue
  mkdir -p "$out/obj" && rm -f "$out/obj"/*
  obj=$out/obj/$(basename "$f")
  awk -v obj="$obj" -v mtl="$out/obj/fuzz.mtl" '$0 == "#mtl" { into_mtl = 1; next } { print > (into_mtl ? mtl : obj) }' "$f"
  check "$obj" "$fovea" render --scene "$obj" --frames 1 --out "$out/render"
done
for f in "$dir"/display/*; do
  [[ -f $f ]] && check "$f" "$fovea" density --display "$f" --json
done
echo "$checked inputs checked"
exit $fail

#!/usr/bin/env bash
# A relocatable copy of a build: the programs (fovea, the benchmarks, the GPU test binaries),
# the OpenXR layer and runtime with manifests, every library they load that is not glibc's
# (Debian's Vulkan and OpenXR loaders, libstdc++ included), the Khronos validation layer and
# data/, so that they run on another Linux x86-64 machine that has only a GPU driver.
# Programs find their libraries through an $ORIGIN run path; run.sh sets the rest.
# Usage: tools/bundle.sh BUILD_DIR OUT_DIR     (./x bundle OUT_DIR bundles build/release)
#        OUT_DIR/run.sh bin/fovea render --display fove0 ...   (on the other machine)
#        OUT_DIR/run.sh bash OUT_DIR/device-measure.sh OUT     (every measurement, one call)
set -euo pipefail
if [[ $# -ne 2 ]]; then
  echo "usage: tools/bundle.sh BUILD_DIR OUT_DIR" >&2
  exit 2
fi
build=$(realpath "$1")
out=$(realpath -m "$2")
src=$(cd "$(dirname "$0")/.." && pwd)
multiarch=$(uname -m)-linux-gnu
if [[ ! -x $build/tools/fovea ]]; then
  echo "bundle: $build/tools/fovea is missing: build first (./x build)" >&2
  exit 2
fi
if [[ -e $out && ! -f $out/.fovea-bundle ]]; then
  echo "bundle: $out exists and is not a bundle; give a new directory" >&2
  exit 2
fi
command -v patchelf > /dev/null || { echo "bundle: patchelf is missing (apt-get install patchelf)" >&2; exit 2; }

mkdir -p "$(dirname "$out")"
tmp=$(mktemp -d "$(dirname "$out")/.bundle.XXXXXX")  # beside OUT_DIR: the rename stays on one filesystem
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp"/{bin,lib,share/vulkan/explicit_layer.d,share/openxr/1/api_layers/explicit.d,share/openxr/1/runtime.d}

programs=("$build/tools/fovea")
for p in "$build"/bench/fovea_bench_* "$build"/tests/{gpu,renderer,reconstruct,pipeline}/fovea_*_tests; do
  [[ -f $p && -x $p ]] && programs+=("$p")
done
ours=("$build/layer/libXrApiLayer_fovea.so" "$build/runtime/libfovea_runtime.so")
cp "${programs[@]}" "$tmp/bin/"
cp "${ours[@]}" "$tmp/lib/"

# Every library the loader resolves for them, but glibc's own (the target's C library and
# dynamic linker must be the ones its kernel and driver use).
glibc='/(ld-linux[^/]*|lib(c|m|dl|pthread|rt|resolv|util|anl|mvec)\.so[^/]*)$'
while read -r lib; do
  [[ -n $lib && ! $lib =~ $glibc ]] && cp -Ln "$lib" "$tmp/lib/"
done < <(for f in "${programs[@]}" "${ours[@]}"; do ldd "$f" | awk '$2 == "=>" && $3 ~ /^\// {print $3}'; done | sort -u)
# The Khronos validation layer, which the GPU tests turn on.
validation=/usr/lib/$multiarch/libVkLayer_khronos_validation.so
if [[ -f $validation ]]; then
  cp -L "$validation" "$tmp/lib/"
  sed 's|"library_path": *"[^"]*"|"library_path": "../../../lib/libVkLayer_khronos_validation.so"|' \
    /usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json \
    > "$tmp/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json"
fi
# OpenXR manifests: library paths relative to the manifest, as both loaders resolve them.
sed 's|"library_path": *"[^"]*"|"library_path": "../../../../../lib/libXrApiLayer_fovea.so"|' \
  "$build/layer/explicit/XrApiLayer_fovea.json" > "$tmp/share/openxr/1/api_layers/explicit.d/XrApiLayer_fovea.json"
sed 's|"library_path": *"[^"]*"|"library_path": "../../../../lib/libfovea_runtime.so"|' \
  "$build/runtime/fovea_runtime.json" > "$tmp/share/openxr/1/runtime.d/fovea_runtime.json"

for f in "$tmp"/bin/*; do patchelf --set-rpath '$ORIGIN/../lib' "$f"; done
for f in "$tmp"/lib/*; do patchelf --set-rpath '$ORIGIN' "$f"; done
cp -r "$src/data" "$tmp/data"
cp "$src/tools/device-measure.sh" "$tmp/"

# The newest glibc symbol version any file asks for: the oldest C library it runs with.
needs=$(for f in "$tmp"/bin/* "$tmp"/lib/*; do objdump -T "$f" 2> /dev/null; done |
  grep -o 'GLIBC_[0-9.]*' | sort -u -V | tail -1)
cat > "$tmp/run.sh" << 'EOF'
#!/usr/bin/env bash
# Runs a program of this bundle: bin/fovea, bin/fovea_bench_*, bin/fovea_*_tests. The Vulkan
# driver is the loader's own search (the machine's GPU driver) unless FOVEA_VK_DRIVER or
# VK_ICD_FILENAMES / VK_DRIVER_FILES say otherwise; data/ and the layers are the bundle's.
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
export FOVEA_SOURCE_DIR=$here
export FOVEA_VK_DRIVER=${FOVEA_VK_DRIVER:-loader}
export VK_LAYER_PATH=$here/share/vulkan/explicit_layer.d${VK_LAYER_PATH:+:$VK_LAYER_PATH}
export XR_API_LAYER_PATH=$here/share/openxr/1/api_layers/explicit.d${XR_API_LAYER_PATH:+:$XR_API_LAYER_PATH}
cmd=${1:?usage: run.sh bin/PROGRAM [ARGS...]}
shift
[[ $cmd != /* && -x $here/$cmd ]] && cmd=$here/$cmd
exec "$cmd" "$@"
EOF
chmod +x "$tmp/run.sh"
{
  echo "Fovea $(git -C "$src" describe --always --dirty 2> /dev/null || echo unknown), built on $(. /etc/os-release && echo "$PRETTY_NAME")"
  echo "Runs on Linux $(uname -m) with glibc >= ${needs#GLIBC_} and a Vulkan 1.2 driver; nothing else is needed."
  echo "  ./run.sh bin/fovea render --display fove0 --out out/render"
  echo "  ./run.sh bin/fovea_gpu_tests   (FOVEA_VK_VALIDATION=1: the validation layer of share/vulkan)"
  echo "  ./run.sh bash device-measure.sh out/measure   (every measurement of a device, in one call)"
  echo "The OpenXR layer: XR_API_LAYER_PATH=share/openxr/1/api_layers/explicit.d (run.sh sets it),"
  echo "XR_ENABLE_API_LAYERS=XR_APILAYER_FOVEA_path_tracing; the simulated runtime: share/openxr/1/runtime.d."
} > "$tmp/README"
touch "$tmp/.fovea-bundle"

chmod 755 "$tmp"
rm -rf "$out"
mv "$tmp" "$out"
trap - EXIT
echo "bundle: $out ($(du -sh "$out" | cut -f1), ${#programs[@]} programs, $(ls "$out/lib" | wc -l) libraries; glibc >= ${needs#GLIBC_})"

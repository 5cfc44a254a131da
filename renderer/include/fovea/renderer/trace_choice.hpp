#pragma once
// `--trace auto`: the faster of the two traversals on this device. Ray queries are not
// always faster: on lavapipe they trace at half the compute BVH's rate. So auto measures
// both once per device, driver and shader build on a fixed probe (the default scene, a
// 160x160 grid, one path per cell) and keeps the result in a cache file; later runs read it.
#include <optional>
#include <string>

#include "fovea/gpu/context.hpp"
#include "fovea/renderer/gpu_scene.hpp"

namespace fovea::renderer {

struct TraceChoice {
  Tracing tracing = Tracing::Compute;  // resolved: RayQuery or Compute, never Auto
  std::string why;                     // for reports and logs
  std::optional<double> compute_ms, rayquery_ms;  // the probe's time per frame, when measured
  bool cached = false;                            // the measurement came from the cache file
};

// `requested` RayQuery or Compute is kept (an unsupported RayQuery fails later, in GpuScene,
// naming the device). Auto on a device without ray queries is Compute. Otherwise the entry
// for this device in `cache_file` ("" : none, measured every time), or a measurement that
// is then written there (to a temporary name, renamed). An unreadable or foreign cache file
// is measured over, with the reason in `why`.
// `measure` false: without a cached entry, no measurement (the OpenXR layer does not delay its
// first frame for one): ray queries where the device offers them, as before auto measured.
TraceChoice choose_tracing(gpu::Context& ctx, Tracing requested, const std::string& cache_file, bool measure = true);

// FOVEA_TRACE_CHOICE_CACHE (a file, or "off": ""), else $XDG_CACHE_HOME/fovea/trace-choice.json,
// else ~/.cache/fovea/trace-choice.json, else "".
std::string default_trace_choice_cache();

}  // namespace fovea::renderer

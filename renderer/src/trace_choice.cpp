#include "fovea/renderer/trace_choice.hpp"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

#include <nlohmann/json.hpp>

#include "fovea/core/clock.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/view.hpp"
#include "fovea/renderer/path_tracer.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "fovea/shaders/embedded.hpp"

namespace fovea::renderer {

namespace fs = std::filesystem;

namespace {

constexpr int kProbeSize = 160;   // cells per side: a few hundred ms per frame on lavapipe
constexpr int kProbeFrames = 3;   // timed frames, after one untimed (pipeline and caches warm)

// The device, its driver and the two tracers' SPIR-V: a new driver or shader build measures anew.
std::string device_key(const gpu::Context& ctx) {
  std::size_t h = 0;
  for (const char* name : {"pt_trace.comp.spv", "pt_trace.rayquery.comp.spv"}) {
    const auto bytes = shaders::find(name);
    h = h * 31 + std::hash<std::string_view>{}(
                     std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  }
  std::ostringstream k;
  k << ctx.info().name << " | " << ctx.info().driver << " | shaders " << std::hex << h;
  return k.str();
}

// Milliseconds per probe frame with `tracing`: wall clock around each submission and its
// fence (the device's time, plus the submission).
double probe_ms(gpu::Context& ctx, const Scene& scene, Tracing tracing) {
  const GpuScene gs(ctx, scene, {}, tracing);
  const PathTracer pt(ctx, gs);
  const core::View view(core::Fov::from_degrees(-40, 40, 40, -40), kProbeSize, kProbeSize);
  const auto grid = cartesian_grid(view);
  gpu::Buffer g(ctx, {grid.size() * sizeof(shaders::GridSample), gpu::BufferUsage::Storage, gpu::Memory::DeviceLocal,
                      "trace_choice.grid"});
  g.upload(grid);
  TraceOutputs out = pt.bind(g, std::uint32_t(grid.size()));
  const PathConfig cfg;  // the real-time configuration: one path per cell, as a frame traces
  double ms = 0;
  for (int f = 0; f <= kProbeFrames; ++f) {
    const core::TimeNs t0 = core::now_ns();
    ctx.submit_and_wait([&](VkCommandBuffer cmd) { pt.record(cmd, out, view, core::Eye::Left, std::uint32_t(f), cfg); });
    if (f > 0) ms += core::ns_to_ms(core::now_ns() - t0);
  }
  return ms / kProbeFrames;
}

std::string fmt_ms(double ms) {
  std::ostringstream s;
  s.precision(ms < 10 ? 2 : 0);
  s << std::fixed << ms << " ms";
  return s.str();
}

TraceChoice from_times(double compute, double rayquery) {
  TraceChoice c;
  c.compute_ms = compute;
  c.rayquery_ms = rayquery;
  c.tracing = rayquery < compute ? Tracing::RayQuery : Tracing::Compute;
  c.why = std::string(c.tracing == Tracing::RayQuery ? "ray queries" : "the compute BVH traversal") +
          " measured faster on this device: compute " + fmt_ms(compute) + ", ray queries " + fmt_ms(rayquery) +
          " per probe frame";
  return c;
}

}  // namespace

std::string default_trace_choice_cache() {
  if (const char* f = std::getenv("FOVEA_TRACE_CHOICE_CACHE"); f && *f) return std::string_view(f) == "off" ? "" : f;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return (fs::path(x) / "fovea" / "trace-choice.json").string();
  if (const char* h = std::getenv("HOME"); h && *h) return (fs::path(h) / ".cache" / "fovea" / "trace-choice.json").string();
  return "";
}

TraceChoice choose_tracing(gpu::Context& ctx, Tracing requested, const std::string& cache_file, bool measure) {
  if (requested != Tracing::Auto) return {requested, "asked for (--trace)", {}, {}, false};
  if (!ctx.features().ray_query) return {Tracing::Compute, "the device has no ray queries", {}, {}, false};
  const std::string key = device_key(ctx);
  nlohmann::json cache = nlohmann::json::object();
  std::string stale;
  if (!cache_file.empty() && fs::exists(cache_file)) {
    try {
      std::ifstream in(cache_file);
      cache = nlohmann::json::parse(in);
      if (!cache.is_object()) throw std::runtime_error("not a JSON object");
      if (cache.contains(key)) {
        const nlohmann::json& e = cache.at(key);
        TraceChoice c = from_times(e.at("compute_ms").get<double>(), e.at("rayquery_ms").get<double>());
        c.cached = true;
        c.why += " (measured once, " + cache_file + ")";
        return c;
      }
    } catch (const std::exception& e) {
      stale = " (" + cache_file + " was unreadable and is measured over: " + e.what() + ")";
      cache = nlohmann::json::object();
    }
  }
  if (!measure)
    return {Tracing::RayQuery, "no measurement for this device in " + (cache_file.empty() ? "(no cache)" : cache_file) +
                                   stale + " and none taken here: ray queries, which the device offers", {}, {}, false};
  const Scene probe = load_scene("default");
  const double compute = probe_ms(ctx, probe, Tracing::Compute);
  const double rayquery = probe_ms(ctx, probe, Tracing::RayQuery);
  TraceChoice c = from_times(compute, rayquery);
  c.why += stale;
  if (!cache_file.empty()) {
    cache[key] = {{"compute_ms", compute}, {"rayquery_ms", rayquery}, {"device", ctx.info().name},
                  {"driver", ctx.info().driver}};
    // A cache that cannot be written costs the next run a measurement, nothing else.
    try {
      fs::create_directories(fs::path(cache_file).parent_path());
      core::write_file_atomic(cache_file, cache.dump(2) + "\n");
    } catch (const std::exception& e) {
      c.why += " (not kept: " + std::string(e.what()) + ")";
    }
  }
  return c;
}

}  // namespace fovea::renderer

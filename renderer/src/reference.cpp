#include "fovea/renderer/reference.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include <tinyexr.h>

#include "fovea/core/clock.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/tonemap.hpp"

namespace fovea::renderer {

namespace {
double luminance(glm::dvec3 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }
constexpr double kPixelEpsilon = 0.01;  // core::kRelMseEpsilon

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}
}  // namespace

std::vector<bool> window_coverage(const ReferenceWindow& window, const core::View& view, const std::string& what) {
  const std::size_t n = std::size_t(view.width()) * std::size_t(view.height());
  if (window.whole()) return std::vector<bool>(n, true);
  std::vector<bool> inside(n, false);
  for (std::size_t k = 0; k < window.discs.size(); ++k) {
    const WindowDisc& d = window.discs[k];
    const std::string name = window.discs.size() > 1 ? what + ", disc " + std::to_string(k + 1) : what;
    const double len = glm::length(d.centre);
    if (!std::isfinite(len) || !(len > 0))
      throw core::InputError(name + ": the centre must be a finite, non-zero view-space direction");
    if (!std::isfinite(d.radius_deg) || !(d.radius_deg > 0) || d.radius_deg > 180)
      throw core::InputError(name + ": the radius must be in (0, 180] degrees, got " + number(d.radius_deg));
    const glm::dvec3 c = d.centre / len;
    std::size_t hits = 0;
    for (int y = 0; y < view.height(); ++y)
      for (int x = 0; x < view.width(); ++x)
        if (core::angle_deg(view.pixel_to_dir({x + 0.5, y + 0.5}), c) <= d.radius_deg) {
          inside[std::size_t(y) * std::size_t(view.width()) + std::size_t(x)] = true;
          ++hits;
        }
    if (hits == 0)
      throw core::InputError(name + ": off the view, no pixel centre lies within " + number(d.radius_deg) + " deg of (" +
                             number(c.x) + ", " + number(c.y) + ", " + number(c.z) + ")");
  }
  return inside;
}

ReferenceResult render_reference(gpu::Context& ctx, const GpuScene& scene, const core::View& view, core::Eye eye,
                                 const ReferenceOptions& o, const std::function<void(const ReferenceProgress&)>& progress) {
  if (o.max_spp == 0) throw core::InputError("reference: --spp must be at least 1");
  if (!(o.until_rel_error >= 0) || !std::isfinite(o.until_rel_error))
    throw core::InputError("reference: --until-rel-error must be a finite number >= 0");
  if (!(o.until_pixel_rel_error >= 0) || !std::isfinite(o.until_pixel_rel_error))
    throw core::InputError("reference: the per-pixel relative error target must be a finite number >= 0");
  const std::vector<bool> covered = window_coverage(o.window, view, "reference window");
  // The pixels the statistics and the image cover; the others are flagged, which the tracer
  // skips (the flag says why: outside the part of the view asked for).
  std::vector<std::size_t> inside;
  for (std::size_t i = 0; i < covered.size(); ++i)
    if (covered[i]) inside.push_back(i);
  const core::TimeNs t0 = core::now_ns();
  auto grid = cartesian_grid(view);
  for (std::size_t i = 0; i < grid.size(); ++i)
    if (!covered[i]) grid[i].flags = shaders::kCellOffscreen;
  gpu::Buffer g(ctx, {grid.size() * sizeof(shaders::GridSample), gpu::BufferUsage::Storage, gpu::Memory::DeviceLocal,
                      "reference.grid"});
  g.upload(grid);
  PathTracer pt(ctx, scene);
  TraceOutputs out = pt.bind(g, std::uint32_t(grid.size()));
  PathConfig cfg = o.path;
  cfg.jitter = true;  // pixel-area estimate: anti-aliased
  cfg.spp = std::max<std::uint32_t>(1, std::min(cfg.spp, o.max_spp));

  ReferenceResult r;
  std::vector<glm::vec4> pixels;
  std::vector<double> batch_means;  // luminance of each batch's image mean
  // Per pixel: sums of its batch luminances and of their squares (batch-means variance).
  std::vector<double> pix_sum, pix_sq;
  std::uint32_t batches = 0;
  while (r.spp < o.max_spp) {
    PathConfig c = cfg;
    c.spp = std::min(cfg.spp, o.max_spp - r.spp);
    // Each batch is traced on its own (frame = batch index for fresh random numbers) so
    // its image mean is an independent estimate for the batch-means error.
    ctx.submit_and_wait([&](VkCommandBuffer cmd) { pt.record(cmd, out, view, eye, batches, c, 0); });
    pixels = out.radiance().download<glm::vec4>();
    glm::dvec3 mean(0);
    for (std::size_t i : inside) mean += glm::dvec3(pixels[i]);
    mean /= double(inside.size());
    batch_means.push_back(luminance(mean));
    // Indexed by the position in `inside`.
    pix_sum.resize(inside.size(), 0.0);
    pix_sq.resize(inside.size(), 0.0);
    for (std::size_t k = 0; k < inside.size(); ++k) {
      const double y = luminance(glm::dvec3(pixels[inside[k]]));
      pix_sum[k] += y;
      pix_sq[k] += y * y;
    }
    // Running mean of the batches on the host, weighted by their sample counts; pixels
    // outside the window stay RGBA 0, alpha 0 marking them not traced.
    if (r.image.pixels.empty()) r.image = core::Image(view.width(), view.height(), glm::vec4(0));
    const double w = double(c.spp) / double(r.spp + c.spp);
    for (std::size_t i : inside) {
      glm::vec4& acc = r.image.pixels[i];
      acc = glm::vec4(glm::mix(glm::dvec3(acc), glm::dvec3(pixels[i]), w), 1.0f);
    }
    r.spp += c.spp;
    ++batches;
    const std::size_t B = batch_means.size();
    r.rel_error = r.pixel_rel_error = std::numeric_limits<double>::quiet_NaN();
    if (B >= 2) {
      double m = 0, v = 0;
      for (double x : batch_means) m += x;
      m /= double(B);
      for (double x : batch_means) v += (x - m) * (x - m);
      v /= double(B - 1);
      r.rel_error = m > 0 ? std::sqrt(v / double(B)) / m : 0.0;
      // Per pixel the squared standard error of its mean relative to its value (the relMSE
      // form of core/metrics, ε = 0.01 keeps dark pixels finite); batches differ in size only
      // in the last one, where the unweighted variance errs on the unconverged side.
      double rel2 = 0;
      for (std::size_t k = 0; k < pix_sum.size(); ++k) {
        const double pm = pix_sum[k] / double(B);
        const double se2 = std::max(0.0, pix_sq[k] / double(B) - pm * pm) / double(B - 1);
        const double acc = luminance(glm::dvec3(r.image.pixels[inside[k]]));
        rel2 += se2 / (acc * acc + kPixelEpsilon);
      }
      r.pixel_rel_error = std::sqrt(rel2 / double(std::max<std::size_t>(pix_sum.size(), 1)));
    }
    r.seconds = double(core::now_ns() - t0) * 1e-9;
    if (progress) progress({r.spp, r.rel_error, r.pixel_rel_error, r.seconds});
    if (B >= 4 && ((o.until_rel_error > 0 && r.rel_error <= o.until_rel_error) ||
                   (o.until_pixel_rel_error > 0 && r.pixel_rel_error <= o.until_pixel_rel_error)))
      break;
  }
  glm::dvec3 mean(0);
  for (std::size_t i : inside) mean += glm::dvec3(r.image.pixels[i]);
  r.mean_rgb = mean / double(inside.size());
  // One batch has no spread to estimate from: the errors stay NaN (unknown), never a 0 that
  // reads as converged.
  return r;
}

void write_exr(const std::string& path, const core::Image& img) {
  std::vector<float> data(img.pixels.size() * 4);
  for (std::size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 4; ++c) {
      const float v = img.pixels[i][c];
      data[4 * i + c] = std::isfinite(v) ? v : 0.0f;
    }
  const std::string tmp = path + ".tmp." + std::to_string(::getpid()) + ".exr";
  const char* err = nullptr;
  if (SaveEXR(data.data(), img.width, img.height, 4, 0, tmp.c_str(), &err) != TINYEXR_SUCCESS) {
    const std::string msg = err ? err : "unknown error";
    if (err) FreeEXRErrorMessage(err);
    std::filesystem::remove(tmp);
    throw std::runtime_error("cannot write " + path + ": " + msg);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw std::runtime_error("cannot write " + path + ": " + ec.message());
  }
}

core::Image read_exr(const std::string& path) {
  float* rgba = nullptr;
  int w = 0, h = 0;
  const char* err = nullptr;
  if (LoadEXR(&rgba, &w, &h, path.c_str(), &err) != TINYEXR_SUCCESS) {
    const std::string msg = err ? err : "unknown error";
    if (err) FreeEXRErrorMessage(err);
    throw core::InputError(path + ": cannot read as OpenEXR (" + msg + ")");
  }
  core::Image img(w, h);
  bool finite = true;
  for (std::size_t i = 0; i < img.pixels.size(); ++i) {
    img.pixels[i] = {rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2], rgba[4 * i + 3]};
    for (int c = 0; c < 4; ++c) finite = finite && std::isfinite(rgba[4 * i + c]);
  }
  std::free(rgba);
  if (!finite) throw core::InputError(path + ": holds non-finite pixel values");
  return img;
}

core::Image tone_map(const core::Image& linear) {
  core::Image out = core::tonemap_linear(linear);
  for (auto& p : out.pixels) p.w = 1.0f;
  return out;
}

}  // namespace fovea::renderer

#include "fovea/renderer/reference.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include <tinyexr.h>

#include "fovea/core/error.hpp"
#include "fovea/core/tonemap.hpp"

namespace fovea::renderer {

namespace {
double luminance(glm::dvec3 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }
constexpr double kPixelEpsilon = 0.01;  // core::kRelMseEpsilon
}  // namespace

ReferenceResult render_reference(gpu::Context& ctx, const GpuScene& scene, const core::View& view, core::Eye eye,
                                 const ReferenceOptions& o, const std::function<void(const ReferenceProgress&)>& progress) {
  if (o.max_spp == 0) throw core::InputError("reference: --spp must be at least 1");
  if (!(o.until_rel_error >= 0) || !std::isfinite(o.until_rel_error))
    throw core::InputError("reference: --until-rel-error must be a finite number >= 0");
  if (!(o.until_pixel_rel_error >= 0) || !std::isfinite(o.until_pixel_rel_error))
    throw core::InputError("reference: the per-pixel relative error target must be a finite number >= 0");
  const auto t0 = std::chrono::steady_clock::now();
  const auto grid = cartesian_grid(view);
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
    for (const auto& p : pixels) mean += glm::dvec3(p);
    mean /= double(pixels.size());
    batch_means.push_back(luminance(mean));
    pix_sum.resize(pixels.size(), 0.0);
    pix_sq.resize(pixels.size(), 0.0);
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      const double y = luminance(glm::dvec3(pixels[i]));
      pix_sum[i] += y;
      pix_sq[i] += y * y;
    }
    // Running mean of the batches on the host, weighted by their sample counts.
    if (r.image.pixels.empty()) r.image = core::Image(view.width(), view.height());
    const double w = double(c.spp) / double(r.spp + c.spp);
    for (std::size_t i = 0; i < pixels.size(); ++i) {
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
      for (std::size_t i = 0; i < pix_sum.size(); ++i) {
        const double pm = pix_sum[i] / double(B);
        const double se2 = std::max(0.0, pix_sq[i] / double(B) - pm * pm) / double(B - 1);
        const double acc = luminance(glm::dvec3(r.image.pixels[i]));
        rel2 += se2 / (acc * acc + kPixelEpsilon);
      }
      r.pixel_rel_error = std::sqrt(rel2 / double(std::max<std::size_t>(pix_sum.size(), 1)));
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (progress) progress({r.spp, r.rel_error, r.pixel_rel_error, r.seconds});
    if (B >= 4 && ((o.until_rel_error > 0 && r.rel_error <= o.until_rel_error) ||
                   (o.until_pixel_rel_error > 0 && r.pixel_rel_error <= o.until_pixel_rel_error)))
      break;
  }
  glm::dvec3 mean(0);
  for (const auto& p : r.image.pixels) mean += glm::dvec3(p);
  r.mean_rgb = mean / double(r.image.pixels.size());
  // One batch: no spread to estimate from.
  if (std::isnan(r.rel_error)) r.rel_error = 0;
  if (std::isnan(r.pixel_rel_error)) r.pixel_rel_error = 0;
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

#include "fovea/compositor/distortion.hpp"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "fovea/core/display.hpp"
#include "gpu_fixture.hpp"

using namespace fovea;
using fovea::test::GpuTest;

namespace {

// A preset's optics at another raster size (the lens is defined in panel fractions).
core::DisplayPreset resized(const std::string& name, int w, int h) {
  const core::DisplayPreset d = core::load_display(name);
  std::string text = d.json;
  const auto swap = [&](const std::string& key, int v) {
    const auto at = text.find("\"" + key + "\"");
    const auto colon = text.find(':', at), end = text.find(',', colon);
    text.replace(colon + 1, end - colon - 1, " " + std::to_string(v));
  };
  swap("width", w);
  swap("height", h);
  return core::parse_display(text, name + "-resized");
}

// Linear test pattern: fine checks, per-channel gradients, a few saturated features.
core::Image pattern(int w, int h) {
  core::Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool check = ((x / 3) + (y / 3)) % 2 == 0;
      img.at(x, y) = {check ? 0.9f : 0.05f, float(x) / w, float(y) / h, 1.0f};
      if (x % 17 == 0) img.at(x, y) = {2.0f, 1.0f, 0.2f, 1.0f};  // HDR value, clamped on output
    }
  return img;
}

void expect_matches_reference(const compositor::PanelImage& gpu, const core::Image& cpu) {
  ASSERT_EQ(gpu.width, cpu.width);
  ASSERT_EQ(gpu.height, cpu.height);
  int worst = 0;
  double worst_diff = 0;
  for (size_t i = 0; i < cpu.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float ref = core::srgb_encode(cpu.pixels[i][c]);
      ASSERT_TRUE(std::isfinite(cpu.pixels[i][c]));
      const double diff = std::abs(gpu.rgba[i * 4 + c] / 255.0 - ref);
      if (diff > worst_diff) {
        worst_diff = diff;
        worst = int(i);
      }
    }
  EXPECT_LE(worst_diff, 1.0 / 255 + 1e-6) << "pixel " << worst % cpu.width << "," << worst / cpu.width;
}

}  // namespace

using Distortion = GpuTest;

TEST_F(Distortion, GpuMatchesCpuReferencePanotools) {
  const core::DisplayPreset d = core::load_display("small");
  for (core::Eye eye : {core::Eye::Left, core::Eye::Right}) {
    const core::HiddenAreaMask mask(core::Lens::for_eye(d, eye));
    const core::Image src = pattern(d.width, d.height);
    compositor::DistortionPass pass(ctx(), mask);
    expect_matches_reference(pass.run(src), compositor::distort_reference(mask, src));
  }
}

TEST_F(Distortion, GpuMatchesCpuReferenceVive) {
  const core::DisplayPreset d = resized("vive", 270, 300);
  const core::HiddenAreaMask mask(core::Lens::for_eye(d, core::Eye::Left));
  const core::Image src = pattern(d.width, d.height);
  compositor::DistortionPass pass(ctx(), mask);
  const compositor::PanelImage out = pass.run(src);
  expect_matches_reference(out, compositor::distort_reference(mask, src));
  // Hidden pixels are black, visible ones are not all black.
  size_t lit = 0;
  for (int y = 0; y < d.height; ++y)
    for (int x = 0; x < d.width; ++x) {
      const std::uint8_t* p = &out.rgba[(size_t(y) * d.width + x) * 4];
      if (mask.hidden(x, y)) {
        ASSERT_EQ(p[0] + p[1] + p[2], 0) << x << "," << y;
      } else {
        lit += p[0] + p[1] + p[2] > 0;
      }
    }
  EXPECT_GT(lit, size_t(d.width * d.height / 2));
}

TEST_F(Distortion, SingleChannelOptics) {
  const core::DisplayPreset d = core::load_display("tiny");
  const core::HiddenAreaMask mask(core::Lens::for_eye(d, core::Eye::Left));
  const core::Image src = pattern(d.width, d.height);
  compositor::DistortionPass pass(ctx(), mask, compositor::ChannelSelect::Blue);
  expect_matches_reference(pass.run(src), compositor::distort_reference(mask, src, compositor::ChannelSelect::Blue));
}

TEST_F(Distortion, NonFiniteInputAndExtremeLensNeverGiveNaN) {
  // Non-monotonic optics (clamped with a note) and NaN / Inf texels in the view image.
  const core::DisplayPreset d = core::parse_display(
      R"({"name":"wild","width":96,"height":80,"fov_deg":{"left":-50,"right":50,"up":45,"down":-45},
          "lens":{"model":"panotools","k":[1,0,-1,0,0],"aberration":[0.9,1,1.1],"centre":[0.5,0.5],"scale":0.5}})",
      "wild");
  const core::Lens lens = core::Lens::for_eye(d, core::Eye::Left);
  ASSERT_FALSE(lens.notes().empty());
  const core::HiddenAreaMask mask(lens);
  core::Image src = pattern(d.width, d.height);
  for (int i = 0; i < 200; ++i)
    src.pixels[size_t(i) * 37 % src.pixels.size()] = i % 2 ? glm::vec4(std::nanf(""), 1, 1, 1)
                                                            : glm::vec4(INFINITY, -INFINITY, 1e38f, 1);
  compositor::DistortionPass pass(ctx(), mask);
  const compositor::PanelImage gpu = pass.run(src);
  const core::Image cpu = compositor::distort_reference(mask, src);
  expect_matches_reference(gpu, cpu);
}

TEST(DistortionReference, ChromaticAberrationSeparatesTheChannelsAtTheEdge) {
  // A white vertical line near the right edge of the view: each channel shows it where
  // that channel's inverse optics put it; red lands outermost, blue innermost (ab_r < ab_b).
  // The line is a Gaussian (σ = 2 px) so pixel-sampled centroids are unbiased.
  const core::DisplayPreset d = resized("fove0", 640, 720);
  const core::Lens lens = core::Lens::for_eye(d, core::Eye::Left);
  const core::HiddenAreaMask mask(lens);
  const int W = d.width, H = d.height, column = int(0.93 * W);
  core::Image src(W, H, {0, 0, 0, 1});
  for (int y = 0; y < H; ++y)
    for (int x = column - 10; x <= column + 10; ++x) {
      const float v = float(std::exp(-0.125 * (x - column) * (x - column)));
      src.at(x, y) = {v, v, v, 1};
    }
  const core::Image out = compositor::distort_reference(mask, src);
  const int row = H / 2;
  const glm::dvec2 line_uv((column + 0.5) / W, (row + 0.5) / double(H));
  double position[3];
  for (int c = 0; c < 3; ++c) {
    const auto uv = lens.inverse(c, lens.uv_to_tangent(line_uv));
    ASSERT_TRUE(uv.has_value());
    const double expect = uv->x * W;
    ASSERT_FALSE(mask.hidden_at({expect, row + 0.5}));
    double sum = 0, moment = 0;
    for (int x = int(expect) - 14; x <= int(expect) + 14; ++x) {
      const double v = out.at(x, row)[c];
      sum += v;
      moment += v * (x + 0.5);
    }
    ASSERT_GT(sum, 2.0) << c;
    position[c] = moment / sum;
    EXPECT_NEAR(position[c], expect, 0.1) << "channel " << c;
  }
  // Expected separation to first order: the source offset x_s from the lens centre is shown
  // at display radius r with g(r)·ab_c = x_s, so r_r − r_b ≈ (x_s/g'(r))·(1/ab_r − 1/ab_b).
  const core::Lens::Channel& g = lens.channel(1);
  const double r = (position[1] / W - g.display_centre.x) * g.to_radial.x;
  const double xs = lens.radial(1, r) * 1.008;  // green's aberration scale
  const double sep_radial = xs / lens.radial_derivative(1, r) * (1 / 0.999 - 1 / 1.018);
  const double sep_px = sep_radial / g.to_radial.x * W;
  EXPECT_GT(position[0], position[1]);
  EXPECT_GT(position[1], position[2]);
  EXPECT_NEAR(position[0] - position[2], sep_px, 0.05 * sep_px);
  EXPECT_GT(position[0] - position[2], 2.0);  // visible colour fringes at the edge
}

// The LUT cache on the GPU reads the same nodes and interpolates as LensLut does.
TEST_F(Distortion, LutCacheMatchesCpuReferenceWithTheSameCache) {
  const core::DisplayPreset d = core::load_display("small");
  const core::HiddenAreaMask mask(core::Lens::for_eye(d, core::Eye::Right));
  const core::Image src = pattern(d.width, d.height);
  compositor::DistortionPass pass(ctx(), mask, compositor::ChannelSelect::All, compositor::OpticsEval::Lut);
  const core::LensLut lut(mask.lens());
  expect_matches_reference(pass.run(src),
                           compositor::distort_reference(mask, src, compositor::ChannelSelect::All, &lut));
}

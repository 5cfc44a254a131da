// A wide, canted display (the `wide` preset's field at a test resolution): each eye turned
// 20° outwards, 75° towards the temple. Both eyes render finite images of their own halves
// of a 190° field, stereo sharing on, the lens' hidden area culled, the traced cells at the
// centred gaze's count wherever the gaze goes (docs/visual-polar.md).
#include <cmath>

#include "fovea/core/eye_optics.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

namespace {

// The shipped preset's field, lens and cant on a 160×93 raster.
core::DisplayPreset small_wide() {
  core::DisplayPreset d = core::load_display("wide");
  std::string json = d.json;
  const auto swap = [&json](const std::string& from, const std::string& to) {
    const auto at = json.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    json.replace(at, from.size(), to);
  };
  swap("\"width\": 2560", "\"width\": 160");
  swap("\"height\": 1488", "\"height\": 93");
  return core::parse_display(json, "wide at 160x93");
}

}  // namespace

TEST_F(GpuTest, CantedWideDisplayRendersBothHalvesOfItsField) {
  const core::DisplayPreset display = small_wide();
  ASSERT_EQ(display.width, 160);
  ASSERT_DOUBLE_EQ(display.cant_deg, 20.0);
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx(), scene);
  reconstruct::ReconSettings s;  // defaults: BMFR, stereo sharing
  core::DistributionParams dp;
  dp.kind = core::DistributionKind::LogPolar;  // the budget holds for it on this field (VP: see the doc)
  pipeline::FramePipeline p(ctx(), gs, core::stereo_views(display), dp, s);
  for (core::Eye e : {core::Eye::Left, core::Eye::Right}) p.set_visibility(e, core::EyeOptics(display, e).view_mask());
  const auto poses = core::eye_poses(scene.camera, display);
  std::int64_t first = 0;
  const glm::dvec3 ahead(0, 0, -1), temple_l = glm::normalize(glm::dvec3(-0.5, 0.1, -1)),
                   temple_r = glm::normalize(glm::dvec3(0.5, 0.1, -1));
  for (std::uint32_t f = 0; f < 4; ++f) {
    const bool off = f >= 2;
    p.render(poses, {off ? temple_l : ahead, off ? temple_r : ahead}, f);
    const std::int64_t traced = p.traced_cells(core::Eye::Left);
    if (f == 0) first = traced;
    EXPECT_NEAR(double(traced) / double(first), 1.0, 0.05) << "frame " << f;
    for (core::Eye e : {core::Eye::Left, core::Eye::Right}) {
      const core::Image img = p.image(e);
      double sum = 0;
      bool finite = true;
      for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
          const glm::vec4 c = img.at(x, y);
          finite = finite && std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z);
          sum += c.x + c.y + c.z;
        }
      EXPECT_TRUE(finite) << "frame " << f << " eye " << core::eye_name(e);
      EXPECT_GT(sum, 0) << "frame " << f << " eye " << core::eye_name(e);
    }
  }
  // The eyes look 40° apart: in the head's frame the left eye's forward points left.
  const glm::dquat head = glm::conjugate(scene.camera.orientation);
  const glm::dvec3 l = head * (p.view(core::Eye::Left).pose().orientation * glm::dvec3(0, 0, -1));
  const glm::dvec3 r = head * (p.view(core::Eye::Right).pose().orientation * glm::dvec3(0, 0, -1));
  EXPECT_NEAR(std::acos(glm::dot(l, r)) * 180 / 3.14159265358979323846, 40.0, 1e-6);
  EXPECT_LT(l.x, 0);
  EXPECT_GT(r.x, 0);
}

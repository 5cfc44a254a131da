// GridMapping::unmoved: a frame's mapping counts as the previous one's (each cell's history
// in the cell itself, taken by Phase I without reprojecting) only when nothing but the
// cells' jitter changed: the same gaze, eye pose and column table. A first frame and any
// move of the gaze or the eye count as moved, for polar and Cartesian grids.
#include "fovea/reconstruct/grid_map.hpp"

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include "fovea/core/display.hpp"
#include "gpu_fixture.hpp"

namespace core = fovea::core;
namespace reconstruct = fovea::reconstruct;
using fovea::test::GpuTest;

TEST_F(GpuTest, GridMappingIsUnmovedOnlyWhenJustTheJitterChanged) {
  const core::View v = core::load_display("tiny").view(core::Eye::Left);
  const glm::dvec3 centre = v.centre_dir();
  const glm::dvec3 aside = v.pixel_to_dir({0.55 * v.width(), 0.5 * v.height()});
  core::Pose turned;
  turned.orientation = glm::angleAxis(glm::radians(0.01), glm::dvec3(0, 1, 0));
  for (const auto kind : {core::DistributionKind::VisualPolar, core::DistributionKind::LogPolar,
                          core::DistributionKind::Cartesian, core::DistributionKind::CartesianUniform}) {
    SCOPED_TRACE(core::distribution_name(kind));
    core::DistributionParams p;
    p.kind = kind;
    auto d = core::make_distribution(v, p);
    reconstruct::GridMapping m(ctx(), *d, nullptr);
    std::uint32_t frame = 0;
    // The next frame at `gaze` from `pose`: whether its mapping is the one written before.
    const auto next = [&](glm::dvec3 gaze, const core::Pose& pose) {
      d->set_frame(gaze, frame++);
      m.write(pose, nullptr);
      return m.unmoved();
    };
    const core::Pose still;
    EXPECT_FALSE(next(centre, still)) << "a first frame has no previous mapping";
    const glm::dvec2 jitter0 = d->jitter();
    m.advance(still);
    EXPECT_TRUE(next(centre, still)) << "the same gaze and pose, another jitter";
    EXPECT_NE(d->jitter(), jitter0) << "the test needs frames with other jitters";
    m.advance(still);
    EXPECT_FALSE(next(aside, still)) << "the gaze moved";
    m.advance(still);
    EXPECT_FALSE(next(aside, turned)) << "the eye turned by 0.01 degrees";
    m.advance(turned);
    EXPECT_TRUE(next(aside, turned)) << "still again";
  }
}

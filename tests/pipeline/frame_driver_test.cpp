// The frame driver every entry point sets its frames up with (pipeline/frame_driver.hpp): the
// display's views with the head at the scene's camera and the lens hidden area culled, or the
// views it is given with the hidden area it is given culled; the frame configuration reaches
// the pipeline; each frame's step reads the gaze and records the frame's times.
#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <glm/gtc/quaternion.hpp>

#include "fovea/core/density_report.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/pipeline/frame_driver.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"

namespace pipeline = fovea::pipeline;
namespace core = fovea::core;
namespace devices = fovea::devices;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

namespace {
double pose_distance(const core::Pose& a, const core::Pose& b) {
  return glm::length(a.position - b.position) + glm::length(a.orientation - b.orientation);
}

// The frame defaults, with `budget` where given, on the compute traversal (no start-up measurement).
pipeline::FrameConfig compute_frame(std::optional<double> budget = std::nullopt) {
  pipeline::FrameConfig frame;
  if (budget) frame.distribution.budget = *budget;
  frame.tracing = renderer::Tracing::Compute;
  pipeline::finish(frame, budget.has_value());
  return frame;
}
// A frame option's value refused: an InputError that names where it came from and what the
// option takes.
void expect_refused(pipeline::FrameConfig& c, const std::string& name, const std::string& value,
                    const std::string& where, const std::string& expected) {
  try {
    pipeline::apply_frame_option(c, name, value, where);
    ADD_FAILURE() << name << " " << value;
  } catch (const fovea::core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(where + ": " + expected), std::string::npos) << e.what();
  }
}
}  // namespace

TEST_F(GpuTest, FrameDriverSetsUpEveryEntryPointAlike) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  const core::DisplayPreset display = core::load_display("tiny");
  const pipeline::FrameConfig frame = compute_frame(0.2);

  // The command-line tools: the preset's views at the scene's camera, the lens hidden area culled.
  pipeline::FrameDriver tools(ctx(), scene, display, {frame, true, false});
  EXPECT_EQ(tools.trace_choice().tracing, renderer::Tracing::Compute);
  EXPECT_EQ(tools.pipeline().distribution(core::Eye::Left).params().budget, 0.2);
  const auto expected = core::eye_poses(scene.camera, display);
  for (std::size_t e = 0; e < 2; ++e) EXPECT_LT(pose_distance(tools.static_poses()[e], expected[e]), 1e-12);
  const std::array<glm::dvec3, 2> gaze{glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)};
  tools.pipeline().render(tools.static_poses(), gaze, 0);
  EXPECT_GT(tools.pipeline().hidden_cells(core::Eye::Left), 0);
  EXPECT_GT(tools.pipeline().hidden_cells(core::Eye::Right), 0);

  pipeline::FrameDriver uncut(ctx(), scene, display, {frame, false, false});
  uncut.pipeline().render(uncut.static_poses(), gaze, 0);
  EXPECT_EQ(uncut.pipeline().hidden_cells(core::Eye::Left), 0);

  // The layer: the application's views, its eye poses in the reference space placed at the
  // scene's camera; nothing culled without the runtime's hidden area.
  const core::StereoViews views = core::stereo_views(display);
  pipeline::FrameDriver layer(ctx(), scene, views, {frame, true, false});
  const core::Pose identity{};
  EXPECT_LT(pose_distance(layer.at_camera(identity), scene.camera), 1e-12);
  const auto app = views.poses();  // the head at the reference space's origin
  for (std::size_t e = 0; e < 2; ++e)
    EXPECT_LT(pose_distance(layer.at_camera(app[e]), expected[e]), 1e-9) << "eye " << e;
  layer.pipeline().render({layer.at_camera(app[0]), layer.at_camera(app[1])}, gaze, 0);
  EXPECT_EQ(layer.pipeline().hidden_cells(core::Eye::Left), 0);
  EXPECT_EQ(layer.pipeline().distribution(core::Eye::Left).params().budget, 0.2);
}

// The layer fetches the runtime's hidden area before its frame driver exists and gives it to
// the given views' driver: each eye's Visual-Polar grid is laid out for the pixels the mask
// leaves and traces the budget there with its cells as laid out (row scale 1). A mask set
// after the grid was laid out is culled too, the budget kept by cutting the periphery's rows
// (row scale 0.35 on `small`); given to the driver later, it lays the grids out again.
TEST_F(GpuTest, FrameDriverLaysGivenViewsOutForTheMaskItIsGiven) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  const core::DisplayPreset display = core::load_display("small");
  const pipeline::FrameConfig frame = compute_frame();
  const core::StereoViews views = core::stereo_views(display);
  pipeline::EyeMasks masks;
  for (core::Eye e : {core::Eye::Left, core::Eye::Right}) masks[std::size_t(e)] = core::EyeOptics(display, e).view_mask();
  pipeline::FrameDriver given(ctx(), scene, views, {frame, true, false}, masks);
  pipeline::FrameDriver late(ctx(), scene, views, {frame, true, false});
  late.enable_depth_output();  // as the layer's for depth compositing: every pipeline it makes writes depth
  for (core::Eye e : {core::Eye::Left, core::Eye::Right}) late.pipeline().set_visibility(e, *masks[std::size_t(e)]);
  const auto head = views.poses();
  const std::array<glm::dvec3, 2> gaze{glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)};
  for (pipeline::FrameDriver* d : {&given, &late})
    d->pipeline().render({d->at_camera(head[0]), d->at_camera(head[1])}, gaze, 0);
  for (core::Eye e : {core::Eye::Left, core::Eye::Right}) {
    SCOPED_TRACE(core::eye_name(e));
    const double budget = frame.distribution.budget * display.width * display.height *
                          (1 - masks[std::size_t(e)]->hidden_fraction());
    for (pipeline::FrameDriver* d : {&given, &late}) {
      EXPECT_GT(d->pipeline().hidden_cells(e), 0);
      EXPECT_NEAR(double(d->pipeline().traced_cells(e)) / budget, 1.0, 0.02);
    }
    EXPECT_EQ(core::visual_polar_state(given.pipeline().distribution(e))->row_scale, 1.0);
    EXPECT_LT(core::visual_polar_state(late.pipeline().distribution(e))->row_scale, 0.9);
  }
  // A hidden area given to the driver later (the runtime's change event) lays the grids out
  // again: a new pipeline, as if it had been given first.
  late.set_visibility(masks);
  late.pipeline().render({late.at_camera(head[0]), late.at_camera(head[1])}, gaze, 1);
  for (core::Eye e : {core::Eye::Left, core::Eye::Right}) {
    EXPECT_EQ(late.pipeline().traced_cells(e), given.pipeline().traced_cells(e)) << core::eye_name(e);
    EXPECT_EQ(late.pipeline().hidden_cells(e), given.pipeline().hidden_cells(e)) << core::eye_name(e);
    EXPECT_EQ(core::visual_polar_state(late.pipeline().distribution(e))->row_scale, 1.0) << core::eye_name(e);
    const std::vector<float> depth = late.pipeline().depth(e);
    EXPECT_TRUE(std::any_of(depth.begin(), depth.end(), [](float d) { return d > 0; })) << core::eye_name(e);
    EXPECT_THROW((void)given.pipeline().depth(e), core::InputError) << core::eye_name(e);
  }
}

// Each frame is one step: the gaze read at the frame's time on the display's timeline (as a
// source of its own reads it), the pipeline's frame with it, and its times by the names every
// timing record uses.
TEST_F(GpuTest, FrameDriverStepReadsTheGazeAtTheFrameTimeAndRecordsItsTimes) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  const core::DisplayPreset display = core::load_display("tiny");
  const pipeline::FrameConfig frame = compute_frame();
  pipeline::FrameDriver driver(ctx(), scene, display, {frame, true, false});
  EXPECT_THROW(driver.step(0), std::logic_error);  // no gaze source yet
  devices::SourceOptions so;
  so.display = display;
  driver.set_gaze(std::make_unique<devices::FoveationGaze>("synthetic:7", so));
  devices::FoveationGaze twin("synthetic:7", so);
  for (std::uint32_t f = 0; f < 3; ++f) {
    const pipeline::DrivenFrame d = driver.step(f);
    EXPECT_EQ(d.index, f);
    EXPECT_EQ(d.frame_ns, std::llround(f / display.refresh_hz * 1e9));
    const devices::FoveaGaze g = twin.at_frame_time(d.frame_ns);
    for (core::Eye e : {core::Eye::Left, core::Eye::Right}) {
      EXPECT_EQ(d.gaze.eye(e).dir, g.eye(e).dir) << "frame " << f;
      // The grid used that gaze (in the view, no fixational hold between these frames' jumps
      // or the same direction again).
      EXPECT_GT(glm::dot(glm::normalize(d.times.gaze[std::size_t(e)].used), glm::normalize(g.eye(e).dir)),
                std::cos(glm::radians(0.5)))
          << "frame " << f;
    }
    std::vector<std::string> gpu, cpu;
    for (const auto& [name, v] : d.gpu_ms()) {
      gpu.push_back(name);
      EXPECT_TRUE(std::isfinite(v) && v >= 0) << name;
    }
    for (const auto& [name, v] : d.cpu_ms()) {
      cpu.push_back(name);
      EXPECT_TRUE(std::isfinite(v) && v >= 0) << name;
    }
    EXPECT_EQ(gpu, (std::vector<std::string>{"grid", "trace", "reconstruct", "resolve", "pixel_albedo", "accumulate",
                                             "bmfr_fit", "post",
                                             "mip", "resample", "blur", "total"}));
    EXPECT_EQ(cpu, (std::vector<std::string>{"gaze", "grid", "trace", "reconstruct", "resolve", "submit", "wait", "total"}));
    EXPECT_DOUBLE_EQ(d.gpu_ms().back().second, d.times.gpu_ms());
    EXPECT_DOUBLE_EQ(d.cpu_ms().back().second, d.gaze_cpu_ms + d.times.cpu_ms());
    EXPECT_GT(d.times.gpu_ms(), 0);
  }
  // A gaze read elsewhere (the layer, the latency harness): used as given, at the given poses.
  devices::FoveaGaze given;
  given.left.dir = given.right.dir = given.combined.dir = glm::normalize(glm::dvec3(0.1, 0.05, -1));
  const pipeline::DrivenFrame d = driver.step(9, given, driver.static_poses(), 0.25);
  EXPECT_LT(glm::length(d.times.gaze[0].used - given.left.dir), 1e-9);
  EXPECT_EQ(d.cpu_ms().front(), (std::pair<std::string, double>{"gaze", 0.25}));
  // A driver of given views has no frame timeline to read a source on.
  pipeline::FrameDriver layer(ctx(), scene, core::stereo_views(display), {frame, true, false});
  EXPECT_THROW(layer.set_gaze(std::make_unique<devices::FoveationGaze>("synthetic:7", so)), std::logic_error);
}

// --seed changes the noise and nothing else: the same seed renders the same bits, another seed
// another realisation of the same frames (the same grid, the same mean).
TEST_F(GpuTest, SeedChangesOnlyTheNoise) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  const core::DisplayPreset display = core::load_display("tiny");
  const auto render = [&](std::uint32_t seed) {
    pipeline::FrameConfig frame;
    frame.tracing = renderer::Tracing::Compute;
    pipeline::apply_frame_option(frame, "seed", std::to_string(seed), "--seed");
    pipeline::finish(frame, false);
    EXPECT_EQ(pipeline::to_json(frame)["seed"], seed);
    pipeline::FrameDriver driver(ctx(), scene, display, {frame, true, false});
    devices::FoveaGaze g;
    g.left.dir = g.right.dir = g.combined.dir = glm::normalize(glm::dvec3(0.05, 0.02, -1));
    std::pair<core::Image, glm::dvec3> out;
    for (std::uint32_t f = 0; f < 3; ++f) out.second = driver.step(f, g, driver.static_poses()).times.gaze[0].used;
    out.first = driver.pipeline().image(core::Eye::Left);
    return out;
  };
  const auto mean = [](const core::Image& im) {
    double m = 0;
    for (const auto& p : im.pixels) m += double(p.x + p.y + p.z);
    return m / double(im.pixels.size());
  };
  const auto a = render(0), again = render(0), b = render(7);
  EXPECT_EQ(a.first.pixels, again.first.pixels);
  EXPECT_NE(a.first.pixels, b.first.pixels);
  EXPECT_EQ(a.second, b.second);  // the grid followed the same gaze
  EXPECT_NEAR(mean(b.first), mean(a.first), 0.05 * mean(a.first));
  pipeline::FrameConfig bad;
  EXPECT_THROW(pipeline::apply_frame_option(bad, "seed", "-1", "--seed"), fovea::core::InputError);
  EXPECT_THROW(pipeline::apply_frame_option(bad, "seed", "1000001", "--seed"), fovea::core::InputError);
}

// --landing-spp sets the new fovea's samples per cell after a gaze jump, 1..8, by the same name
// everywhere (command line, the layer's file, reports); anything else is refused naming it.
TEST(FrameOptions, LandingSamplesAreAWholeNumberFromOneToEight) {
  pipeline::FrameConfig c;
  EXPECT_EQ(c.recon.landing_spp, 8u);
  EXPECT_EQ(pipeline::to_json(c)["landing-spp"], 8);
  pipeline::apply_frame_option(c, "landing-spp", "1", "--landing-spp");
  EXPECT_EQ(c.recon.landing_spp, 1u);
  EXPECT_EQ(pipeline::to_json(c)["landing-spp"], 1);
  for (const char* bad : {"0", "9", "-1", "4.5", "", "four", "99999999999999999999"})
    expect_refused(c, "landing-spp", bad, "layer.json: default.landing-spp", "expected a whole number in 1..8");
  EXPECT_EQ(c.recon.landing_spp, 1u);  // a refused value changes nothing
}

// --pixel-albedo (the display pixels' own albedo in the fovea; default on) and --lattice-blur
// (the B-spline over cells several pixels wide; default on) are on or off by the same
// name everywhere; anything else is refused naming where it came from and changes nothing.
TEST(FrameOptions, OnOffOptionsTakeOnlyOnOrOff) {
  struct Case {
    const char* name;
    bool on_by_default;
    bool (*is_on)(const pipeline::FrameConfig&);
  };
  const Case cases[] = {
      {"pixel-albedo", true, [](const pipeline::FrameConfig& c) { return c.recon.pixel_albedo; }},
      {"lattice-blur", true, [](const pipeline::FrameConfig& c) { return c.recon.lattice_blur; }},
  };
  for (const Case& k : cases) {
    pipeline::FrameConfig c;
    EXPECT_EQ(k.is_on(c), k.on_by_default) << k.name;
    EXPECT_EQ(pipeline::to_json(c)[k.name], k.on_by_default ? "on" : "off") << k.name;
    const char* flipped = k.on_by_default ? "off" : "on";
    pipeline::apply_frame_option(c, k.name, flipped, std::string("--") + k.name);
    EXPECT_EQ(k.is_on(c), !k.on_by_default) << k.name;
    EXPECT_EQ(pipeline::to_json(c)[k.name], flipped) << k.name;
    const std::string where = std::string("layer.json: default.") + k.name;
    for (const char* bad : {"", "true", "1", "ON"}) expect_refused(c, k.name, bad, where, "expected on or off");
    EXPECT_EQ(k.is_on(c), !k.on_by_default) << k.name;  // a refused value changes nothing
  }
}

// --raster-filter is box (the default) or gaussian by the same name everywhere; anything else
// is refused naming where it came from, and gaussian only for cartesian, whose cells are the
// display's pixels.
TEST(FrameOptions, RasterFilterIsBoxOrGaussianForCartesianOnly) {
  pipeline::FrameConfig c;
  EXPECT_FALSE(c.recon.raster_gaussian);
  EXPECT_EQ(pipeline::to_json(c)["raster-filter"], "box");
  for (const char* bad : {"", "on", "Gaussian", "tent"})
    expect_refused(c, "raster-filter", bad, "layer.json: default.raster-filter", "expected box or gaussian");
  pipeline::apply_frame_option(c, "raster-filter", "gaussian", "--raster-filter");
  EXPECT_EQ(pipeline::to_json(c)["raster-filter"], "gaussian");
  try {
    pipeline::finish(c, false);  // the default distribution, visual-polar
    ADD_FAILURE() << "gaussian accepted for visual-polar";
  } catch (const fovea::core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("raster-filter: only cartesian"), std::string::npos) << e.what();
  }
  pipeline::apply_frame_option(c, "distribution", "cartesian", "--distribution");
  pipeline::finish(c, false);
  EXPECT_TRUE(c.recon.raster_gaussian);
}

// --cap sets Visual-Polar's samples per display pixel at most (κ) by the same name everywhere;
// the grid then puts that many in the fovea. A cap outside (0, 16] or not a number is refused
// naming where it came from.
TEST(FrameOptions, CapSetsTheFoveaSamplesPerPixel) {
  pipeline::FrameConfig c;
  EXPECT_EQ(pipeline::to_json(c)["cap"], c.distribution.cap);
  pipeline::apply_frame_option(c, "cap", "2", "--cap");
  pipeline::finish(c, false);
  EXPECT_EQ(pipeline::to_json(c)["cap"], 2.0);
  const core::View view(core::Fov::from_degrees(-40, 40, 40, -40), 200, 200);
  const auto d = core::make_distribution(view, c.distribution);
  EXPECT_NEAR(core::measure_density(*d).fovea_spp, 2.0, 0.05);
  for (const char* bad : {"0", "-1", "16.5", "nan", "inf", "", "two"}) {
    pipeline::FrameConfig b;
    try {
      pipeline::apply_frame_option(b, "cap", bad, "layer.json: default.cap");
      pipeline::finish(b, false);
      ADD_FAILURE() << bad;
    } catch (const fovea::core::InputError& e) {
      const std::string what = e.what();
      EXPECT_TRUE(what.find("layer.json: default.cap: expected a finite number") != std::string::npos ||
                  what.find("cap: must be in (0, 16]") != std::string::npos)
          << bad << ": " << what;
    }
  }
  pipeline::FrameConfig other;  // the other distributions have no cap to set
  pipeline::apply_frame_option(other, "distribution", "log-polar", "--distribution");
  pipeline::apply_frame_option(other, "cap", "2", "--cap");
  EXPECT_THROW(pipeline::finish(other, false), fovea::core::InputError);
}

// A fixating eye's drift does not move the grid: within kGridHoldDeg (0.5°) of the gaze the
// grid was laid out for it stays there; a larger move, and the first frame after reset(),
// lay it out again at the gaze.
TEST_F(GpuTest, GridHoldsStillThroughAFixationalDrift) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = core::load_display("tiny");
  pipeline::FramePipeline p(ctx(), gs, core::stereo_views(display), {}, {}, {}, /*mono=*/true);
  const auto poses = core::eye_poses(scene.camera, display);
  const auto at = [](double yaw_deg) {
    const double a = glm::radians(yaw_deg);
    return glm::dvec3(std::sin(a), 0, -std::cos(a));
  };
  const auto used = [&](double yaw_deg, std::uint32_t f) {
    return p.render(poses, {at(yaw_deg), at(yaw_deg)}, f).gaze[0].used;
  };
  EXPECT_LT(glm::length(used(2.0, 0) - at(2.0)), 1e-9);
  EXPECT_LT(glm::length(used(2.3, 1) - at(2.0)), 1e-9) << "0.3°: held";
  EXPECT_LT(glm::length(used(1.6, 2) - at(2.0)), 1e-9) << "0.4° the other way: held";
  EXPECT_LT(glm::length(used(2.8, 3) - at(2.8)), 1e-9) << "0.8°: laid out again";
  EXPECT_LT(glm::length(used(3.1, 4) - at(2.8)), 1e-9) << "held at the new place";
  p.reset();
  EXPECT_LT(glm::length(used(3.1, 5) - at(3.1)), 1e-9) << "after reset";
}

// The layer's host-side parts without an OpenXR session: configuration, compositing, gaze.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "composite.hpp"
#include "config.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/clock.hpp"
#include "fovea/devices/hid_stream.hpp"
#include "frame_log.hpp"
#include "frame_queue.hpp"
#include "gaze_input.hpp"
#include "layer_queue.hpp"
#include "next_chain.hpp"
#include "traced_slots.hpp"

namespace fovea::layer {
namespace {

TEST(LayerConfig, ApplicationSectionOverridesDefault) {
  const std::string text = R"({"default": {"scene": "default", "composite": "alpha"},
                               "applications": {"HelloXR": {"scene": "cornell", "app_background": [1, 2, 3]}}})";
  const LayerConfig a = parse_config(text, "layer.json", "HelloXR");
  EXPECT_EQ(a.scene, "cornell");
  EXPECT_EQ(a.composite, Composite::Alpha);
  ASSERT_TRUE(a.app_background.has_value());
  EXPECT_EQ((*a.app_background)[2], 3);
  EXPECT_EQ(a.origin, "layer.json: applications.HelloXR");
  const LayerConfig b = parse_config(text, "layer.json", "Other");
  EXPECT_EQ(b.scene, "default");
  EXPECT_FALSE(b.app_background.has_value());
}

TEST(LayerConfig, ErrorsNameFileAndField) {
  const auto message = [](const std::string& text) {
    try {
      parse_config(text, "cfg.json", "App");
    } catch (const core::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("{").find("cfg.json"), std::string::npos);
  EXPECT_NE(message(R"({"default": {"composite": "over"}})").find("default.composite"), std::string::npos);
  EXPECT_NE(message(R"({"applications": {"App": {"app_background": [1, 2, 300]}}})").find("applications.App.app_background"),
            std::string::npos);
  EXPECT_NE(message(R"({"default": {"sceen": "x"}})").find("unknown key"), std::string::npos);
  EXPECT_NE(message(R"({"defaults": {}})").find("unknown key"), std::string::npos);
}

// Fuzz finding: 4294967297 used to wrap to 1 through get<int>().
TEST(LayerConfig, BackgroundComponentsAreRangeCheckedInSixtyFourBits) {
  for (const char* bad : {"[4294967297, 0, 0]", "[0, -4294967295, 0]", "[0, 0, 18446744073709551615]",
                          "[0, 0, 1.5]", "[0, 0, 1e400]"}) {
    const std::string text = std::string(R"({"default": {"app_background": )") + bad + "}}";
    try {
      parse_config(text, "cfg.json", "App");
      ADD_FAILURE() << bad << " accepted";
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cfg.json"), std::string::npos) << e.what();
    }
  }
  const auto c = parse_config(R"({"default": {"app_background": [0, 128, 255]}})", "cfg.json", "App");
  ASSERT_TRUE(c.app_background.has_value());
  EXPECT_EQ(*c.app_background, (std::array<int, 3>{0, 128, 255}));
}

Pixels8 filled(int w, int h, std::array<std::uint8_t, 4> c) {
  Pixels8 p{w, h, {}};
  for (int i = 0; i < w * h; ++i) p.data.insert(p.data.end(), c.begin(), c.end());
  return p;
}

TEST(LayerComposite, AppOnTopKeysTheBackground) {
  Pixels8 app = filled(8, 6, {47, 79, 79, 255});
  std::copy_n(std::array<std::uint8_t, 4>{0, 0, 255, 255}.data(), 4, app.at(3, 2));
  std::copy_n(std::array<std::uint8_t, 4>{48, 80, 79, 255}.data(), 4, app.at(5, 2));  // within tolerance
  const auto bg = border_colour(app);
  EXPECT_EQ(bg, (std::array<std::uint8_t, 3>{47, 79, 79}));
  Pixels8 scene = filled(8, 6, {200, 100, 50, 255});
  EXPECT_EQ(composite(scene, app, Composite::AppOnTop, bg, LayerBlend{}), 1);
  EXPECT_EQ(scene.at(3, 2)[2], 255);
  EXPECT_EQ(scene.at(5, 2)[0], 200);
  EXPECT_EQ(scene.at(0, 0)[0], 200);
  Pixels8 only = filled(8, 6, {200, 100, 50, 255});
  EXPECT_EQ(composite(only, app, Composite::SceneOnly, bg, LayerBlend{}), 0);
  EXPECT_EQ(only.data, filled(8, 6, {200, 100, 50, 255}).data);
}

// OpenXR layers are premultiplied unless XR_COMPOSITION_LAYER_UNPREMULTIPLIED_ALPHA_BIT is set.
TEST(LayerComposite, AlphaBlendsPremultipliedByDefault) {
  const XrCompositionLayerFlags flags = XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT;
  const LayerBlend blend = layer_blend(flags, pixel_format(VK_FORMAT_R8G8B8A8_UNORM));
  EXPECT_TRUE(blend.premultiplied);
  Pixels8 app = filled(2, 2, {0, 0, 0, 0});
  std::copy_n(std::array<std::uint8_t, 4>{255, 0, 0, 255}.data(), 4, app.at(0, 0));
  std::copy_n(std::array<std::uint8_t, 4>{128, 0, 0, 128}.data(), 4, app.at(1, 0));  // red at half coverage
  std::copy_n(std::array<std::uint8_t, 4>{0, 60, 0, 0}.data(), 4, app.at(1, 1));     // additive light
  Pixels8 scene = filled(2, 2, {0, 0, 200, 255});
  EXPECT_EQ(composite(scene, app, Composite::Alpha, {0, 0, 0}, blend), 3);
  EXPECT_EQ(scene.at(0, 0)[0], 255);
  EXPECT_EQ(scene.at(1, 0)[0], 128);  // not 128 * 128 / 255 as straight alpha would give
  EXPECT_EQ(scene.at(1, 0)[2], 100);
  EXPECT_EQ(scene.at(1, 1)[1], 60);
  EXPECT_EQ(scene.at(1, 1)[2], 200);
  EXPECT_EQ(scene.at(0, 1)[2], 200);
}

TEST(LayerComposite, AlphaBlendsStraightAlphaWhenUnpremultiplied) {
  const LayerBlend blend =
      layer_blend(XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT | XR_COMPOSITION_LAYER_UNPREMULTIPLIED_ALPHA_BIT,
                  pixel_format(VK_FORMAT_B8G8R8A8_UNORM));
  EXPECT_FALSE(blend.premultiplied);
  Pixels8 app = filled(2, 1, {255, 0, 0, 0});
  std::copy_n(std::array<std::uint8_t, 4>{255, 0, 0, 128}.data(), 4, app.at(1, 0));
  Pixels8 scene = filled(2, 1, {0, 0, 200, 255});
  EXPECT_EQ(composite(scene, app, Composite::Alpha, {0, 0, 0}, blend), 1);
  EXPECT_EQ(scene.at(0, 0)[0], 0);  // alpha 0: the scene
  EXPECT_EQ(scene.at(1, 0)[0], 128);
  EXPECT_EQ(scene.at(1, 0)[2], 100);
}

// Without XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT the layer is opaque.
TEST(LayerComposite, AlphaIgnoredWithoutSourceAlphaBit) {
  const LayerBlend blend = layer_blend(0, pixel_format(VK_FORMAT_R8G8B8A8_SRGB));
  EXPECT_FALSE(blend.source_alpha);
  Pixels8 app = filled(1, 1, {10, 20, 30, 0});
  Pixels8 scene = filled(1, 1, {0, 0, 200, 255});
  EXPECT_EQ(composite(scene, app, Composite::Alpha, {0, 0, 0}, blend), 1);
  EXPECT_EQ(scene.data, (std::vector<std::uint8_t>{10, 20, 30, 255}));
}

// sRGB swapchains blend in linear light: half coverage of white over black is linear 0.5,
// sRGB-encoded 188, not the 128 of blending the encoded bytes.
TEST(LayerComposite, AlphaBlendsInLinearLight) {
  const LayerBlend blend = layer_blend(XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT |
                                           XR_COMPOSITION_LAYER_UNPREMULTIPLIED_ALPHA_BIT,
                                       pixel_format(VK_FORMAT_R8G8B8A8_SRGB));
  Pixels8 app = filled(1, 1, {255, 255, 255, 128});
  Pixels8 scene = filled(1, 1, {0, 0, 0, 255});
  EXPECT_EQ(composite(scene, app, Composite::Alpha, {0, 0, 0}, blend), 1);
  const int expected = int(std::lround(core::srgb_encode(128.0f / 255.0f) * 255.0f));
  EXPECT_EQ(expected, 188);
  EXPECT_EQ(scene.at(0, 0)[0], expected);
  // A pixel over itself is unchanged whatever the coverage (no drift from re-encoding).
  Pixels8 same = filled(1, 1, {90, 140, 200, 255});
  const Pixels8 over = filled(1, 1, {90, 140, 200, 77});
  composite(same, over, Composite::Alpha, {0, 0, 0}, blend);
  EXPECT_EQ(same.data, (std::vector<std::uint8_t>{90, 140, 200, 255}));
}

TEST(LayerComposite, EncodesSceneForTheSwapchainFormat) {
  core::Image img(2, 1);
  img.at(0, 0) = {1.0f, 0.0f, 0.0f, 1.0f};  // the tone map keeps the hue of a pure primary
  img.at(1, 0) = {NAN, 0.0f, 0.0f, 1.0f};
  const Pixels8 rgba = encode_scene(img, pixel_format(VK_FORMAT_R8G8B8A8_SRGB));
  const Pixels8 bgra = encode_scene(img, pixel_format(VK_FORMAT_B8G8R8A8_UNORM));
  EXPECT_GT(rgba.at(0, 0)[0], 0);
  EXPECT_EQ(rgba.at(0, 0)[2], 0);
  EXPECT_EQ(bgra.at(0, 0)[0], 0);
  EXPECT_GT(bgra.at(0, 0)[2], 0);
  EXPECT_GT(rgba.at(0, 0)[0], bgra.at(0, 0)[2]);  // sRGB encoding brightens mid tones
  EXPECT_EQ(rgba.at(1, 0)[0], 0);                 // never NaN garbage
  EXPECT_EQ(rgba.at(1, 0)[3], 255);
  EXPECT_THROW(pixel_format(VK_FORMAT_D32_SFLOAT), std::runtime_error);
}

TEST(LayerComposite, ResamplesByDirection) {
  const core::Fov wide = core::Fov::from_degrees(-40, 40, 40, -40), narrow = core::Fov::from_degrees(-20, 20, 20, -20);
  Pixels8 app = filled(40, 40, {10, 10, 10, 255});
  std::copy_n(std::array<std::uint8_t, 4>{250, 0, 0, 255}.data(), 4, app.at(20, 20));
  const Pixels8 same = resample(app, core::View(wide, 40, 40), core::View(wide, 40, 40));
  EXPECT_EQ(same.data, app.data);
  // The narrow view sees the wide view's centre magnified, and nothing outside it is missing.
  const Pixels8 zoom = resample(app, core::View(wide, 40, 40), core::View(narrow, 40, 40));
  EXPECT_EQ(zoom.at(20, 20)[0], 250);
  EXPECT_EQ(zoom.at(0, 0)[3], 255);
  // The wide view seen from the narrow one: its border is not covered.
  const Pixels8 out = resample(app, core::View(narrow, 40, 40), core::View(wide, 40, 40));
  EXPECT_EQ(out.at(0, 0)[3], 0);
}

// Rotational reprojection of a path-traced frame to newer view poses: the head turned 10
// degrees left since the frame was traced, so what lay straight ahead now lies 10 degrees to
// the right (tangent projection: x = (tan 10 + tan 40) / (2 tan 40) * 80 = 48.4).
TEST(LayerComposite, ReprojectsByRotation) {
  const core::Fov wide = core::Fov::from_degrees(-40, 40, 40, -40);
  Pixels8 traced = filled(80, 80, {10, 10, 10, 255});
  std::copy_n(std::array<std::uint8_t, 4>{250, 0, 0, 255}.data(), 4, traced.at(40, 40));
  const glm::dquat now = glm::angleAxis(glm::radians(10.0), glm::dvec3(0, 1, 0));
  const glm::dquat then(1, 0, 0, 0);
  const Pixels8 out = resample(traced, core::View(wide, 80, 80), core::View(wide, 80, 80), glm::conjugate(then) * now);
  int found_x = -1, found_y = -1;
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 80; ++x)
      if (out.at(x, y)[0] == 250) found_x = x, found_y = y;
  EXPECT_EQ(found_x, 48);
  EXPECT_EQ(found_y, 40);
  // The left border now looks where the frame was not traced.
  EXPECT_EQ(out.at(0, 40)[3], 0);
  EXPECT_EQ(out.at(79, 40)[3], 255);
}

// A pipelined application: frame N+1 is waited before frame N ends. Each end gets its own
// frame's record (by predicted display time), a frame begun again is discarded, an end
// without a begin has no record.
TEST(LayerFrameQueue, PipelinedFramesKeepTheirOwnRecords) {
  FrameQueue q;
  EXPECT_FALSE(q.end(100).has_value());  // nothing begun
  q.waited(100, 1, 2);
  q.begun(3);
  q.waited(200, 4, 5);  // the next frame waited before the first ends
  const auto first = q.end(100);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->frame, 0);
  EXPECT_EQ(first->wait_call_ns, 1);
  EXPECT_EQ(first->begin_ns, 3);
  q.begun(6);
  q.waited(300, 7, 8);
  // An end naming no waited time ends the oldest begun frame.
  const auto second = q.end(12345);
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(second->frame, 1);
  EXPECT_EQ(second->display_time_ns, 200);
  EXPECT_EQ(second->begin_ns, 6);
  // Frame 2 begun, then frame 3 begun without ending 2: ending 3 drops 2.
  q.begun(9);
  q.waited(400, 10, 11);
  q.begun(12);
  const auto fourth = q.end(400);
  ASSERT_TRUE(fourth.has_value());
  EXPECT_EQ(fourth->frame, 3);
  EXPECT_EQ(q.in_flight(), 0u);
  // An application that waits without ever ending keeps a bounded queue.
  for (int i = 0; i < 100; ++i) q.waited(1000 + i, 0, 0);
  EXPECT_EQ(q.in_flight(), FrameQueue::kMaxInFlight);
}

// The traced-frame slots between the render thread and the application's thread: a slot is
// claimed once, comes back only when the application's thread releases it after its frame was
// retired, and a render thread waiting for one is woken by a release or by stop().
TEST(LayerSlotPool, SlotsComeBackOnlyWhenReleased) {
  EXPECT_THROW(SlotPool(0), std::invalid_argument);
  EXPECT_THROW(SlotPool(SlotPool::kMaxSlots + 1), std::invalid_argument);
  auto pool = std::make_shared<SlotPool>(3);
  const int a = pool->claim(), b = pool->claim(), c = pool->claim();
  EXPECT_EQ(std::vector<int>({a, b, c}), std::vector<int>({0, 1, 2}));
  EXPECT_EQ(pool->take_retired(), 0u);
  {
    SlotLease lease(pool, b);  // a frame in slot b, gone at the end of the scope
    EXPECT_EQ(lease.slot(), b);
  }
  EXPECT_EQ(pool->take_retired(), 1u << b);
  EXPECT_EQ(pool->take_retired(), 0u);  // taken once
  // No slot is free until the application's thread releases one: the render thread waits.
  int claimed = -2;
  std::thread render([&] { claimed = pool->claim(); });
  pool->release(b);
  render.join();
  EXPECT_EQ(claimed, b);
  std::thread stopped([&] { claimed = pool->claim(); });
  pool->stop();
  stopped.join();
  EXPECT_EQ(claimed, -1);
  pool->release(a);
  EXPECT_EQ(pool->claim(), -1) << "claims fail once stopped";
}

TEST(LayerConfig, RenderMode) {
  EXPECT_FALSE(parse_config(R"({"default": {"scene": "cornell"}})", "cfg.json", "App").lockstep);
  EXPECT_TRUE(parse_config(R"({"default": {"render": "lockstep"}})", "cfg.json", "App").lockstep);
  EXPECT_FALSE(parse_config(R"({"default": {"render": "lockstep"}, "applications": {"App": {"render": "async"}}})",
                            "cfg.json", "App")
                   .lockstep);
  try {
    parse_config(R"({"default": {"render": "sync"}})", "cfg.json", "App");
    FAIL() << "accepted";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cfg.json: default.render"), std::string::npos) << e.what();
  }
}

TEST(LayerConfig, Compositor) {
  EXPECT_TRUE(parse_config(R"({"default": {"scene": "cornell"}})", "cfg.json", "App").gpu_compositor);
  EXPECT_FALSE(parse_config(R"({"default": {"compositor": "host"}})", "cfg.json", "App").gpu_compositor);
  EXPECT_TRUE(parse_config(R"({"default": {"compositor": "host"}, "applications": {"App": {"compositor": "gpu"}}})",
                           "cfg.json", "App")
                  .gpu_compositor);
  try {
    parse_config(R"({"default": {"compositor": 1}})", "cfg.json", "App");
    FAIL() << "accepted";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cfg.json: default.compositor"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("\"gpu\" or \"host\""), std::string::npos) << e.what();
  }
  setenv("XDG_CONFIG_HOME", "/nonexistent-fovea-config", 1);  // no configuration file
  setenv("FOVEA_LAYER_COMPOSITOR", "host", 1);
  EXPECT_FALSE(load_config("App").gpu_compositor);
  setenv("FOVEA_LAYER_COMPOSITOR", "cpu", 1);
  EXPECT_THROW(load_config("App"), core::InputError);
  unsetenv("FOVEA_LAYER_COMPOSITOR");
}

TEST(LayerConfig, RenderPriority) {
  const RenderPriority d = parse_config(R"({"default": {"scene": "cornell"}})", "cfg.json", "App").render_priority;
  EXPECT_FALSE(d.idle);
  EXPECT_EQ(d.nice, 19);
  const RenderPriority n = parse_config(R"({"default": {"render_priority": 7}})", "cfg.json", "App").render_priority;
  EXPECT_FALSE(n.idle);
  EXPECT_EQ(n.nice, 7);
  EXPECT_EQ(render_priority_name(n), "nice 7");
  EXPECT_EQ(render_priority_name(parse_config(R"({"default": {"render_priority": "idle"}})", "cfg.json", "App")
                                     .render_priority),
            "SCHED_IDLE");
  EXPECT_TRUE(parse_config(R"({"default": {"render_priority": 5}, "applications": {"App": {"render_priority": "idle"}}})",
                           "cfg.json", "App")
                  .render_priority.idle);
  for (const char* bad : {"20", "-1", "\"low\"", "1.5", "\" 3\""}) {
    try {
      parse_config(std::string(R"({"default": {"render_priority": )") + bad + "}}", "cfg.json", "App");
      FAIL() << bad << " accepted";
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cfg.json: default.render_priority"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("\"idle\" or a nice value 0..19"), std::string::npos) << e.what();
    }
  }
  setenv("XDG_CONFIG_HOME", "/nonexistent-fovea-config", 1);
  setenv("FOVEA_LAYER_RENDER_PRIORITY", "10", 1);
  EXPECT_EQ(load_config("App").render_priority.nice, 10);
  setenv("FOVEA_LAYER_RENDER_PRIORITY", "nice", 1);
  EXPECT_THROW(load_config("App"), core::InputError);
  unsetenv("FOVEA_LAYER_RENDER_PRIORITY");
}

// A raw HID capture configured as the layer's gaze is a recording: at display times on the
// host clock the fovea follows it from the first frame on (it used to be taken for a live
// device and froze on its last sample).
TEST(LayerGaze, HidCaptureFollowsTheRecordingFromTheFirstFrame) {
  const std::string file = std::string(std::getenv("FOVEA_SOURCE_DIR")) + "/data/gaze/hid-ms.hidcap";
  const core::DisplayPreset display = core::load_display("small");
  std::vector<devices::GazeSample> rec;
  {
    devices::SourceOptions o;
    o.display = display;
    devices::hid::HidCaptureStream cap(file, o);
    devices::GazeSample s;
    while (cap.next(s)) rec.push_back(s);
  }
  ASSERT_EQ(rec.size(), 240u);
  LayerGaze gaze("hid-capture:" + file, display);
  const std::int64_t first = core::now_ns() + 20'000'000;  // XrTime of the first frame
  const std::int64_t period = std::llround(1e9 / display.refresh_hz);
  int moved = 0;
  glm::dvec3 prev(0, 0, -1);
  for (int f = 0; f * period < 2'000'000'000; ++f) {
    const std::int64_t t = first + f * period;
    const devices::FoveaGaze g = gaze.frame(t, nullptr);
    const auto newest = std::upper_bound(rec.begin(), rec.end(), t - first,
                                         [](std::int64_t q, const devices::GazeSample& s) { return q < s.t_ns; }) - 1;
    ASSERT_TRUE(g.has_sample);
    ASSERT_EQ(g.sample_ns, first + newest->t_ns) << f;
    ASSERT_LE(g.sample_ns, t);
    moved += core::angle_deg(prev, g.left.dir) > 0.01;
    prev = g.left.dir;
  }
  EXPECT_GT(moved, 40);  // ~140 frames of a search task: the fovea keeps moving
}

TEST(LayerGaze, TheActionGoesThroughTheSamePolicyWithItsSampleTime) {
  LayerGaze gaze("synthetic:1", core::load_display("small"));
  const glm::dvec3 right = glm::normalize(glm::dvec3(0.5, 0, -1));
  const std::int64_t t0 = 1'000'000'000'000;
  ActionGaze a{right, t0 - 4'000'000};
  const devices::FoveaGaze g = gaze.frame(t0, &a);
  EXPECT_EQ(g.sample_ns, t0 - 4'000'000);  // the runtime's XrEyeGazeSampleTimeEXT, not the display time
  EXPECT_LT(core::angle_deg(g.right.dir, right), 1e-9);
  const ActionGaze lost{std::nullopt, 0};
  const devices::FoveaGaze held = gaze.frame(t0 + 300'000'000, &lost);  // within the hold
  EXPECT_EQ(held.left.state, devices::FoveaState::Holding);
  EXPECT_LT(core::angle_deg(held.left.dir, right), 1e-9);
  const devices::FoveaGaze rest = gaze.frame(t0 + 800'000'000, &lost);  // past hold + ease
  EXPECT_EQ(rest.left.state, devices::FoveaState::Resting);
  EXPECT_LT(core::angle_deg(rest.left.dir, glm::dvec3(0, 0, -1)), 1e-9);
}

// No gaze source configured: fixed foveation at the view centre, said in a warning, never a
// synthetic scanpath.
TEST(LayerGaze, WithoutASourceTheFoveaStaysAtTheViewCentre) {
  testing::internal::CaptureStderr();
  LayerGaze gaze("", core::load_display("small"));
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("warn: no gaze source configured"), std::string::npos) << err;
  const std::int64_t t0 = 5'000'000'000;
  for (int frame = 0; frame < 300; ++frame) {  // 3.3 s at 90 Hz
    const devices::FoveaGaze g = gaze.frame(t0 + std::int64_t(frame) * 11'111'111, nullptr);
    ASSERT_FALSE(g.has_sample);
    for (core::Eye e : {core::Eye::Left, core::Eye::Right}) {
      ASSERT_EQ(g.eye(e).state, devices::FoveaState::Resting) << frame;
      ASSERT_LT(core::angle_deg(g.eye(e).dir, glm::dvec3(0, 0, -1)), 1e-9) << frame;
    }
  }
  // The runtime's eye-gaze action still steers it when present.
  const glm::dvec3 up = glm::normalize(glm::dvec3(0, 0.3, -1));
  const ActionGaze a{up, t0 + 4'000'000'000};
  EXPECT_LT(core::angle_deg(gaze.frame(t0 + 4'000'000'000, &a).left.dir, up), 1e-9);
}

// The window depth an application stores for view distance z (the inverse of view_distance).
float window_depth(double z, const DepthRange& r) {
  const auto inverse = [](double v) { return std::isinf(v) ? 0.0 : 1.0 / v; };
  const double t = (inverse(z) - inverse(r.near_z)) / (inverse(r.far_z) - inverse(r.near_z));
  return float(r.min_depth + t * (double(r.max_depth) - r.min_depth));
}

TEST(LayerDepth, ViewDistanceMapsTheRangeEnds) {
  const double inf = std::numeric_limits<double>::infinity();
  const float finf = std::numeric_limits<float>::infinity();
  for (const DepthRange r : {DepthRange{0, 1, 0.1f, 100}, DepthRange{0, 1, 100, 0.1f}, DepthRange{0.25f, 0.75f, 0.05f, 20},
                             DepthRange{0, 1, 0.1f, finf}, DepthRange{0, 1, finf, 0.1f}}) {
    const double zn = view_distance(r.min_depth, r), zf = view_distance(r.max_depth, r);
    if (std::isinf(r.near_z)) EXPECT_EQ(zn, inf); else EXPECT_NEAR(zn, r.near_z, 1e-5 * r.near_z);
    if (std::isinf(r.far_z)) EXPECT_EQ(zf, inf); else EXPECT_NEAR(zf, r.far_z, 1e-5 * r.far_z);
    for (double z : {0.5, 1.0, 3.0, 17.0}) EXPECT_NEAR(view_distance(window_depth(z, r), r), z, 1e-4 * z);
  }
  EXPECT_THROW(view_distance(0.5f, DepthRange{0, 1, 1, 1}), std::runtime_error);
  EXPECT_THROW(view_distance(0.5f, DepthRange{0.5f, 0.5f, 0.1f, 10}), std::runtime_error);
  EXPECT_THROW(view_distance(0.5f, DepthRange{0, 1, 0, 10}), std::runtime_error);
}

TEST(LayerDepth, KeepsTheNearerSurfaceForEveryDepthConvention) {
  const float finf = std::numeric_limits<float>::infinity();
  // Scene: surfaces at 2 m and 5 m, sky (0) in pixel 2.
  const std::vector<float> scene_depth{2, 2, 0, 5, 5};
  for (const DepthRange r : {DepthRange{0, 1, 0.1f, 100}, DepthRange{0, 1, 100, 0.1f}, DepthRange{0.25f, 0.75f, 0.05f, 200},
                             DepthRange{0, 1, 0.1f, finf}, DepthRange{0, 1, finf, 0.1f}}) {
    Pixels8 app = filled(5, 1, {10, 20, 30, 255});
    app.at(4, 0)[3] = 0;  // not covered by the application
    // App surfaces at 1 m (nearer), 3 m (behind the scene), 50 m (in front of the sky),
    // cleared (the far end), 1 m but alpha 0.
    const bool reversed = r.near_z > r.far_z;
    const float cleared = reversed ? r.min_depth : r.max_depth;
    const std::vector<float> app_depth{window_depth(1, r), window_depth(3, r), window_depth(50, r), cleared,
                                       window_depth(1, r)};
    Pixels8 scene = filled(5, 1, {200, 100, 50, 255});
    EXPECT_EQ(composite_depth(scene, scene_depth, app, app_depth, r), 2)
        << "near " << r.near_z << " far " << r.far_z;
    EXPECT_EQ(scene.at(0, 0)[0], 10);
    EXPECT_EQ(scene.at(1, 0)[0], 200);
    EXPECT_EQ(scene.at(2, 0)[0], 10);
    EXPECT_EQ(scene.at(3, 0)[0], 200);
    EXPECT_EQ(scene.at(4, 0)[0], 200);
  }
  Pixels8 scene = filled(2, 1, {0, 0, 0, 255});
  EXPECT_THROW(composite_depth(scene, {1}, filled(2, 1, {0, 0, 0, 255}), {0, 0}, DepthRange{}), std::logic_error);
}

// The replaced projection view keeps every structure the application chained but its depth.
TEST(LayerNextChain, DropsOnlyTheDepth) {
  XrCompositionLayerColorScaleBiasKHR after{XR_TYPE_COMPOSITION_LAYER_COLOR_SCALE_BIAS_KHR};
  XrCompositionLayerDepthInfoKHR depth{XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR, &after};
  XrCompositionLayerColorScaleBiasKHR before{XR_TYPE_COMPOSITION_LAYER_COLOR_SCALE_BIAS_KHR, &depth};
  before.colorScale = {0.5f, 0.25f, 1, 1};
  ChainCopies copies;
  std::size_t lost = 7;
  const auto* head = static_cast<const XrCompositionLayerColorScaleBiasKHR*>(
      copies.without(&before, XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR, &lost));
  EXPECT_EQ(lost, 0u);
  ASSERT_NE(head, nullptr);
  EXPECT_NE(head, &before);  // a copy: the application's chain is left untouched
  EXPECT_EQ(before.next, &depth);
  EXPECT_EQ(head->type, XR_TYPE_COMPOSITION_LAYER_COLOR_SCALE_BIAS_KHR);
  EXPECT_EQ(head->colorScale.g, 0.25f);
  EXPECT_EQ(head->next, &after);  // after the depth: shared
  // Depth first or alone, or no depth at all: no copies needed.
  EXPECT_EQ(copies.without(&depth, XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR), &after);
  EXPECT_EQ(copies.without(&after, XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR), &after);
  EXPECT_EQ(copies.without(nullptr, XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR), nullptr);
}

TEST(LayerNextChain, AnUnknownStructureBeforeTheDepthIsCounted) {
  XrCompositionLayerDepthInfoKHR depth{XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR};
  XrCompositionLayerColorScaleBiasKHR known{XR_TYPE_COMPOSITION_LAYER_COLOR_SCALE_BIAS_KHR, &depth};
  const XrBaseInStructure unknown{XrStructureType(1000999999), reinterpret_cast<const XrBaseInStructure*>(&known)};
  EXPECT_EQ(structure_size(unknown.type), 0u);
  EXPECT_EQ(structure_size(XR_TYPE_COMPOSITION_LAYER_COLOR_SCALE_BIAS_KHR), sizeof(known));
  ChainCopies copies;
  std::size_t lost = 0;
  const auto* head = static_cast<const XrBaseInStructure*>(
      copies.without(&unknown, XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR, &lost));
  EXPECT_EQ(lost, 1u);
  ASSERT_NE(head, nullptr);
  EXPECT_EQ(head->type, XR_TYPE_COMPOSITION_LAYER_COLOR_SCALE_BIAS_KHR);
  EXPECT_EQ(head->next, nullptr);
}

// FOVEA_LAYER_OUT is created when missing, as the runtime creates FOVEA_RUNTIME_OUT (one
// helper, xrcommon::create_output_dir): the frames are logged, not just warned about.
TEST(LayerFrameLog, MissingOutputDirectoryIsCreated) {
  namespace fs = std::filesystem;
  const fs::path root = fs::temp_directory_path() / ("fovea_layer_out_" + std::to_string(::getpid()));
  fs::remove_all(root);
  const fs::path out = root / "not" / "yet";
  {
    FrameLog log;
    log.open(out.string());
    FrameTimes t;
    t.frame = 3;
    log.write(t);
  }  // the destructor writes what is left
  std::ifstream in(out / "layer_timing.jsonl");
  std::string line;
  ASSERT_TRUE(std::getline(in, line)) << "no record in " << out;
  EXPECT_NE(line.find("\"frame\":3"), std::string::npos) << line;
  fs::remove_all(root);
}

// The layer's frame is `fovea render`'s: the same defaults (FrameDefaults.* checks the CLI's
// entry points against them) and the same option names, in the file and the environment.
TEST(FrameConfigLayer, DefaultsAndOptionNamesAreFoveaRendersOwn) {
  const nlohmann::json defaults = pipeline::to_json(pipeline::FrameConfig{});
  EXPECT_EQ(pipeline::to_json(parse_config("{}", "cfg.json", "App").frame), defaults);
  const LayerConfig c = parse_config(
      R"({"default": {"budget": 0.2, "distribution": "log-polar", "jitter": "off", "denoiser": "none",
                      "bmfr-precision": "fp16", "stereo-share": "alternate", "trace": "compute"},
          "applications": {"App": {"budget": 0.25}}})",
      "cfg.json", "App");
  const nlohmann::json j = pipeline::to_json(c.frame);
  EXPECT_EQ(j["budget"], 0.25);
  EXPECT_EQ(j["distribution"], "log-polar");
  EXPECT_EQ(j["jitter"], "off");
  EXPECT_EQ(j["denoiser"], "none");
  EXPECT_EQ(j["bmfr-precision"], "fp16");
  EXPECT_EQ(j["stereo-share"], "alternate");
  EXPECT_EQ(j["trace"], "compute");
  // Cartesian traces every pixel; a fraction is refused naming the file, as on the command line.
  EXPECT_EQ(parse_config(R"({"default": {"distribution": "cartesian"}})", "cfg.json", "App").frame.distribution.budget, 1.0);
  for (const char* bad : {R"({"default": {"distribution": "cartesian", "budget": 0.5}})",
                          R"({"default": {"budget": 7}})", R"({"default": {"stereo-share": "both"}})"}) {
    try {
      parse_config(bad, "cfg.json", "App");
      ADD_FAILURE() << "accepted " << bad;
    } catch (const core::InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("cfg.json", 0), 0u) << e.what();
    }
  }
}

TEST(FrameConfigLayer, EnvironmentTakesTheSameOptions) {
  setenv("XDG_CONFIG_HOME", "/nonexistent-fovea-config", 1);  // no configuration file
  setenv("FOVEA_LAYER_BUDGET", "0.2", 1);
  setenv("FOVEA_LAYER_STEREO_SHARE", "off", 1);
  const nlohmann::json j = pipeline::to_json(load_config("App").frame);
  EXPECT_EQ(j["budget"], 0.2);
  EXPECT_EQ(j["stereo-share"], "off");
  setenv("FOVEA_LAYER_DENOISER", "neural", 1);
  try {
    load_config("App");
    ADD_FAILURE() << "FOVEA_LAYER_DENOISER=neural accepted";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("FOVEA_LAYER_DENOISER: unknown \"neural\""), std::string::npos) << e.what();
  }
  for (const char* v : {"FOVEA_LAYER_BUDGET", "FOVEA_LAYER_STEREO_SHARE", "FOVEA_LAYER_DENOISER"}) unsetenv(v);
}

// The path tracer's queue on the application's device, for the queue families of common
// drivers (NVIDIA: 16 graphics, 2 transfer, 8 compute; RADV: 1 graphics, 4 compute; lavapipe:
// 1 of everything) and the requests an application makes.
VkQueueFamilyProperties family(VkQueueFlags flags, std::uint32_t count) {
  VkQueueFamilyProperties f{};
  f.queueFlags = flags;
  f.queueCount = count;
  return f;
}
VkDeviceQueueCreateInfo queues(std::uint32_t family, std::uint32_t count, const float* priorities,
                               VkDeviceQueueCreateFlags flags = 0) {
  VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  q.flags = flags;
  q.queueFamilyIndex = family;
  q.queueCount = count;
  q.pQueuePriorities = priorities;
  return q;
}

TEST(LayerQueue, AsynchronousComputeFamilyFirstThenASpareQueueElseWhyNot) {
  constexpr VkQueueFlags G = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT | VK_QUEUE_TRANSFER_BIT;
  constexpr VkQueueFlags C = VK_QUEUE_COMPUTE_BIT | VK_QUEUE_TRANSFER_BIT, T = VK_QUEUE_TRANSFER_BIT;
  const std::vector<VkQueueFamilyProperties> nvidia{family(G, 16), family(T, 2), family(C, 8)};
  const std::vector<VkQueueFamilyProperties> radv{family(G, 1), family(C, 4)};
  const std::vector<VkQueueFamilyProperties> lavapipe{family(G, 1)};
  const float app_priorities[] = {1.0f, 0.5f};

  // The graphics queue the application renders with: the compute family beside it.
  const VkDeviceQueueCreateInfo graphics = queues(0, 1, app_priorities);
  for (const auto* families : {&nvidia, &radv}) {
    const LayerQueueRequest r = request_layer_queue(*families, &graphics, 1);
    ASSERT_TRUE(r.queue.has_value()) << r.no_queue;
    EXPECT_EQ(*r.queue, (QueueIndex{std::uint32_t(families->size() - 1), 0}));
    ASSERT_EQ(r.infos.size(), 2u);
    EXPECT_EQ(r.infos[0].queueCount, 1u);  // the application's request unchanged
    EXPECT_EQ(r.infos[0].pQueuePriorities, app_priorities);
    EXPECT_EQ(r.infos[1].queueFamilyIndex, r.queue->family);
    EXPECT_EQ(r.infos[1].queueCount, 1u);
    EXPECT_EQ(r.infos[1].pQueuePriorities[0], 0.0f);
  }
  // Every compute-capable family in use: one more queue of the first with a queue to spare,
  // the application's priorities kept.
  const VkDeviceQueueCreateInfo both[] = {queues(0, 2, app_priorities), queues(2, 8, app_priorities)};
  LayerQueueRequest r = request_layer_queue(nvidia, both, 2);
  ASSERT_TRUE(r.queue.has_value()) << r.no_queue;
  EXPECT_EQ(*r.queue, (QueueIndex{0, 2}));
  ASSERT_EQ(r.infos.size(), 2u);
  EXPECT_EQ(r.infos[0].queueCount, 3u);
  EXPECT_EQ(r.infos[0].pQueuePriorities[0], 1.0f);
  EXPECT_EQ(r.infos[0].pQueuePriorities[1], 0.5f);
  EXPECT_EQ(r.infos[0].pQueuePriorities[2], 0.0f);
  EXPECT_EQ(r.infos[1].queueCount, 8u);
  // No queue to spare: the request unchanged, and why.
  const VkDeviceQueueCreateInfo radv_all[] = {queues(0, 1, app_priorities), queues(1, 4, app_priorities)};
  for (const auto& [families, request, count] :
       {std::tuple{&lavapipe, &graphics, 1u}, std::tuple{&radv, radv_all, 2u}}) {
    r = request_layer_queue(*families, request, count);
    EXPECT_FALSE(r.queue.has_value());
    ASSERT_EQ(r.infos.size(), count);
    for (std::uint32_t i = 0; i < count; ++i) EXPECT_EQ(r.infos[i].queueCount, request[i].queueCount);
    EXPECT_NE(r.no_queue.find("the application asks for every queue"), std::string::npos) << r.no_queue;
    EXPECT_NE(r.no_queue.find("family 0: 1 of 1"), std::string::npos) << r.no_queue;
  }
  // A family with protected queues is the application's alone; none without compute at all.
  const VkDeviceQueueCreateInfo protected_compute[] = {
      queues(0, 1, app_priorities), queues(1, 1, app_priorities, VK_DEVICE_QUEUE_CREATE_PROTECTED_BIT)};
  r = request_layer_queue(radv, protected_compute, 2);
  EXPECT_FALSE(r.queue.has_value());
  r = request_layer_queue({family(T, 2)}, nullptr, 0);
  EXPECT_FALSE(r.queue.has_value());
  EXPECT_NE(r.no_queue.find("no compute-capable queue family"), std::string::npos) << r.no_queue;
}

}  // namespace
}  // namespace fovea::layer

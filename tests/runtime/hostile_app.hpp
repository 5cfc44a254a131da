#pragma once
// A hostile OpenXR application: it submits bad composition layers, destroys swapchains
// mid-frame, calls the frame and swapchain functions out of order and uses invalid and
// destroyed handles, asserting the specification's error code for each, then checks that
// a normal frame loop still works and that the session ends cleanly.
//
// The scenarios are value-parameterised GoogleTests (TEST_P in hostile_app.cpp) so the same
// application runs against the runtime alone (hostile_app_test.cpp) and with the Fovea API
// layer between it and the runtime (tests/layer/hostile_layer_test.cpp): the layer must
// return the runtime's codes unchanged and keep the process alive.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "xr_fixture.hpp"
#include "xr_process.hpp"

namespace fovea::test {

struct HostileVariant {
  std::string name;       // test name suffix
  std::string layer_dir;  // explicit layer manifest directory; empty: the runtime alone
  std::string scene;      // FOVEA_SCENE for the layer (empty: pass-through)
};

class HostileApp : public XrTest, public ::testing::WithParamInterface<HostileVariant> {
 protected:
  void SetUp() override;
  void TearDown() override;

  // Session FOCUSED, one swapchain per eye with a released image, LOCAL space.
  void start();
  // xrWaitFrame + xrBeginFrame (a frame left open by a failed xrEndFrame is discarded).
  XrTime open_frame();
  // Acquire, wait and release one image of `sc`.
  void cycle(XrSwapchain sc);
  // The stereo projection layer of the eye swapchains, reset to valid values.
  const XrCompositionLayerBaseHeader* projection();
  // One frame: wait, begin, new images in the eye swapchains, then xrEndFrame with the
  // projection layer and `spoil` applied to the end info (and the projection) first.
  void expect_end(const char* what, XrResult expected, const std::function<void(XrFrameEndInfo&)>& spoil);
  // A normal frame loop of n frames with the eye swapchains: every xrEndFrame succeeds.
  void normal_frames(int n);
  void expect(const char* what, XrResult got, XrResult expected);
  // With the layer: its log shows no internal failure; with a scene, the last frame was
  // replaced by the layer's rendering (an application error does not disable it).
  void check_layer_after();

  std::unique_ptr<TempDir> out_;
  XrSpace local_ = XR_NULL_HANDLE;
  uint32_t width_ = 0, height_ = 0;
  XrSwapchain eye_[2] = {XR_NULL_HANDLE, XR_NULL_HANDLE};
  XrView located_[2]{};
  XrCompositionLayerProjectionView views_[3]{};
  XrCompositionLayerProjection projection_{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
};

}  // namespace fovea::test

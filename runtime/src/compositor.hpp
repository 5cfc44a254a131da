#pragma once
// What the simulated panel shows. The submitted projection layers are read back from the
// application's swapchain images into each eye's rendered view (the display preset's FOV and
// raster; a plain copy when the layer matches it, else resampled by direction). Then the
// lens (env FOVEA_RUNTIME_LENS): "gpu" (default) the compositor's distortion pass on a
// compute context of the runtime's own, "cpu" its double-precision reference
// (compositor::distort_reference; per-channel distortion, hidden area black), or "off" the
// undistorted view with the directions the lens hides blacked out. Every k-th frame the two
// panel images are written as PNG files.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fovea/core/display.hpp"
#include "fovea/core/hidden_area.hpp"
#include "fovea/core/image.hpp"
#include "fovea/compositor/distortion.hpp"
#include "fovea/compositor/marker.hpp"
#include "fovea/devices/saccade_predict.hpp"
#include "gaze.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "vk_util.hpp"
#include "xr.hpp"

namespace fovea::runtime {

enum class LensMode { Gpu, Cpu, Off };
// "gpu" | "cpu" | "off"; throws core::InputError naming FOVEA_RUNTIME_LENS otherwise.
LensMode parse_lens_mode(const std::string& s);

struct LayerView {
  VkImage image = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  std::uint32_t array_layer = 0;
  XrRect2Di rect{};
  core::Fov fov;
};

// Host time of compose()'s stages over both eyes (ms, monotonic clock): swapchain read-back
// (GPU copy and wait included), resampling into the rendered views, the lens, and PNG writing.
struct ComposeTimes {
  double readback_ms = 0, resample_ms = 0, lens_ms = 0, write_ms = 0;
};

struct ProjectionLayer {
  std::array<LayerView, 2> views;
  bool alpha_blend = false;  // XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT
};

class Compositor {
 public:
  // `hidden` (one per eye) must outlive the compositor.
  Compositor(VkPhysicalDevice physical, VkDevice device, OneShotQueue& queue, const core::DisplayPreset& display,
             std::array<const core::HiddenAreaMask*, 2> hidden, LensMode lens, std::string out_dir,
             std::int64_t png_every);
  ~Compositor();
  Compositor(const Compositor&) = delete;
  Compositor& operator=(const Compositor&) = delete;

  // Whether frame `index` is one whose panel images are produced.
  bool wants(std::int64_t index) const { return !out_dir_.empty() && index % png_every_ == 0; }
  // Composes and writes <out>/panel_<index>_{left,right}.png. The images must be in
  // COLOR_ATTACHMENT_OPTIMAL layout, owned by the session queue (as after release) and
  // sampleable (VK_IMAGE_USAGE_SAMPLED_BIT); they are left that way. Throws std::runtime_error on Vulkan or I/O failure.
  ComposeTimes compose(std::int64_t index, const std::vector<ProjectionLayer>& layers);

  static bool readable_format(VkFormat f);

  // Marker mode (FOVEA_MARKER…, docs/marker.md), called once per ended frame before
  // compose(): feeds the frame's gaze to the saccade-onset detector and advances the marker;
  // compose() then draws it. Each event is appended to <out>/marker.jsonl with the gaze
  // sample time behind it and the frame's display time.
  void observe_frame(std::int64_t index, const GazeSample& gaze, core::TimeNs displayed_ns);

 private:
  // The view's rect in linear RGBA, read by sampling the image (xr_readback.comp on the
  // application's device): swapchain images carry the sampled usage the runtime adds, not
  // necessarily the transfer usage a copy would need.
  core::Image read_back(const LayerView& v);
  void ensure_staging(VkDeviceSize bytes);
  void ensure_pipeline();

  VkPhysicalDevice physical_;
  VkDevice device_;
  OneShotQueue& queue_;
  core::DisplayPreset display_;
  std::array<const core::HiddenAreaMask*, 2> hidden_;
  LensMode lens_;
  // Gpu mode: created at the first composed frame.
  std::unique_ptr<gpu::Context> gpu_;
  std::array<std::unique_ptr<compositor::DistortionPass>, 2> passes_;
  // Off mode: per eye, whether each rendered-view pixel is visible (computed at first use).
  std::array<std::vector<std::uint8_t>, 2> visible_;
  std::string out_dir_;
  std::int64_t png_every_;
  compositor::MarkerConfig marker_config_;
  compositor::MarkerSchedule marker_;
  devices::SaccadeOnsetDetector onsets_;
  core::TimeNs last_gaze_ns_ = 0;
  std::int64_t lit_frame_ = -1;  // the frame index observe_frame() lit
  // The read-back pipeline (created at the first composed frame).
  VkSampler sampler_ = VK_NULL_HANDLE;
  gpu::ForeignPipelines program_;  // xr_readback.comp
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  VkBuffer staging_ = VK_NULL_HANDLE;
  VkDeviceMemory staging_memory_ = VK_NULL_HANDLE;
  VkDeviceSize staging_size_ = 0;
};

}  // namespace fovea::runtime

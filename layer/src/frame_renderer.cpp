#include "frame_renderer.hpp"

#include <stdexcept>

namespace fovea::layer {

std::unique_ptr<FrameRenderer> make_frame_renderer(const std::string& scene, const VulkanBinding&) {
  if (scene.empty()) return nullptr;
  throw std::runtime_error("FOVEA_LAYER_SCENE=" + scene +
                           ": scene rendering is not available in this build (the path tracer and the "
                           "reconstruction are not integrated into the layer yet)");
}

}  // namespace fovea::layer

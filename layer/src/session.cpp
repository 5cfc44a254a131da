// xrCreateSession / xrDestroySession: capture the application's Vulkan objects from the
// graphics binding and set up the session's frame renderer (none without a scene) and log.
#include <cstdlib>

#include "layer.hpp"
#include "log.hpp"

namespace fovea::layer {
namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

}  // namespace

XrResult intercept::xrCreateSession(XrInstance instance, const XrSessionCreateInfo* info, XrSession* session) {
  PFN_xrCreateSession next = nullptr;
  const Dispatch* dispatch = nullptr;  // stable: instances live in a std::map until xrDestroyInstance
  std::string application;
  {
    std::lock_guard lock(layer().mutex);
    auto it = layer().instances.find(instance);
    if (it == layer().instances.end()) return XR_ERROR_HANDLE_INVALID;
    next = it->second.next.xrCreateSession;
    dispatch = &it->second.next;
    application = it->second.application;
  }
  const XrResult r = next(instance, info, session);
  if (XR_FAILED(r)) return r;
  SessionState st;
  st.instance = instance;
  try {
    for (auto* p = static_cast<const XrBaseInStructure*>(info->next); p; p = p->next)
      if (p->type == XR_TYPE_GRAPHICS_BINDING_VULKAN_KHR) {
        const auto* b = reinterpret_cast<const XrGraphicsBindingVulkanKHR*>(p);
        st.vulkan = {b->instance, b->physicalDevice, b->device, b->queueFamilyIndex, b->queueIndex};
      }
    st.log.open(env("FOVEA_LAYER_OUT"));
    st.renderer = make_frame_renderer(load_config(application), st.vulkan, *dispatch, *session);
    FOVEA_LAYER_INFO("session: Vulkan device %s (queue family %u index %u); %s", st.vulkan.valid() ? "captured" : "absent",
                     st.vulkan.queue_family, st.vulkan.queue_index,
                     st.renderer ? "rendering the scene" : "no scene: pass-through, measuring only");
  } catch (const std::exception& e) {
    FOVEA_LAYER_ERROR("session setup failed, the layer passes this session through: %s", e.what());
    st.renderer.reset();
    st.disabled = true;
  }
  std::lock_guard lock(layer().mutex);
  layer().sessions[*session] = std::move(st);
  return r;
}

void release_session(SessionState& s, const Dispatch& next) {
  s.renderer.reset();
  destroy_eye_gaze_session(next, s.gaze);
  s.disabled = true;
}

XrResult intercept::xrDestroySession(XrSession session) {
  PFN_xrDestroySession next = nullptr;
  {
    std::lock_guard lock(layer().mutex);
    const Dispatch* d = next_for_session(session);
    if (!d) return XR_ERROR_HANDLE_INVALID;
    next = d->xrDestroySession;
    auto it = layer().sessions.find(session);
    if (it != layer().sessions.end()) release_session(it->second, *d);
  }
  const XrResult r = next(session);
  if (XR_SUCCEEDED(r)) {
    std::lock_guard lock(layer().mutex);
    Layer& l = layer();
    for (auto it = l.swapchains.begin(); it != l.swapchains.end();)
      it = it->second.session == session ? l.swapchains.erase(it) : std::next(it);
    l.sessions.erase(session);
  }
  return r;
}

}  // namespace fovea::layer

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
  PFN_xrGetVisibilityMaskKHR get_visibility_mask = nullptr;
  {
    std::lock_guard lock(layer().mutex);
    auto it = layer().instances.find(instance);
    if (it == layer().instances.end()) return XR_ERROR_HANDLE_INVALID;
    next = it->second.next.xrCreateSession;
    dispatch = &it->second.next;
    application = it->second.application;
    get_visibility_mask = it->second.get_visibility_mask;
  }
  const XrResult r = next(instance, info, session);
  if (XR_FAILED(r)) return r;
  SessionState st;
  st.instance = instance;
  st.get_visibility_mask = get_visibility_mask;
  try {
    for (auto* p = static_cast<const XrBaseInStructure*>(info->next); p; p = p->next)
      if (p->type == XR_TYPE_GRAPHICS_BINDING_VULKAN_KHR) {
        const auto* b = reinterpret_cast<const XrGraphicsBindingVulkanKHR*>(p);
        st.vulkan = {b->instance, b->physicalDevice, b->device, b->queueFamilyIndex, b->queueIndex};
        std::lock_guard lock(layer().mutex);
        if (auto d = layer().vulkan_devices.find(b->device); d != layer().vulkan_devices.end()) {
          VulkanDeviceRecord& added = st.vulkan.added = d->second;
          if (added.layer_queue == QueueIndex{b->queueFamilyIndex, b->queueIndex}) {
            added.layer_queue.reset();
            added.no_layer_queue = "the application uses the queue the layer added to its device";
          }
        }
      }
    st.frames->log.open(env("FOVEA_LAYER_OUT"));
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

std::shared_ptr<FrameRenderer> release_session(SessionState& s, const Dispatch& next) {
  destroy_eye_gaze_session(next, s.gaze);
  s.disabled = true;
  return std::move(s.renderer);
}

XrResult intercept::xrDestroySession(XrSession session) {
  PFN_xrDestroySession next = nullptr;
  std::shared_ptr<FrameRenderer> renderer;
  {
    std::lock_guard lock(layer().mutex);
    const Dispatch* d = next_for_session(session);
    if (!d) return XR_ERROR_HANDLE_INVALID;
    next = d->xrDestroySession;
    auto it = layer().sessions.find(session);
    if (it != layer().sessions.end()) renderer = release_session(it->second, *d);
  }
  renderer.reset();  // joins the render thread; the swapchains go while the session lives
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

// A visibility mask change makes the session's renderer fetch the mask again. When the layer
// enabled the extension for itself the event is the layer's alone: it is consumed and the
// next event, if any, is returned instead. So is an interaction-profile change that only the
// layer's eye-gaze binding caused.
XrResult intercept::xrPollEvent(XrInstance instance, XrEventDataBuffer* event) {
  PFN_xrPollEvent next = nullptr;
  bool hidden = false;
  {
    std::lock_guard lock(layer().mutex);
    auto it = layer().instances.find(instance);
    if (it == layer().instances.end()) return XR_ERROR_HANDLE_INVALID;
    next = it->second.next.xrPollEvent;
    hidden = it->second.visibility_mask_hidden;
  }
  for (;;) {
    const XrResult r = next(instance, event);
    if (r == XR_SUCCESS && event->type == XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED &&
        layer_caused_profile_change(reinterpret_cast<const XrEventDataInteractionProfileChanged*>(event)->session)) {
      *event = {XR_TYPE_EVENT_DATA_BUFFER};
      continue;
    }
    if (r != XR_SUCCESS || event->type != XR_TYPE_EVENT_DATA_VISIBILITY_MASK_CHANGED_KHR) return r;
    const XrSession session = reinterpret_cast<const XrEventDataVisibilityMaskChangedKHR*>(event)->session;
    {
      std::lock_guard lock(layer().mutex);
      auto it = layer().sessions.find(session);
      if (it != layer().sessions.end()) ++it->second.visibility_mask_generation;
    }
    if (!hidden) return r;
    *event = {XR_TYPE_EVENT_DATA_BUFFER};  // the application's buffer, as the runtime expects it
  }
}

}  // namespace fovea::layer

// Session lifetime and the session state machine:
//   IDLE -> READY (on creation) -> SYNCHRONIZED (first xrWaitFrame) -> VISIBLE -> FOCUSED
//   (first xrEndFrame); on exit (xrRequestExitSession, or FOVEA_EXIT_AFTER_FRAMES frames ended)
//   FOCUSED -> VISIBLE -> SYNCHRONIZED -> STOPPING; xrEndSession -> IDLE -> EXITING.
#include <vector>

#include "api.hpp"
#include "compositor.hpp"
#include "state.hpp"
#include "vk_util.hpp"

namespace fovea::runtime {

Session::~Session() {
  compositor.reset();
  gpu.reset();
}

// Queues the transitions from the current state down to STOPPING (once).
void request_exit(Session& s) {
  s.exit_requested = true;
  switch (s.queued_state) {
    case XR_SESSION_STATE_FOCUSED: s.queue_state(XR_SESSION_STATE_VISIBLE); [[fallthrough]];
    case XR_SESSION_STATE_VISIBLE: s.queue_state(XR_SESSION_STATE_SYNCHRONIZED); [[fallthrough]];
    case XR_SESSION_STATE_SYNCHRONIZED: s.queue_state(XR_SESSION_STATE_STOPPING); break;
    case XR_SESSION_STATE_READY:
      s.queue_state(XR_SESSION_STATE_SYNCHRONIZED);
      s.queue_state(XR_SESSION_STATE_STOPPING);
      break;
    default: break;  // already stopping or not running
  }
}

XrResult api::xrCreateSession(XrInstance instance, const XrSessionCreateInfo* info, XrSession* session) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = find<Instance>(instance);
    if (!inst) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_SESSION_CREATE_INFO) || !session) return XR_ERROR_VALIDATION_FAILURE;
    if (info->createFlags != 0) return XR_ERROR_VALIDATION_FAILURE;
    if (info->systemId != kSystemId || !inst->system_queried) return XR_ERROR_SYSTEM_INVALID;
    const auto* binding =
        find_next<const XrGraphicsBindingVulkanKHR>(info->next, XR_TYPE_GRAPHICS_BINDING_VULKAN_KHR);
    if (!binding || !(inst->has(XR_KHR_VULKAN_ENABLE_EXTENSION_NAME) || inst->has(XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME)))
      return XR_ERROR_GRAPHICS_DEVICE_INVALID;
    if (!inst->graphics_requirements_queried) return XR_ERROR_GRAPHICS_REQUIREMENTS_CALL_MISSING;
    if (binding->instance == VK_NULL_HANDLE || binding->physicalDevice == VK_NULL_HANDLE ||
        binding->device == VK_NULL_HANDLE)
      return XR_ERROR_GRAPHICS_DEVICE_INVALID;
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(binding->physicalDevice, &families, nullptr);
    std::vector<VkQueueFamilyProperties> props(families);
    vkGetPhysicalDeviceQueueFamilyProperties(binding->physicalDevice, &families, props.data());
    if (binding->queueFamilyIndex >= families || binding->queueIndex >= props[binding->queueFamilyIndex].queueCount)
      return XR_ERROR_GRAPHICS_DEVICE_INVALID;
    if (inst->session) return XR_ERROR_LIMIT_REACHED;

    auto s = std::make_unique<Session>();
    s->instance = inst;
    s->created_ns = xr_now();
    s->vk_physical = binding->physicalDevice;
    s->vk_device = binding->device;
    s->queue_family = binding->queueFamilyIndex;
    s->queue_index = binding->queueIndex;
    vkGetDeviceQueue(s->vk_device, s->queue_family, s->queue_index, &s->queue);
    s->gpu = std::make_unique<OneShotQueue>(s->vk_device, s->queue_family, s->queue);
    s->compositor = std::make_unique<Compositor>(
        s->vk_physical, s->vk_device, *s->gpu, inst->display,
        std::array<const core::HiddenAreaMask*, 2>{inst->hidden[0].get(), inst->hidden[1].get()}, inst->config.lens,
        inst->config.out_dir, inst->config.png_every);
    s->clock = DisplayClock(inst->display.refresh_hz, inst->config.pacing);
    s->timing.open(inst->config.out_dir);
    Session* raw = s.get();
    const std::uint64_t id = add_object(std::move(s), inst->id);
    inst->session = id;
    raw->queue_state(XR_SESSION_STATE_IDLE);
    raw->queue_state(XR_SESSION_STATE_READY);
    FOVEA_LOG_INFO("session created (queue family %u index %u)", raw->queue_family, raw->queue_index);
    *session = to_handle<XrSession>(id);
    return XR_SUCCESS;
  });
}

XrResult api::xrDestroySession(XrSession session) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    s->instance->session = 0;
    destroy_object(s->id);
    return XR_SUCCESS;
  });
}

XrResult api::xrBeginSession(XrSession session, const XrSessionBeginInfo* info) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_SESSION_BEGIN_INFO)) return XR_ERROR_VALIDATION_FAILURE;
    if (info->primaryViewConfigurationType != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO) {
      const auto t = info->primaryViewConfigurationType;
      const bool known = t == XR_VIEW_CONFIGURATION_TYPE_PRIMARY_MONO || t == XR_VIEW_CONFIGURATION_TYPE_PRIMARY_QUAD_VARJO ||
                         t == XR_VIEW_CONFIGURATION_TYPE_SECONDARY_MONO_FIRST_PERSON_OBSERVER_MSFT;
      return known ? XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED : XR_ERROR_VALIDATION_FAILURE;
    }
    if (s->running) return XR_ERROR_SESSION_RUNNING;
    if (s->state != XR_SESSION_STATE_READY) return XR_ERROR_SESSION_NOT_READY;
    s->running = true;
    FOVEA_LOG_INFO("session begun");
    return XR_SUCCESS;
  });
}

XrResult api::xrEndSession(XrSession session) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
    if (s->state != XR_SESSION_STATE_STOPPING) return XR_ERROR_SESSION_NOT_STOPPING;
    s->running = false;
    s->frame_open = false;
    s->waited.clear();
    frame_begun().notify_all();
    s->queue_state(XR_SESSION_STATE_IDLE);
    if (s->exit_requested) s->queue_state(XR_SESSION_STATE_EXITING);
    FOVEA_LOG_INFO("session ended after %lld frames", static_cast<long long>(s->frames_ended));
    return XR_SUCCESS;
  });
}

XrResult api::xrRequestExitSession(XrSession session) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
    request_exit(*s);
    return XR_SUCCESS;
  });
}

}  // namespace fovea::runtime

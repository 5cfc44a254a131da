// Instance lifetime, extensions, events, paths, string conversions and time conversion.
#include <cstdio>
#include <cstring>
#include <string>

#include <openxr/openxr_reflection.h>

#include "api.hpp"
#include "fovea/core/error.hpp"
#include "fovea/xrcommon/output_dir.hpp"
#include "state.hpp"

namespace fovea::runtime {
namespace {

const XrExtensionProperties kExtensions[] = {
    {XR_TYPE_EXTENSION_PROPERTIES, nullptr, XR_KHR_VULKAN_ENABLE_EXTENSION_NAME, XR_KHR_vulkan_enable_SPEC_VERSION},
    {XR_TYPE_EXTENSION_PROPERTIES, nullptr, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME, XR_KHR_vulkan_enable2_SPEC_VERSION},
    {XR_TYPE_EXTENSION_PROPERTIES, nullptr, XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME,
     XR_EXT_eye_gaze_interaction_SPEC_VERSION},
    {XR_TYPE_EXTENSION_PROPERTIES, nullptr, XR_KHR_VISIBILITY_MASK_EXTENSION_NAME, XR_KHR_visibility_mask_SPEC_VERSION},
    {XR_TYPE_EXTENSION_PROPERTIES, nullptr, XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME,
     XR_KHR_composition_layer_depth_SPEC_VERSION},
    {XR_TYPE_EXTENSION_PROPERTIES, nullptr, XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME,
     XR_KHR_convert_timespec_time_SPEC_VERSION},
};

bool supported_extension(const char* name) {
  for (const auto& e : kExtensions)
    if (!std::strcmp(e.extensionName, name)) return true;
  return false;
}

// Path strings (core spec "Path Atom Type"): absolute, components of [a-z0-9-_.], no empty
// components, no "." or ".." components, no trailing slash.
bool well_formed_path(const char* s) {
  if (!terminated(s, XR_MAX_PATH_LENGTH) || s[0] != '/') return false;
  const size_t n = std::strlen(s);
  if (n < 2 || s[n - 1] == '/') return false;
  size_t start = 1;
  for (size_t i = 1; i <= n; ++i) {
    if (i == n || s[i] == '/') {
      const size_t len = i - start;
      if (len == 0) return false;
      const std::string comp(s + start, len);
      if (comp == "." || comp == "..") return false;
      start = i + 1;
      continue;
    }
    const char c = s[i];
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.')) return false;
  }
  return true;
}

}  // namespace

XrResult api::xrEnumerateApiLayerProperties(uint32_t capacity, uint32_t* count, XrApiLayerProperties* props) {
  return guarded(__func__, [&] {
    return two_call(capacity, count, props, std::vector<XrApiLayerProperties>{});
  });
}

XrResult api::xrEnumerateInstanceExtensionProperties(const char* layerName, uint32_t capacity, uint32_t* count,
                                                     XrExtensionProperties* props) {
  return guarded(__func__, [&]() -> XrResult {
    if (layerName) return XR_ERROR_API_LAYER_NOT_PRESENT;
    if (!count || (capacity && !props)) return XR_ERROR_VALIDATION_FAILURE;
    const uint32_t n = uint32_t(std::size(kExtensions));
    *count = n;
    if (capacity == 0) return XR_SUCCESS;
    if (capacity < n) return XR_ERROR_SIZE_INSUFFICIENT;
    for (uint32_t i = 0; i < n; ++i)
      if (props[i].type != XR_TYPE_EXTENSION_PROPERTIES) return XR_ERROR_VALIDATION_FAILURE;
    for (uint32_t i = 0; i < n; ++i) {
      void* next = props[i].next;
      props[i] = kExtensions[i];
      props[i].next = next;
    }
    return XR_SUCCESS;
  });
}

XrResult api::xrCreateInstance(const XrInstanceCreateInfo* info, XrInstance* instance) {
  return guarded(__func__, [&]() -> XrResult {
    if (!has_type(info, XR_TYPE_INSTANCE_CREATE_INFO) || !instance) return XR_ERROR_VALIDATION_FAILURE;
    if (info->createFlags != 0) return XR_ERROR_VALIDATION_FAILURE;
    const XrApplicationInfo& app = info->applicationInfo;
    if (!terminated(app.applicationName, sizeof app.applicationName) || app.applicationName[0] == '\0' ||
        !terminated(app.engineName, sizeof app.engineName))
      return XR_ERROR_NAME_INVALID;
    if (XR_VERSION_MAJOR(app.apiVersion) != 1) return XR_ERROR_API_VERSION_UNSUPPORTED;
    if (info->enabledExtensionCount && !info->enabledExtensionNames) return XR_ERROR_VALIDATION_FAILURE;
    auto inst = std::make_unique<Instance>();
    for (uint32_t i = 0; i < info->enabledExtensionCount; ++i) {
      const char* ext = info->enabledExtensionNames[i];
      if (!ext || !supported_extension(ext)) {
        FOVEA_LOG_WARN("xrCreateInstance: extension %s is not supported", ext ? ext : "(null)");
        return XR_ERROR_EXTENSION_NOT_PRESENT;
      }
      inst->extensions.insert(ext);
    }
    try {
      inst->config = read_config();
      xrcommon::create_output_dir(inst->config.out_dir, "FOVEA_RUNTIME_OUT");
      inst->display = core::load_display(inst->config.display);
      inst->head = HeadMotion::from_spec(inst->config.head);
      inst->gaze = std::make_unique<GazeTracker>(inst->config.gaze, inst->display);
      for (int e = 0; e < 2; ++e)
        inst->hidden[size_t(e)] = std::make_unique<core::HiddenAreaMask>(
            core::Lens::for_eye(inst->display, e == 0 ? core::Eye::Left : core::Eye::Right));
    } catch (const core::InputError& e) {
      FOVEA_LOG_ERROR("xrCreateInstance: %s", e.what());
      return XR_ERROR_INITIALIZATION_FAILED;
    }
    inst->app_name = app.applicationName;
    log::set_file_dir(inst->config.out_dir);
    std::string exts;
    for (const auto& e : inst->extensions) exts += " " + e;
    FOVEA_LOG_INFO("instance: application \"%s\", display \"%s\" %dx%d@%gHz, gaze %s, head %s, extensions:%s",
                   inst->app_name.c_str(), inst->display.name.c_str(), inst->display.width, inst->display.height,
                   inst->display.refresh_hz, inst->gaze->describe().c_str(), inst->config.head.c_str(), exts.c_str());
    *instance = to_handle<XrInstance>(add_object(std::move(inst), 0));
    return XR_SUCCESS;
  });
}

XrResult api::xrDestroyInstance(XrInstance instance) {
  return guarded(__func__, [&]() -> XrResult {
    if (!find<Instance>(instance)) return XR_ERROR_HANDLE_INVALID;
    destroy_object(reinterpret_cast<std::uint64_t>(instance));
    return XR_SUCCESS;
  });
}

XrResult api::xrGetInstanceProperties(XrInstance instance, XrInstanceProperties* props) {
  return guarded(__func__, [&]() -> XrResult {
    if (!find<Instance>(instance)) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(props, XR_TYPE_INSTANCE_PROPERTIES)) return XR_ERROR_VALIDATION_FAILURE;
    props->runtimeVersion = XR_MAKE_VERSION(0, 1, 0);
    std::snprintf(props->runtimeName, sizeof props->runtimeName, "Fovea simulated HMD");
    return XR_SUCCESS;
  });
}

XrResult api::xrPollEvent(XrInstance instance, XrEventDataBuffer* event) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = find<Instance>(instance);
    if (!inst) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(event, XR_TYPE_EVENT_DATA_BUFFER)) return XR_ERROR_VALIDATION_FAILURE;
    while (!inst->events.empty()) {
      QueuedEvent e = inst->events.front();
      inst->events.pop_front();
      if (e.session) {
        Session* s = static_cast<Session*>(find_object(e.session, Kind::Session));
        if (!s) continue;  // the session was destroyed: its events go with it
        if (e.state) {
          s->state = *e.state;
          FOVEA_LOG_INFO("session state -> %d", int(*e.state));
        }
      }
      std::memcpy(event, &e.data, sizeof *event);
      return XR_SUCCESS;
    }
    return XR_EVENT_UNAVAILABLE;
  });
}

namespace {

#define FOVEA_CASE(n, v) \
  case n:                \
    return #n;
const char* result_name(XrResult value) {
  switch (value) {
    XR_LIST_ENUM_XrResult(FOVEA_CASE)
    default: return nullptr;
  }
}
const char* structure_type_name(XrStructureType value) {
  switch (value) {
    XR_LIST_ENUM_XrStructureType(FOVEA_CASE)
    default: return nullptr;
  }
}
#undef FOVEA_CASE

// The shared body of xr*ToString: the enum's name, or `unknown` for values this header
// version does not list.
XrResult enum_to_string(const char* call, XrInstance instance, char* buffer, std::size_t size, const char* name,
                        const std::string& unknown) {
  return guarded(call, [&]() -> XrResult {
    if (!find<Instance>(instance)) return XR_ERROR_HANDLE_INVALID;
    if (!buffer) return XR_ERROR_VALIDATION_FAILURE;
    std::snprintf(buffer, size, "%s", name ? name : unknown.c_str());
    return XR_SUCCESS;
  });
}

}  // namespace

XrResult api::xrResultToString(XrInstance instance, XrResult value, char buffer[XR_MAX_RESULT_STRING_SIZE]) {
  return enum_to_string(__func__, instance, buffer, XR_MAX_RESULT_STRING_SIZE, result_name(value),
                        std::string("XR_UNKNOWN_") + (value >= 0 ? "SUCCESS_" : "FAILURE_") + std::to_string(int(value)));
}

XrResult api::xrStructureTypeToString(XrInstance instance, XrStructureType value,
                                      char buffer[XR_MAX_STRUCTURE_NAME_SIZE]) {
  return enum_to_string(__func__, instance, buffer, XR_MAX_STRUCTURE_NAME_SIZE, structure_type_name(value),
                        "XR_UNKNOWN_STRUCTURE_TYPE_" + std::to_string(int(value)));
}

XrResult api::xrStringToPath(XrInstance instance, const char* pathString, XrPath* path) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = find<Instance>(instance);
    if (!inst) return XR_ERROR_HANDLE_INVALID;
    if (!pathString || !path) return XR_ERROR_VALIDATION_FAILURE;
    if (!well_formed_path(pathString)) return XR_ERROR_PATH_FORMAT_INVALID;
    if (inst->paths.size() >= 65536) return XR_ERROR_PATH_COUNT_EXCEEDED;
    *path = inst->path(pathString);
    return XR_SUCCESS;
  });
}

XrResult api::xrPathToString(XrInstance instance, XrPath path, uint32_t capacity, uint32_t* count, char* buffer) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = find<Instance>(instance);
    if (!inst) return XR_ERROR_HANDLE_INVALID;
    const std::string* s = inst->path_string(path);
    if (!s) return XR_ERROR_PATH_INVALID;
    return two_call_string(capacity, count, buffer, *s);
  });
}

XrResult api::xrConvertTimespecTimeToTimeKHR(XrInstance instance, const struct timespec* ts, XrTime* time) {
  return guarded(__func__, [&]() -> XrResult {
    if (!find<Instance>(instance)) return XR_ERROR_HANDLE_INVALID;
    if (!ts || !time) return XR_ERROR_VALIDATION_FAILURE;
    if (ts->tv_sec < 0 || ts->tv_nsec < 0 || ts->tv_nsec >= 1'000'000'000) return XR_ERROR_TIME_INVALID;
    // XrTime is CLOCK_MONOTONIC in nanoseconds.
    *time = XrTime(ts->tv_sec) * 1'000'000'000 + ts->tv_nsec;
    return XR_SUCCESS;
  });
}

XrResult api::xrConvertTimeToTimespecTimeKHR(XrInstance instance, XrTime time, struct timespec* ts) {
  return guarded(__func__, [&]() -> XrResult {
    if (!find<Instance>(instance)) return XR_ERROR_HANDLE_INVALID;
    if (!ts) return XR_ERROR_VALIDATION_FAILURE;
    if (time <= 0) return XR_ERROR_TIME_INVALID;
    ts->tv_sec = time / 1'000'000'000;
    ts->tv_nsec = time % 1'000'000'000;
    return XR_SUCCESS;
  });
}

}  // namespace fovea::runtime

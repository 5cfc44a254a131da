// xrCreateApiLayerInstance, xrGetInstanceProcAddr and xrDestroyInstance (api_layer.adoc:
// create-instance process, intercept requirements); the layer's global state.
#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "layer.hpp"
#include "log.hpp"

namespace fovea::layer {
namespace {

struct Entry {
  const char* name;
  PFN_xrVoidFunction fn;
};

#define FOVEA_LAYER_ENTRY(name) {#name, reinterpret_cast<PFN_xrVoidFunction>(&intercept::name)},
const Entry kIntercepted[] = {FOVEA_LAYER_INTERCEPTED(FOVEA_LAYER_ENTRY)};
#undef FOVEA_LAYER_ENTRY

// Whether the end of the chain (the loader's terminator, then the runtime) offers an instance
// extension. Asked there: a layer below need not answer a global command without an instance
// (the core validation layer reports an internal error when asked).
bool runtime_has_extension(PFN_xrGetInstanceProcAddr last_gipa, const char* name) {
  PFN_xrEnumerateInstanceExtensionProperties enumerate = nullptr;
  if (XR_FAILED(last_gipa(XR_NULL_HANDLE, "xrEnumerateInstanceExtensionProperties",
                          reinterpret_cast<PFN_xrVoidFunction*>(&enumerate))) ||
      !enumerate)
    return false;
  std::uint32_t n = 0;
  if (XR_FAILED(enumerate(nullptr, 0, &n, nullptr))) return false;
  std::vector<XrExtensionProperties> props(n, {XR_TYPE_EXTENSION_PROPERTIES});
  if (XR_FAILED(enumerate(nullptr, n, &n, props.data()))) return false;
  return std::any_of(props.begin(), props.begin() + n, [&](const XrExtensionProperties& p) {
    return !std::strcmp(p.extensionName, name);
  });
}

}  // namespace

XrResult XRAPI_CALL get_instance_proc_addr(XrInstance instance, const char* name, PFN_xrVoidFunction* function) {
  if (!name || !function) return XR_ERROR_VALIDATION_FAILURE;
  if (!std::strcmp(name, "xrGetInstanceProcAddr")) {
    *function = reinterpret_cast<PFN_xrVoidFunction>(&get_instance_proc_addr);
    return XR_SUCCESS;
  }
  PFN_xrGetInstanceProcAddr next = nullptr;
  bool mask_hidden = false, timespec_hidden = false;
  {
    std::lock_guard lock(layer().mutex);
    auto it = layer().instances.find(instance);
    if (it != layer().instances.end()) {
      next = it->second.next.xrGetInstanceProcAddr;
      mask_hidden = it->second.visibility_mask_hidden;
      timespec_hidden = it->second.timespec_hidden;
    }
  }
  if (!next) {
    *function = nullptr;
    return XR_ERROR_HANDLE_INVALID;  // not an instance created through this layer
  }
  // What the application did not enable stays unsupported for it, as without the layer.
  if ((mask_hidden && !std::strcmp(name, "xrGetVisibilityMaskKHR")) ||
      (timespec_hidden &&
       (!std::strcmp(name, "xrConvertTimeToTimespecTimeKHR") || !std::strcmp(name, "xrConvertTimespecTimeToTimeKHR")))) {
    *function = nullptr;
    return XR_ERROR_FUNCTION_UNSUPPORTED;
  }
  // Resolve down the chain first: an intercepted command the runtime does not have stays
  // unsupported.
  const XrResult r = next(instance, name, function);
  if (XR_FAILED(r)) return r;
  for (const Entry& e : kIntercepted)
    if (!std::strcmp(e.name, name)) *function = e.fn;
  return r;
}

XrResult XRAPI_CALL create_api_layer_instance(const XrInstanceCreateInfo* info, const XrApiLayerCreateInfo* layer_info,
                                              XrInstance* instance) {
  if (!info || !layer_info || !instance) return XR_ERROR_VALIDATION_FAILURE;
  if (layer_info->structType != XR_LOADER_INTERFACE_STRUCT_API_LAYER_CREATE_INFO ||
      layer_info->structVersion != XR_API_LAYER_CREATE_INFO_STRUCT_VERSION ||
      layer_info->structSize != sizeof(XrApiLayerCreateInfo))
    return XR_ERROR_INITIALIZATION_FAILED;
  const XrApiLayerNextInfo* next = layer_info->nextInfo;
  if (!next || next->structType != XR_LOADER_INTERFACE_STRUCT_API_LAYER_NEXT_INFO ||
      next->structVersion != XR_API_LAYER_NEXT_INFO_STRUCT_VERSION || next->structSize != sizeof(XrApiLayerNextInfo) ||
      std::strcmp(next->layerName, kLayerName) != 0 || !next->nextGetInstanceProcAddr ||
      !next->nextCreateApiLayerInstance)
    return XR_ERROR_INITIALIZATION_FAILED;

  // The layer's own extension is answered by the loader from the manifest; the layers
  // below and the runtime do not know it.
  std::vector<const char*> extensions;
  bool ours = false;
  for (uint32_t i = 0; i < info->enabledExtensionCount; ++i) {
    if (!std::strcmp(info->enabledExtensionNames[i], kLayerExtension))
      ours = true;
    else
      extensions.push_back(info->enabledExtensionNames[i]);
  }
  // With a scene configured, the layer's own eye-gaze input needs the extension enabled below.
  const std::string application(info->applicationInfo.applicationName,
                                strnlen(info->applicationInfo.applicationName, XR_MAX_APPLICATION_NAME_SIZE));
  // With a scene configured, the runtime's hidden area lets the layer skip tracing it.
  bool want_gaze = false, want_mask = false;
  const char* out = std::getenv("FOVEA_LAYER_OUT");
  const XrApiLayerNextInfo* last = next;
  while (last->next) last = last->next;
  // The timing log's XrTime values go on the layer's clock where the runtime can convert them.
  const bool want_timespec = out && *out && runtime_has_extension(last->nextGetInstanceProcAddr, kConvertTimespecExtension);
  try {
    if (!load_config(application).scene.empty()) {
      want_gaze = runtime_has_extension(last->nextGetInstanceProcAddr, kEyeGazeExtension);
      want_mask = runtime_has_extension(last->nextGetInstanceProcAddr, kVisibilityMaskExtension);
    }
  } catch (const std::exception& e) {
    FOVEA_LAYER_WARN("layer configuration: %s", e.what());  // reported again when the session starts
  }
  const auto enabled = [&](const char* name) {
    return std::any_of(extensions.begin(), extensions.end(), [&](const char* e) { return !std::strcmp(e, name); });
  };
  const bool gaze_hidden = want_gaze && !enabled(kEyeGazeExtension);
  if (gaze_hidden) extensions.push_back(kEyeGazeExtension);
  const bool app_mask = enabled(kVisibilityMaskExtension);
  const bool mask_hidden = want_mask && !app_mask;
  if (mask_hidden) extensions.push_back(kVisibilityMaskExtension);
  const bool timespec_hidden = want_timespec && !enabled(kConvertTimespecExtension);
  if (timespec_hidden) extensions.push_back(kConvertTimespecExtension);
  XrInstanceCreateInfo down = *info;
  down.enabledExtensionCount = uint32_t(extensions.size());
  down.enabledExtensionNames = extensions.data();
  XrApiLayerCreateInfo down_layer = *layer_info;
  down_layer.nextInfo = next->next;
  const XrResult r = next->nextCreateApiLayerInstance(&down, &down_layer, instance);
  if (XR_FAILED(r)) return r;

  InstanceState state;
  state.extension_enabled = ours;
  state.application = application;
  state.next.xrGetInstanceProcAddr = next->nextGetInstanceProcAddr;
  bool complete = true;
#define FOVEA_LAYER_RESOLVE(name)                                                                     \
  if (XR_FAILED(next->nextGetInstanceProcAddr(*instance, #name,                                      \
                                              reinterpret_cast<PFN_xrVoidFunction*>(&state.next.name))) || \
      !state.next.name)                                                                                 \
    complete = false;
  FOVEA_LAYER_NEXT(FOVEA_LAYER_RESOLVE)
#undef FOVEA_LAYER_RESOLVE
  if (!complete) {
    FOVEA_LAYER_ERROR("a core command is missing below the layer");
    if (state.next.xrDestroyInstance) state.next.xrDestroyInstance(*instance);
    *instance = XR_NULL_HANDLE;
    return XR_ERROR_INITIALIZATION_FAILED;
  }
  if ((want_mask || app_mask) &&
      (XR_FAILED(next->nextGetInstanceProcAddr(*instance, "xrGetVisibilityMaskKHR",
                                               reinterpret_cast<PFN_xrVoidFunction*>(&state.get_visibility_mask))) ||
       !state.get_visibility_mask)) {
    FOVEA_LAYER_WARN("%s enabled but xrGetVisibilityMaskKHR missing below: every view pixel is traced",
                     kVisibilityMaskExtension);
    state.get_visibility_mask = nullptr;
  }
  state.visibility_mask_hidden = mask_hidden;
  state.timespec_hidden = timespec_hidden;
  if ((want_timespec || enabled(kConvertTimespecExtension)) &&
      (XR_FAILED(next->nextGetInstanceProcAddr(*instance, "xrConvertTimeToTimespecTimeKHR",
                                               reinterpret_cast<PFN_xrVoidFunction*>(&state.to_timespec))) ||
       !state.to_timespec)) {
    FOVEA_LAYER_WARN("%s enabled but xrConvertTimeToTimespecTimeKHR missing below: layer_timing.jsonl keeps the "
                     "runtime's XrTime values", kConvertTimespecExtension);
    state.to_timespec = nullptr;
  }
  state.gaze_hidden = gaze_hidden;
  if (want_gaze) try {
      state.gaze = create_eye_gaze_actions(state.next, *instance);
      // OpenXR 1.0's top-level user paths, and the eye tracker's when the application enabled it.
      std::vector<const char*> users = {"/user/hand/left", "/user/hand/right", "/user/head", "/user/gamepad",
                                        "/user/treadmill"};
      if (!gaze_hidden) users.push_back(kEyeGazeUser);
      for (const char* u : users) {
        XrPath p = XR_NULL_PATH;
        if (XR_SUCCEEDED(state.next.xrStringToPath(*instance, u, &p))) state.app_user_paths.push_back(p);
      }
    } catch (const std::exception& e) {
      FOVEA_LAYER_WARN("eye-gaze action unavailable, gaze from FOVEA_GAZE: %s", e.what());
    }
  {
    std::lock_guard lock(layer().mutex);
    layer().instances[*instance] = state;
    layer().last_instance = *instance;
  }
  FOVEA_LAYER_INFO("instance created for \"%s\" (%s %s; layers below: %s)", info->applicationInfo.applicationName,
                   kLayerExtension, ours ? "enabled" : "not enabled",
                   next->next ? next->next->layerName : "none");
  return r;
}

Layer& layer() {
  static Layer l;
  return l;
}

const Dispatch* next_for_session(XrSession session) {
  Layer& l = layer();
  auto s = l.sessions.find(session);
  auto i = l.instances.find(s != l.sessions.end() ? s->second.instance : l.last_instance);
  return i == l.instances.end() ? nullptr : &i->second.next;
}

XrResult intercept::xrDestroyInstance(XrInstance instance) {
  PFN_xrDestroyInstance next = nullptr;
  std::vector<std::shared_ptr<FrameRenderer>> renderers;
  {
    // What the layer created on the instance's handles goes first, while they are alive: the
    // sessions' renderers (swapchains, frees on the application's device), eye-gaze spaces
    // and the eye-gaze action set. The instance's table stays until the call down returns.
    std::lock_guard lock(layer().mutex);
    auto it = layer().instances.find(instance);
    if (it == layer().instances.end()) return XR_ERROR_HANDLE_INVALID;
    const Dispatch& d = it->second.next;
    for (auto& [handle, session] : layer().sessions)
      if (session.instance == instance) renderers.push_back(release_session(session, d));
    destroy_eye_gaze_actions(d, it->second.gaze);
    next = d.xrDestroyInstance;
  }
  renderers.clear();  // joins the render threads, destroys their swapchains while the instance lives
  const XrResult r = next(instance);
  if (XR_SUCCEEDED(r)) {
    std::lock_guard lock(layer().mutex);
    Layer& l = layer();
    for (auto it = l.sessions.begin(); it != l.sessions.end();) {
      if (it->second.instance != instance) {
        ++it;
        continue;
      }
      for (auto sc = l.swapchains.begin(); sc != l.swapchains.end();)
        sc = sc->second.session == it->first ? l.swapchains.erase(sc) : std::next(sc);
      it = l.sessions.erase(it);
    }
    for (auto as = l.action_sets.begin(); as != l.action_sets.end();)
      as = as->second == instance ? l.action_sets.erase(as) : std::next(as);
    l.instances.erase(instance);
    if (l.last_instance == instance) l.last_instance = l.instances.empty() ? XR_NULL_HANDLE : l.instances.rbegin()->first;
  }
  return r;
}

}  // namespace fovea::layer

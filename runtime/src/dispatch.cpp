// Loader negotiation and xrGetInstanceProcAddr: the runtime's only ways in.
#include <cstring>

#include "api.hpp"
#include "fovea/xrcommon/loader_interface.hpp"
#include "state.hpp"

namespace fovea::runtime {
namespace {

struct Entry {
  const char* name;
  PFN_xrVoidFunction fn;
  const char* extension;
};

#define FOVEA_RUNTIME_ENTRY(name, ext) {#name, reinterpret_cast<PFN_xrVoidFunction>(&api::name), ext},
const Entry kEntries[] = {FOVEA_RUNTIME_COMMANDS(FOVEA_RUNTIME_ENTRY)};
#undef FOVEA_RUNTIME_ENTRY

const Entry* lookup(const char* name) {
  for (const Entry& e : kEntries)
    if (!std::strcmp(e.name, name)) return &e;
  return nullptr;
}

}  // namespace

XrResult api::xrGetInstanceProcAddr(XrInstance instance, const char* name, PFN_xrVoidFunction* function) {
  return guarded(__func__, [&]() -> XrResult {
    if (!name || !function) return XR_ERROR_VALIDATION_FAILURE;
    *function = nullptr;
    const Entry* e = lookup(name);
    if (instance == XR_NULL_HANDLE) {
      // Without an instance only these three may be queried (core spec, xrGetInstanceProcAddr).
      if (!std::strcmp(name, "xrEnumerateInstanceExtensionProperties") ||
          !std::strcmp(name, "xrEnumerateApiLayerProperties") || !std::strcmp(name, "xrCreateInstance")) {
        *function = e->fn;
        return XR_SUCCESS;
      }
      return XR_ERROR_HANDLE_INVALID;
    }
    const Instance* inst = find<Instance>(instance);
    if (!inst) return XR_ERROR_HANDLE_INVALID;
    if (!e || (e->extension && !inst->has(e->extension))) return XR_ERROR_FUNCTION_UNSUPPORTED;
    *function = e->fn;
    return XR_SUCCESS;
  });
}

}  // namespace fovea::runtime

extern "C" __attribute__((visibility("default"))) XrResult xrNegotiateLoaderRuntimeInterface(
    const XrNegotiateLoaderInfo* loaderInfo, XrNegotiateRuntimeRequest* runtimeRequest) {
  if (!loaderInfo || !runtimeRequest) return XR_ERROR_INITIALIZATION_FAILED;
  if (loaderInfo->structType != XR_LOADER_INTERFACE_STRUCT_LOADER_INFO ||
      loaderInfo->structVersion != XR_LOADER_INFO_STRUCT_VERSION ||
      loaderInfo->structSize != sizeof(XrNegotiateLoaderInfo))
    return XR_ERROR_INITIALIZATION_FAILED;
  if (runtimeRequest->structType != XR_LOADER_INTERFACE_STRUCT_RUNTIME_REQUEST ||
      runtimeRequest->structVersion != XR_RUNTIME_INFO_STRUCT_VERSION ||
      runtimeRequest->structSize != sizeof(XrNegotiateRuntimeRequest))
    return XR_ERROR_INITIALIZATION_FAILED;
  if (loaderInfo->minInterfaceVersion > XR_CURRENT_LOADER_RUNTIME_VERSION ||
      loaderInfo->maxInterfaceVersion < XR_CURRENT_LOADER_RUNTIME_VERSION)
    return XR_ERROR_INITIALIZATION_FAILED;
  // Any 1.x loader: the runtime implements OpenXR 1.0.
  if (XR_VERSION_MAJOR(loaderInfo->minApiVersion) > 1 || XR_VERSION_MAJOR(loaderInfo->maxApiVersion) < 1)
    return XR_ERROR_INITIALIZATION_FAILED;
  runtimeRequest->runtimeInterfaceVersion = XR_CURRENT_LOADER_RUNTIME_VERSION;
  runtimeRequest->runtimeApiVersion = XR_CURRENT_API_VERSION;
  runtimeRequest->getInstanceProcAddr = &fovea::runtime::api::xrGetInstanceProcAddr;
  return XR_SUCCESS;
}

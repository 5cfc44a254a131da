// A test API layer, enabled below XR_APILAYER_FOVEA_path_tracing: it forwards everything and
// appends what the Fovea layer sends down to the file $FOVEA_TEST_RECORD, one line per call:
//   create_swapchain H | destroy_swapchain H | destroy_session H | destroy_instance H
//   end_frame projection=T,T view=T,T view=T,T   (the next chains' structure types)
// For one instance at a time (the tests create one).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <openxr/openxr.h>

#include "fovea/xrcommon/loader_interface.hpp"

namespace {

constexpr const char* kName = "XR_APILAYER_FOVEA_test_recorder";

PFN_xrGetInstanceProcAddr g_next_gipa = nullptr;
PFN_xrCreateSwapchain g_create_swapchain = nullptr;
PFN_xrDestroySwapchain g_destroy_swapchain = nullptr;
PFN_xrDestroySession g_destroy_session = nullptr;
PFN_xrDestroyInstance g_destroy_instance = nullptr;
PFN_xrEndFrame g_end_frame = nullptr;

void record(const std::string& line) {
  const char* path = std::getenv("FOVEA_TEST_RECORD");
  if (!path) return;
  if (FILE* f = std::fopen(path, "a")) {
    std::fprintf(f, "%s\n", line.c_str());
    std::fclose(f);
  }
}

template <class H>
std::string id(H h) {
  return std::to_string(reinterpret_cast<std::uint64_t>(h));
}

std::string types(const void* chain) {
  std::string out;
  for (auto* p = static_cast<const XrBaseInStructure*>(chain); p; p = p->next)
    out += (out.empty() ? "" : ",") + std::to_string(int(p->type));
  return out;
}

XrResult XRAPI_CALL create_swapchain(XrSession s, const XrSwapchainCreateInfo* ci, XrSwapchain* out) {
  const XrResult r = g_create_swapchain(s, ci, out);
  if (XR_SUCCEEDED(r)) record("create_swapchain " + id(*out));
  return r;
}
XrResult XRAPI_CALL destroy_swapchain(XrSwapchain h) {
  record("destroy_swapchain " + id(h));
  return g_destroy_swapchain(h);
}
XrResult XRAPI_CALL destroy_session(XrSession h) {
  record("destroy_session " + id(h));
  return g_destroy_session(h);
}
XrResult XRAPI_CALL destroy_instance(XrInstance h) {
  record("destroy_instance " + id(h));
  return g_destroy_instance(h);
}
XrResult XRAPI_CALL end_frame(XrSession s, const XrFrameEndInfo* info) {
  std::string line = "end_frame";
  for (uint32_t i = 0; info && info->layers && i < info->layerCount; ++i) {
    if (!info->layers[i] || info->layers[i]->type != XR_TYPE_COMPOSITION_LAYER_PROJECTION) continue;
    const auto* p = reinterpret_cast<const XrCompositionLayerProjection*>(info->layers[i]);
    line += " projection=" + types(p->next);
    for (uint32_t v = 0; p->views && v < p->viewCount; ++v) line += " view=" + types(p->views[v].next);
  }
  record(line);
  return g_end_frame(s, info);
}

XrResult XRAPI_CALL gipa(XrInstance instance, const char* name, PFN_xrVoidFunction* fn) {
  if (!g_next_gipa) {  // asked before any instance exists: this layer has nothing to offer
    *fn = nullptr;
    return XR_ERROR_FUNCTION_UNSUPPORTED;
  }
  const XrResult r = g_next_gipa(instance, name, fn);
  if (XR_FAILED(r)) return r;
  const std::string n = name;
  if (n == "xrGetInstanceProcAddr") *fn = reinterpret_cast<PFN_xrVoidFunction>(&gipa);
  if (n == "xrCreateSwapchain") *fn = reinterpret_cast<PFN_xrVoidFunction>(&create_swapchain);
  if (n == "xrDestroySwapchain") *fn = reinterpret_cast<PFN_xrVoidFunction>(&destroy_swapchain);
  if (n == "xrDestroySession") *fn = reinterpret_cast<PFN_xrVoidFunction>(&destroy_session);
  if (n == "xrDestroyInstance") *fn = reinterpret_cast<PFN_xrVoidFunction>(&destroy_instance);
  if (n == "xrEndFrame") *fn = reinterpret_cast<PFN_xrVoidFunction>(&end_frame);
  return r;
}

template <class PFN>
bool resolve(XrInstance instance, const char* name, PFN& out) {
  return XR_SUCCEEDED(g_next_gipa(instance, name, reinterpret_cast<PFN_xrVoidFunction*>(&out))) && out;
}

XrResult XRAPI_CALL create_instance(const XrInstanceCreateInfo* info, const XrApiLayerCreateInfo* layer_info,
                                    XrInstance* instance) {
  const XrApiLayerNextInfo* next = layer_info->nextInfo;
  if (!next || std::strcmp(next->layerName, kName) != 0) return XR_ERROR_INITIALIZATION_FAILED;
  XrApiLayerCreateInfo down = *layer_info;
  down.nextInfo = next->next;
  const XrResult r = next->nextCreateApiLayerInstance(info, &down, instance);
  if (XR_FAILED(r)) return r;
  g_next_gipa = next->nextGetInstanceProcAddr;
  if (!resolve(*instance, "xrCreateSwapchain", g_create_swapchain) ||
      !resolve(*instance, "xrDestroySwapchain", g_destroy_swapchain) ||
      !resolve(*instance, "xrDestroySession", g_destroy_session) ||
      !resolve(*instance, "xrDestroyInstance", g_destroy_instance) || !resolve(*instance, "xrEndFrame", g_end_frame))
    return XR_ERROR_INITIALIZATION_FAILED;
  return r;
}

}  // namespace

extern "C" __attribute__((visibility("default"))) XrResult xrNegotiateLoaderApiLayerInterface(
    const XrNegotiateLoaderInfo*, const char* layer_name, XrNegotiateApiLayerRequest* request) {
  if (!layer_name || std::strcmp(layer_name, kName) != 0 || !request) return XR_ERROR_INITIALIZATION_FAILED;
  request->layerInterfaceVersion = XR_CURRENT_LOADER_API_LAYER_VERSION;
  request->layerApiVersion = XR_CURRENT_API_VERSION;
  request->getInstanceProcAddr = &gipa;
  request->createApiLayerInstance = &create_instance;
  return XR_SUCCESS;
}

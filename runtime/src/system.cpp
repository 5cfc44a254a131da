// The simulated HMD as an XrSystem: form factor, properties, view configuration (from the
// display preset), blend modes and the visibility mask.
#include <cstdio>

#include <openxr/openxr_reflection.h>

#include "api.hpp"
#include "state.hpp"
#include "visibility_mask.hpp"

namespace fovea::runtime {
namespace {

bool valid_view_config(XrViewConfigurationType t) {
  switch (t) {
#define FOVEA_CASE(n, v) case n:
    XR_LIST_ENUM_XrViewConfigurationType(FOVEA_CASE)
#undef FOVEA_CASE
    return t != XR_VIEW_CONFIGURATION_TYPE_MAX_ENUM;
    default: return false;
  }
}

// XR_SUCCESS for the supported configuration, else the error the spec asks for.
XrResult check_view_config(XrViewConfigurationType t) {
  if (!valid_view_config(t)) return XR_ERROR_VALIDATION_FAILURE;
  return t == XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO ? XR_SUCCESS : XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED;
}

// Instance with a queried system, or the result code explaining why not.
XrResult system_of(XrInstance instance, XrSystemId system, Instance** out) {
  Instance* inst = find<Instance>(instance);
  if (!inst) return XR_ERROR_HANDLE_INVALID;
  if (system != kSystemId) return XR_ERROR_SYSTEM_INVALID;
  *out = inst;
  return XR_SUCCESS;
}

}  // namespace

XrResult api::xrGetSystem(XrInstance instance, const XrSystemGetInfo* getInfo, XrSystemId* systemId) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = find<Instance>(instance);
    if (!inst) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(getInfo, XR_TYPE_SYSTEM_GET_INFO) || !systemId) return XR_ERROR_VALIDATION_FAILURE;
    // Any other value, known or not (the CTS passes XR_FORM_FACTOR_MAX_ENUM), is a form
    // factor this runtime does not support.
    if (getInfo->formFactor != XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY) return XR_ERROR_FORM_FACTOR_UNSUPPORTED;
    inst->system_queried = true;
    *systemId = kSystemId;
    return XR_SUCCESS;
  });
}

XrResult api::xrGetSystemProperties(XrInstance instance, XrSystemId systemId, XrSystemProperties* props) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = nullptr;
    if (XrResult r = system_of(instance, systemId, &inst); r != XR_SUCCESS) return r;
    if (!has_type(props, XR_TYPE_SYSTEM_PROPERTIES)) return XR_ERROR_VALIDATION_FAILURE;
    props->systemId = kSystemId;
    props->vendorId = 0;
    std::snprintf(props->systemName, sizeof props->systemName, "Fovea simulated HMD (%s)", inst->display.name.c_str());
    props->graphicsProperties.maxSwapchainImageWidth = kMaxSwapchainSize;
    props->graphicsProperties.maxSwapchainImageHeight = kMaxSwapchainSize;
    props->graphicsProperties.maxLayerCount = kMaxLayers;
    props->trackingProperties.orientationTracking = XR_TRUE;
    props->trackingProperties.positionTracking = XR_TRUE;
    if (auto* gaze = find_next<XrSystemEyeGazeInteractionPropertiesEXT>(
            props->next, XR_TYPE_SYSTEM_EYE_GAZE_INTERACTION_PROPERTIES_EXT))
      gaze->supportsEyeGazeInteraction = inst->has(XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME) ? XR_TRUE : XR_FALSE;
    return XR_SUCCESS;
  });
}

XrResult api::xrEnumerateViewConfigurations(XrInstance instance, XrSystemId systemId, uint32_t capacity,
                                            uint32_t* count, XrViewConfigurationType* types) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = nullptr;
    if (XrResult r = system_of(instance, systemId, &inst); r != XR_SUCCESS) return r;
    return two_call(capacity, count, types,
                    std::vector<XrViewConfigurationType>{XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO});
  });
}

XrResult api::xrGetViewConfigurationProperties(XrInstance instance, XrSystemId systemId,
                                               XrViewConfigurationType type, XrViewConfigurationProperties* props) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = nullptr;
    if (XrResult r = system_of(instance, systemId, &inst); r != XR_SUCCESS) return r;
    if (!has_type(props, XR_TYPE_VIEW_CONFIGURATION_PROPERTIES)) return XR_ERROR_VALIDATION_FAILURE;
    if (XrResult r = check_view_config(type); r != XR_SUCCESS) return r;
    props->viewConfigurationType = type;
    props->fovMutable = XR_TRUE;
    return XR_SUCCESS;
  });
}

XrResult api::xrEnumerateViewConfigurationViews(XrInstance instance, XrSystemId systemId,
                                                XrViewConfigurationType type, uint32_t capacity, uint32_t* count,
                                                XrViewConfigurationView* views) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = nullptr;
    if (XrResult r = system_of(instance, systemId, &inst); r != XR_SUCCESS) return r;
    if (XrResult r = check_view_config(type); r != XR_SUCCESS) return r;
    if (!count || (capacity && !views)) return XR_ERROR_VALIDATION_FAILURE;
    *count = 2;
    if (capacity == 0) return XR_SUCCESS;
    if (capacity < 2) return XR_ERROR_SIZE_INSUFFICIENT;
    for (uint32_t i = 0; i < 2; ++i)
      if (views[i].type != XR_TYPE_VIEW_CONFIGURATION_VIEW) return XR_ERROR_VALIDATION_FAILURE;
    for (uint32_t i = 0; i < 2; ++i) {
      views[i].recommendedImageRectWidth = uint32_t(inst->display.width);
      views[i].recommendedImageRectHeight = uint32_t(inst->display.height);
      views[i].maxImageRectWidth = kMaxSwapchainSize;
      views[i].maxImageRectHeight = kMaxSwapchainSize;
      views[i].recommendedSwapchainSampleCount = 1;
      views[i].maxSwapchainSampleCount = 1;
    }
    return XR_SUCCESS;
  });
}

XrResult api::xrEnumerateEnvironmentBlendModes(XrInstance instance, XrSystemId systemId,
                                               XrViewConfigurationType type, uint32_t capacity, uint32_t* count,
                                               XrEnvironmentBlendMode* modes) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = nullptr;
    if (XrResult r = system_of(instance, systemId, &inst); r != XR_SUCCESS) return r;
    if (XrResult r = check_view_config(type); r != XR_SUCCESS) return r;
    return two_call(capacity, count, modes, std::vector<XrEnvironmentBlendMode>{XR_ENVIRONMENT_BLEND_MODE_OPAQUE});
  });
}

XrResult api::xrGetVisibilityMaskKHR(XrSession session, XrViewConfigurationType type, uint32_t viewIndex,
                                     XrVisibilityMaskTypeKHR maskType, XrVisibilityMaskKHR* mask) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (XrResult r = check_view_config(type); r != XR_SUCCESS) return r;
    if (viewIndex >= 2) return XR_ERROR_VALIDATION_FAILURE;
    if (maskType < XR_VISIBILITY_MASK_TYPE_HIDDEN_TRIANGLE_MESH_KHR || maskType > XR_VISIBILITY_MASK_TYPE_LINE_LOOP_KHR)
      return XR_ERROR_VALIDATION_FAILURE;
    if (!has_type(mask, XR_TYPE_VISIBILITY_MASK_KHR)) return XR_ERROR_VALIDATION_FAILURE;
    if ((mask->vertexCapacityInput && !mask->vertices) || (mask->indexCapacityInput && !mask->indices))
      return XR_ERROR_VALIDATION_FAILURE;
    const VisibilityMask m = visibility_mask(*s->instance->hidden[viewIndex], maskType);
    mask->vertexCountOutput = uint32_t(m.vertices.size());
    mask->indexCountOutput = uint32_t(m.indices.size());
    FOVEA_LOG_INFO("visibility mask: view %u type %d: %zu vertices, %zu indices (lens: %s)", viewIndex, int(maskType),
                   m.vertices.size(), m.indices.size(),
                   core::lens_model_name(s->instance->hidden[viewIndex]->lens().kind()));
    // Either capacity 0 makes the call a size query (XR_KHR_visibility_mask).
    if (mask->vertexCapacityInput == 0 || mask->indexCapacityInput == 0) return XR_SUCCESS;
    if (mask->vertexCapacityInput < m.vertices.size() || mask->indexCapacityInput < m.indices.size())
      return XR_ERROR_SIZE_INSUFFICIENT;
    std::copy(m.vertices.begin(), m.vertices.end(), mask->vertices);
    std::copy(m.indices.begin(), m.indices.end(), mask->indices);
    return XR_SUCCESS;
  });
}

}  // namespace fovea::runtime

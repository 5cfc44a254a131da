#pragma once
// OpenXR with the platform pieces this runtime implements (Vulkan, timespec).
// XR_NO_PROTOTYPES is defined for the runtime target: it must never call the loader.
#include <time.h>
#include <vulkan/vulkan.h>

#define XR_USE_GRAPHICS_API_VULKAN
#define XR_USE_TIMESPEC
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

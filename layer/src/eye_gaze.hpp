#pragma once
// The layer's own eye-gaze input (XR_EXT_eye_gaze_interaction), used when a scene is
// configured and the runtime offers the extension: an action set with one pose action bound
// to /user/eyes_ext/input/gaze_ext/pose, merged into the application's
// xrSuggestInteractionProfileBindings (for the eye-gaze profile), xrAttachSessionActionSets
// and xrSyncActions. The gaze is located in VIEW space at each frame's display time.
// The application does not see it (actions.cpp): an extension it did not enable stays
// unsupported for it, and what the layer's binding changes (the eye-gaze profile becoming
// current, its change event) is answered and filtered as without the layer.

#define XR_USE_GRAPHICS_API_VULKAN
#include <vulkan/vulkan.h>
#include <openxr/openxr.h>

#include "gaze_input.hpp"

namespace fovea::layer {

struct Dispatch;

constexpr const char* kEyeGazeExtension = "XR_EXT_eye_gaze_interaction";
constexpr const char* kEyeGazeProfile = "/interaction_profiles/ext/eye_gaze_interaction";
constexpr const char* kEyeGazePath = "/user/eyes_ext/input/gaze_ext/pose";
constexpr const char* kEyeGazeUser = "/user/eyes_ext";

// Per instance: created after xrCreateInstance when the extension was enabled below.
struct EyeGazeActions {
  XrActionSet set = XR_NULL_HANDLE;
  XrAction pose = XR_NULL_HANDLE;
  XrPath profile = XR_NULL_PATH, binding = XR_NULL_PATH;
  XrPath user = XR_NULL_PATH;  // /user/eyes_ext
  bool valid() const { return pose != XR_NULL_HANDLE; }
};

// Per session, after an attach that included the layer's set.
struct EyeGazeSession {
  XrSpace gaze = XR_NULL_HANDLE, view = XR_NULL_HANDLE;
  bool attached() const { return gaze != XR_NULL_HANDLE; }
};

// Creates the action set and action and suggests the binding; throws std::runtime_error
// after destroying whatever it had created.
EyeGazeActions create_eye_gaze_actions(const Dispatch& next, XrInstance instance);
void destroy_eye_gaze_actions(const Dispatch& next, EyeGazeActions& a);
// The spaces for a session whose attach included the set; throws std::runtime_error.
EyeGazeSession create_eye_gaze_session(const Dispatch& next, const EyeGazeActions& a, XrSession session);
void destroy_eye_gaze_session(const Dispatch& next, EyeGazeSession& s);
// The gaze direction in VIEW space at `time` (nullopt when not tracked) and the time of the
// tracker sample behind it.
ActionGaze locate_eye_gaze(const Dispatch& next, const EyeGazeSession& s, XrTime time);

}  // namespace fovea::layer

#include "eye_gaze.hpp"

#include <cstdio>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "layer.hpp"

namespace fovea::layer {
namespace {

void check(XrResult r, const char* what) {
  if (XR_FAILED(r)) throw std::runtime_error(std::string(what) + " failed below the layer: XrResult " + std::to_string(int(r)));
}

}  // namespace

EyeGazeActions create_eye_gaze_actions(const Dispatch& next, XrInstance instance) {
  EyeGazeActions a;
  // Action set names and localized names are unique per instance, so a fixed name could
  // collide with the application's (XR_ERROR_NAME_DUPLICATED, or
  // XR_ERROR_LOCALIZED_NAME_DUPLICATED for its localized name): both carry 64 random bits
  // drawn per instance, which no application can guess.
  std::random_device entropy;
  const unsigned long long tag = (static_cast<unsigned long long>(entropy()) << 32) ^ entropy();
  XrActionSetCreateInfo si{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::snprintf(si.actionSetName, sizeof si.actionSetName, "xr_apilayer_fovea_gaze_%016llx", tag);
  std::snprintf(si.localizedActionSetName, sizeof si.localizedActionSetName, "Fovea layer eye gaze %016llx", tag);
  check(next.xrCreateActionSet(instance, &si, &a.set), "xrCreateActionSet");
  // A later step's failure must not leave the set (and its action) behind in the runtime.
  struct SetGuard {
    const Dispatch& next;
    XrActionSet set;
    ~SetGuard() {
      if (set != XR_NULL_HANDLE) next.xrDestroyActionSet(set);
    }
  } guard{next, a.set};
  XrActionCreateInfo ai{XR_TYPE_ACTION_CREATE_INFO};
  ai.actionType = XR_ACTION_TYPE_POSE_INPUT;
  std::strcpy(ai.actionName, "gaze");
  std::strcpy(ai.localizedActionName, "Eye gaze");
  check(next.xrCreateAction(a.set, &ai, &a.pose), "xrCreateAction");
  check(next.xrStringToPath(instance, kEyeGazeProfile, &a.profile), "xrStringToPath");
  check(next.xrStringToPath(instance, kEyeGazePath, &a.binding), "xrStringToPath");
  check(next.xrStringToPath(instance, kEyeGazeUser, &a.user), "xrStringToPath");
  const XrActionSuggestedBinding b{a.pose, a.binding};
  XrInteractionProfileSuggestedBinding sb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
  sb.interactionProfile = a.profile;
  sb.countSuggestedBindings = 1;
  sb.suggestedBindings = &b;
  check(next.xrSuggestInteractionProfileBindings(instance, &sb), "xrSuggestInteractionProfileBindings");
  guard.set = XR_NULL_HANDLE;
  return a;
}

void destroy_eye_gaze_actions(const Dispatch& next, EyeGazeActions& a) {
  if (a.set != XR_NULL_HANDLE) next.xrDestroyActionSet(a.set);  // its action goes with it
  a = {};
}

void destroy_eye_gaze_session(const Dispatch& next, EyeGazeSession& s) {
  for (XrSpace space : {s.gaze, s.view})
    if (space != XR_NULL_HANDLE) next.xrDestroySpace(space);
  s = {};
}

EyeGazeSession create_eye_gaze_session(const Dispatch& next, const EyeGazeActions& a, XrSession session) {
  EyeGazeSession s;
  XrActionSpaceCreateInfo ai{XR_TYPE_ACTION_SPACE_CREATE_INFO};
  ai.action = a.pose;
  ai.poseInActionSpace.orientation.w = 1;
  check(next.xrCreateActionSpace(session, &ai, &s.gaze), "xrCreateActionSpace");
  XrReferenceSpaceCreateInfo ri{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  ri.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_VIEW;
  ri.poseInReferenceSpace.orientation.w = 1;
  if (XR_FAILED(next.xrCreateReferenceSpace(session, &ri, &s.view))) {
    next.xrDestroySpace(s.gaze);
    throw std::runtime_error("xrCreateReferenceSpace(VIEW) failed below the layer");
  }
  return s;
}

ActionGaze locate_eye_gaze(const Dispatch& next, const EyeGazeSession& s, XrTime time) {
  XrEyeGazeSampleTimeEXT when{XR_TYPE_EYE_GAZE_SAMPLE_TIME_EXT};
  XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
  loc.next = &when;
  ActionGaze g;
  if (XR_FAILED(next.xrLocateSpace(s.gaze, s.view, time, &loc))) return g;
  const XrSpaceLocationFlags need = XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT;
  if ((loc.locationFlags & need) != need) return g;
  const auto& q = loc.pose.orientation;
  // The gaze ray is the pose's -Z axis (XR_EXT_eye_gaze_interaction).
  g.dir = glm::dquat(q.w, q.x, q.y, q.z) * glm::dvec3(0, 0, -1);
  g.sample_time_ns = when.time;
  return g;
}

}  // namespace fovea::layer

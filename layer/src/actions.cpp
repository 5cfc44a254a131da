// Action intercepts: the layer's eye-gaze action set (eye_gaze.hpp) rides along in the
// application's suggestions for the eye-gaze profile, its attach and its syncs. Without the
// layer's action (no scene, or the runtime lacks the extension) the calls go down unchanged.
#include <algorithm>
#include <vector>

#include "layer.hpp"
#include "log.hpp"

namespace fovea::layer {
namespace {

struct Lookup {
  const Dispatch* next = nullptr;
  EyeGazeActions gaze;
};

Lookup for_instance(XrInstance instance) {
  std::lock_guard lock(layer().mutex);
  auto it = layer().instances.find(instance);
  if (it == layer().instances.end()) return {};
  return {&it->second.next, it->second.gaze};
}

Lookup for_session(XrSession session) {
  std::lock_guard lock(layer().mutex);
  auto s = layer().sessions.find(session);
  if (s == layer().sessions.end() || s->second.disabled || !s->second.renderer) return {next_for_session(session), {}};
  auto it = layer().instances.find(s->second.instance);
  return {next_for_session(session), it == layer().instances.end() ? EyeGazeActions{} : it->second.gaze};
}

}  // namespace

// A later suggestion for a profile replaces the earlier one: the application's suggestion
// for the eye-gaze profile gets the layer's binding added.
XrResult intercept::xrSuggestInteractionProfileBindings(XrInstance instance,
                                                        const XrInteractionProfileSuggestedBinding* info) {
  const Lookup l = for_instance(instance);
  if (!l.next) return XR_ERROR_HANDLE_INVALID;
  if (!l.gaze.valid() || !info || info->type != XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING ||
      info->interactionProfile != l.gaze.profile || !info->suggestedBindings)
    return l.next->xrSuggestInteractionProfileBindings(instance, info);
  std::vector<XrActionSuggestedBinding> merged(info->suggestedBindings,
                                               info->suggestedBindings + info->countSuggestedBindings);
  merged.push_back({l.gaze.pose, l.gaze.binding});
  XrInteractionProfileSuggestedBinding down = *info;
  down.countSuggestedBindings = std::uint32_t(merged.size());
  down.suggestedBindings = merged.data();
  const XrResult r = l.next->xrSuggestInteractionProfileBindings(instance, &down);
  // The application's own mistake is reported for its own arguments.
  return XR_FAILED(r) ? l.next->xrSuggestInteractionProfileBindings(instance, info) : r;
}

XrResult intercept::xrAttachSessionActionSets(XrSession session, const XrSessionActionSetsAttachInfo* info) {
  const Lookup l = for_session(session);
  if (!l.next) return XR_ERROR_HANDLE_INVALID;
  if (!l.gaze.valid() || !info || info->type != XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO)
    return l.next->xrAttachSessionActionSets(session, info);
  std::vector<XrActionSet> sets(info->actionSets, info->actionSets + (info->actionSets ? info->countActionSets : 0));
  sets.push_back(l.gaze.set);
  XrSessionActionSetsAttachInfo down = *info;
  down.countActionSets = std::uint32_t(sets.size());
  down.actionSets = sets.data();
  XrResult r = l.next->xrAttachSessionActionSets(session, &down);
  if (XR_FAILED(r)) return l.next->xrAttachSessionActionSets(session, info);  // the application's own error
  std::lock_guard lock(layer().mutex);
  auto s = layer().sessions.find(session);
  if (s == layer().sessions.end()) return r;
  try {
    s->second.gaze = create_eye_gaze_session(*l.next, l.gaze, session);
    FOVEA_LAYER_INFO("gaze: the eye-gaze action (%s), merged into the application's action sets", kEyeGazePath);
  } catch (const std::exception& e) {
    FOVEA_LAYER_WARN("eye-gaze action spaces unavailable, gaze from FOVEA_GAZE: %s", e.what());
  }
  return r;
}

XrResult intercept::xrSyncActions(XrSession session, const XrActionsSyncInfo* info) {
  const Lookup l = for_session(session);
  if (!l.next) return XR_ERROR_HANDLE_INVALID;
  bool attached = false;
  {
    std::lock_guard lock(layer().mutex);
    auto s = layer().sessions.find(session);
    attached = s != layer().sessions.end() && s->second.gaze.attached();
  }
  if (!attached || !l.gaze.valid() || !info || info->type != XR_TYPE_ACTIONS_SYNC_INFO)
    return l.next->xrSyncActions(session, info);
  std::vector<XrActiveActionSet> sets(info->activeActionSets,
                                      info->activeActionSets + (info->activeActionSets ? info->countActiveActionSets : 0));
  sets.push_back({l.gaze.set, XR_NULL_PATH});
  XrActionsSyncInfo down = *info;
  down.countActiveActionSets = std::uint32_t(sets.size());
  down.activeActionSets = sets.data();
  const XrResult r = l.next->xrSyncActions(session, &down);
  return XR_FAILED(r) ? l.next->xrSyncActions(session, info) : r;
}

}  // namespace fovea::layer

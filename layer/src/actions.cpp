// Action intercepts: the layer's eye-gaze action set (eye_gaze.hpp) rides along in the
// application's suggestions for the eye-gaze profile, its attach and its syncs, and the
// application's eye-gaze queries are answered as without the layer. Without the layer's
// action (no scene, or the runtime lacks the extension) the calls go down unchanged.
//
// Attach semantics: the layer's set is attached only inside a valid attach of the
// application's (at least one set), so an attach the runtime refuses is refused with the
// runtime's code, and an application that attaches later still can. An application that
// never attaches leaves the layer without the action: its gaze then comes from FOVEA_GAZE or
// stays at the view centre (attaching on the application's behalf would make its own later
// attach fail with XR_ERROR_ACTIONSETS_ALREADY_ATTACHED).
#include <algorithm>
#include <vector>

#include "layer.hpp"
#include "log.hpp"

namespace fovea::layer {
namespace {

struct Lookup {
  const Dispatch* next = nullptr;
  EyeGazeActions gaze;
  bool gaze_hidden = false, app_suggested_gaze = false;
  std::vector<XrPath> app_user_paths;
};

Lookup lookup(const InstanceState& i, const Dispatch* next) {
  return {next, i.gaze, i.gaze_hidden, i.app_suggested_gaze, i.app_user_paths};
}

Lookup for_instance(XrInstance instance) {
  std::lock_guard lock(layer().mutex);
  auto it = layer().instances.find(instance);
  if (it == layer().instances.end()) return {};
  return lookup(it->second, &it->second.next);
}

// `rendering`: only while the session renders does the layer's set ride along; what the
// application sees of the extension it did not enable is hidden for the whole instance.
Lookup for_session(XrSession session, bool rendering = true) {
  std::lock_guard lock(layer().mutex);
  auto s = layer().sessions.find(session);
  const auto it = s == layer().sessions.end() ? layer().instances.end() : layer().instances.find(s->second.instance);
  if (it == layer().instances.end()) return {next_for_session(session)};
  Lookup l = lookup(it->second, next_for_session(session));
  if (rendering && (s->second.disabled || !s->second.renderer)) l.gaze = {};
  return l;
}

}  // namespace

// A later suggestion for a profile replaces the earlier one: the application's suggestion
// for the eye-gaze profile gets the layer's binding added.
XrResult intercept::xrSuggestInteractionProfileBindings(XrInstance instance,
                                                        const XrInteractionProfileSuggestedBinding* info) {
  const Lookup l = for_instance(instance);
  if (!l.next) return XR_ERROR_HANDLE_INVALID;
  if (!l.gaze.valid() || !info || info->type != XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING ||
      info->interactionProfile != l.gaze.profile || !info->suggestedBindings || info->countSuggestedBindings == 0)
    return l.next->xrSuggestInteractionProfileBindings(instance, info);
  // The profile of an extension the application did not enable.
  if (l.gaze_hidden) return XR_ERROR_PATH_UNSUPPORTED;
  std::vector<XrActionSuggestedBinding> merged(info->suggestedBindings,
                                               info->suggestedBindings + info->countSuggestedBindings);
  merged.push_back({l.gaze.pose, l.gaze.binding});
  XrInteractionProfileSuggestedBinding down = *info;
  down.countSuggestedBindings = std::uint32_t(merged.size());
  down.suggestedBindings = merged.data();
  XrResult r = l.next->xrSuggestInteractionProfileBindings(instance, &down);
  // The application's own mistake is reported for its own arguments.
  if (XR_FAILED(r)) r = l.next->xrSuggestInteractionProfileBindings(instance, info);
  std::lock_guard lock(layer().mutex);
  auto it = layer().instances.find(instance);
  // A refused suggestion leaves the earlier one in force.
  if (it != layer().instances.end() && XR_SUCCEEDED(r)) it->second.app_suggested_gaze = true;
  return r;
}

// The application's action sets are recorded with their instance, so xrCreateAction knows
// which instance's view of eye gaze applies (an unknown set: the most recent instance's
// table, for the runtime to report).
XrInstance instance_of(XrActionSet set) {
  std::lock_guard lock(layer().mutex);
  const auto it = layer().action_sets.find(set);
  return it != layer().action_sets.end() ? it->second : layer().last_instance;
}

XrResult intercept::xrCreateActionSet(XrInstance instance, const XrActionSetCreateInfo* info, XrActionSet* set) {
  const Lookup l = for_instance(instance);
  if (!l.next) return XR_ERROR_HANDLE_INVALID;
  const XrResult r = l.next->xrCreateActionSet(instance, info, set);
  if (XR_SUCCEEDED(r)) {
    std::lock_guard lock(layer().mutex);
    layer().action_sets[*set] = instance;
  }
  return r;
}

XrResult intercept::xrDestroyActionSet(XrActionSet set) {
  const Lookup l = for_instance(instance_of(set));
  if (!l.next) return XR_ERROR_HANDLE_INVALID;
  const XrResult r = l.next->xrDestroyActionSet(set);
  if (XR_SUCCEEDED(r)) {
    std::lock_guard lock(layer().mutex);
    layer().action_sets.erase(set);
  }
  return r;
}

// /user/eyes_ext is no top-level user path for an application without the extension: an
// action the runtime created with it as a subaction path is destroyed again and the call
// answers XR_ERROR_PATH_UNSUPPORTED (the runtime's earlier checks still answer first).
XrResult intercept::xrCreateAction(XrActionSet set, const XrActionCreateInfo* info, XrAction* action) {
  const Lookup l = for_instance(instance_of(set));
  if (!l.next) return XR_ERROR_HANDLE_INVALID;
  const XrResult r = l.next->xrCreateAction(set, info, action);
  if (XR_FAILED(r) || !l.gaze_hidden || l.gaze.user == XR_NULL_PATH) return r;
  for (uint32_t i = 0; i < info->countSubactionPaths; ++i)
    if (info->subactionPaths[i] == l.gaze.user) {
      l.next->xrDestroyAction(*action);
      *action = XR_NULL_HANDLE;
      return XR_ERROR_PATH_UNSUPPORTED;
    }
  return r;
}

XrResult intercept::xrAttachSessionActionSets(XrSession session, const XrSessionActionSetsAttachInfo* info) {
  const Lookup l = for_session(session);
  if (!l.next) return XR_ERROR_HANDLE_INVALID;
  // Only a valid attach carries the layer's set: with none of the application's, the runtime's
  // refusal stands.
  if (!l.gaze.valid() || !info || info->type != XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO || info->countActionSets == 0 ||
      !info->actionSets)
    return l.next->xrAttachSessionActionSets(session, info);
  std::vector<XrActionSet> sets(info->actionSets, info->actionSets + info->countActionSets);
  sets.push_back(l.gaze.set);
  XrSessionActionSetsAttachInfo down = *info;
  down.countActionSets = std::uint32_t(sets.size());
  down.actionSets = sets.data();
  XrResult r = l.next->xrAttachSessionActionSets(session, &down);
  if (XR_FAILED(r)) return l.next->xrAttachSessionActionSets(session, info);  // the application's own error
  std::lock_guard lock(layer().mutex);
  auto s = layer().sessions.find(session);
  if (s == layer().sessions.end()) return r;
  s->second.app_profiles.assign(l.app_user_paths.size(), XR_NULL_PATH);  // none current before the attach
  try {
    s->second.gaze = create_eye_gaze_session(*l.next, l.gaze, session);
    FOVEA_LAYER_INFO("gaze: the eye-gaze action (%s), merged into the application's action sets", kEyeGazePath);
  } catch (const std::exception& e) {
    FOVEA_LAYER_WARN("eye-gaze action spaces unavailable, gaze from FOVEA_GAZE: %s", e.what());
  }
  return r;
}

// An application without the extension naming /user/eyes_ext as an active set's subaction
// path gets the runtime's answer for a path that is no top-level user path: the layer passes
// its own binding path (/user/eyes_ext/input/gaze_ext/pose, never a top-level user path)
// in its place, so the runtime's own checks, in their order, give the code the application
// would get without the layer.
XrResult intercept::xrSyncActions(XrSession session, const XrActionsSyncInfo* info) {
  const Lookup hidden = for_session(session, false);
  if (!hidden.next) return XR_ERROR_HANDLE_INVALID;
  const Lookup l = for_session(session);
  bool attached = false;
  {
    std::lock_guard lock(layer().mutex);
    auto s = layer().sessions.find(session);
    attached = s != layer().sessions.end() && s->second.gaze.attached();
  }
  const bool well_formed = info && info->type == XR_TYPE_ACTIONS_SYNC_INFO &&
                           (info->activeActionSets || info->countActiveActionSets == 0);
  if (!well_formed) return l.next->xrSyncActions(session, info);
  std::vector<XrActiveActionSet> sets(info->activeActionSets, info->activeActionSets + info->countActiveActionSets);
  bool hides = false;
  if (hidden.gaze_hidden && hidden.gaze.user != XR_NULL_PATH)
    for (XrActiveActionSet& s : sets)
      if (s.subactionPath == hidden.gaze.user) {
        s.subactionPath = hidden.gaze.binding;
        hides = true;
      }
  XrActionsSyncInfo own = *info;
  own.activeActionSets = sets.data();
  if (!attached || !l.gaze.valid()) return l.next->xrSyncActions(session, hides ? &own : info);
  std::vector<XrActiveActionSet> merged = sets;
  merged.push_back({l.gaze.set, XR_NULL_PATH});
  XrActionsSyncInfo down = *info;
  down.countActiveActionSets = std::uint32_t(merged.size());
  down.activeActionSets = merged.data();
  const XrResult r = l.next->xrSyncActions(session, &down);
  return XR_FAILED(r) ? l.next->xrSyncActions(session, hides ? &own : info) : r;
}

namespace {

// The profile the application would see for `user` without the layer: the eye tracker's is
// current through the layer's binding alone unless the application suggested one too.
XrPath app_visible(const Lookup& l, XrPath user, XrPath profile) {
  return user == l.gaze.user && !l.app_suggested_gaze ? XrPath(XR_NULL_PATH) : profile;
}

}  // namespace

XrResult intercept::xrGetCurrentInteractionProfile(XrSession session, XrPath user, XrInteractionProfileState* state) {
  const Lookup l = for_session(session, false);
  if (!l.next) return XR_ERROR_HANDLE_INVALID;
  const bool well_formed = state && state->type == XR_TYPE_INTERACTION_PROFILE_STATE;
  if (!l.gaze.valid() || !well_formed || user != l.gaze.user)
    return l.next->xrGetCurrentInteractionProfile(session, user, state);
  // Not a top-level user path for an application without the extension.
  if (l.gaze_hidden) return XR_ERROR_PATH_UNSUPPORTED;
  const XrResult r = l.next->xrGetCurrentInteractionProfile(session, user, state);
  if (XR_SUCCEEDED(r)) state->interactionProfile = app_visible(l, user, state->interactionProfile);
  return r;
}

// An application that did not enable XR_EXT_eye_gaze_interaction finds no eye-gaze support,
// as the runtime answers without the extension enabled.
XrResult intercept::xrGetSystemProperties(XrInstance instance, XrSystemId system, XrSystemProperties* properties) {
  const Lookup l = for_instance(instance);
  if (!l.next) return XR_ERROR_HANDLE_INVALID;
  const XrResult r = l.next->xrGetSystemProperties(instance, system, properties);
  if (XR_FAILED(r) || !l.gaze_hidden) return r;
  for (auto* n = static_cast<XrBaseOutStructure*>(properties->next); n; n = n->next)
    if (n->type == XR_TYPE_SYSTEM_EYE_GAZE_INTERACTION_PROPERTIES_EXT)
      reinterpret_cast<XrSystemEyeGazeInteractionPropertiesEXT*>(n)->supportsEyeGazeInteraction = XR_FALSE;
  return r;
}

bool layer_caused_profile_change(XrSession session) {
  const Lookup l = for_session(session, false);
  std::vector<XrPath> seen;
  {
    std::lock_guard lock(layer().mutex);
    auto s = layer().sessions.find(session);
    if (!l.next || !l.gaze.valid() || s == layer().sessions.end() || !s->second.gaze.attached()) return false;
    seen = s->second.app_profiles;
  }
  bool changed = false;
  for (std::size_t i = 0; i < l.app_user_paths.size() && i < seen.size(); ++i) {
    XrInteractionProfileState st{XR_TYPE_INTERACTION_PROFILE_STATE};
    if (XR_FAILED(l.next->xrGetCurrentInteractionProfile(session, l.app_user_paths[i], &st))) continue;
    const XrPath now = app_visible(l, l.app_user_paths[i], st.interactionProfile);
    changed |= now != seen[i];
    seen[i] = now;
  }
  std::lock_guard lock(layer().mutex);
  auto s = layer().sessions.find(session);
  if (s != layer().sessions.end()) s->second.app_profiles = seen;
  return !changed;
}

}  // namespace fovea::layer

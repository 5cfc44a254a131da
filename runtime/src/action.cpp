// Actions. The simulated HMD has an eye tracker (XR_EXT_eye_gaze_interaction) and no
// controllers: bindings for the common controller profiles are accepted and validated, but
// those devices are never connected, so their actions stay inactive.
#include <algorithm>
#include <optional>
#include <string>

#include "api.hpp"
#include "state.hpp"

namespace fovea::runtime {
namespace {

constexpr const char* kEyeGazeProfile = "/interaction_profiles/ext/eye_gaze_interaction";
constexpr const char* kEyeGazePose = "/user/eyes_ext/input/gaze_ext/pose";

// An interaction profile of the OpenXR 1.0 specification (section 6.4, "Interaction
// Profile Paths") with its component paths. A component listed without a user path exists
// on every user path of the profile; one prefixed "left:" or "right:" only on that hand.
// Only what 1.0 lists: grip_surface (1.1, XR_EXT_palm_pose) and extension profiles are not
// offered.
struct Profile {
  const char* path;
  std::vector<const char*> users;       // top-level user paths the profile binds
  std::vector<const char*> components;  // relative to the user path
};

const std::vector<Profile>& profiles() {
  static const std::vector<Profile> p = {
      {"/interaction_profiles/khr/simple_controller",
       {"/user/hand/left", "/user/hand/right"},
       {"input/select/click", "input/menu/click", "input/grip/pose", "input/aim/pose", "output/haptic"}},
      {"/interaction_profiles/google/daydream_controller",
       {"/user/hand/left", "/user/hand/right"},
       {"input/select/click", "input/trackpad/x", "input/trackpad/y", "input/trackpad/click", "input/trackpad/touch",
        "input/grip/pose", "input/aim/pose"}},
      {"/interaction_profiles/htc/vive_controller",
       {"/user/hand/left", "/user/hand/right"},
       {"input/system/click", "input/squeeze/click", "input/menu/click", "input/trigger/click", "input/trigger/value",
        "input/trackpad/x", "input/trackpad/y", "input/trackpad/click", "input/trackpad/touch", "input/grip/pose",
        "input/aim/pose", "output/haptic"}},
      {"/interaction_profiles/htc/vive_pro",
       {"/user/head"},
       {"input/system/click", "input/volume_up/click", "input/volume_down/click", "input/mute_mic/click"}},
      {"/interaction_profiles/microsoft/motion_controller",
       {"/user/hand/left", "/user/hand/right"},
       {"input/menu/click", "input/squeeze/click", "input/trigger/value", "input/thumbstick/x", "input/thumbstick/y",
        "input/thumbstick/click", "input/trackpad/x", "input/trackpad/y", "input/trackpad/click",
        "input/trackpad/touch", "input/grip/pose", "input/aim/pose", "output/haptic"}},
      {"/interaction_profiles/microsoft/xbox_controller",
       {"/user/gamepad"},
       {"input/menu/click", "input/view/click", "input/a/click", "input/b/click", "input/x/click", "input/y/click",
        "input/dpad_down/click", "input/dpad_right/click", "input/dpad_up/click", "input/dpad_left/click",
        "input/shoulder_left/click", "input/shoulder_right/click", "input/thumbstick_left/click",
        "input/thumbstick_right/click", "input/trigger_left/value", "input/trigger_right/value",
        "input/thumbstick_left/x", "input/thumbstick_left/y", "input/thumbstick_right/x", "input/thumbstick_right/y",
        "output/haptic_left", "output/haptic_right", "output/haptic_left_trigger", "output/haptic_right_trigger"}},
      {"/interaction_profiles/oculus/go_controller",
       {"/user/hand/left", "/user/hand/right"},
       {"input/system/click", "input/trigger/click", "input/back/click", "input/trackpad/x", "input/trackpad/y",
        "input/trackpad/click", "input/trackpad/touch", "input/grip/pose", "input/aim/pose"}},
      {"/interaction_profiles/oculus/touch_controller",
       {"/user/hand/left", "/user/hand/right"},
       {"left:input/x/click", "left:input/x/touch", "left:input/y/click", "left:input/y/touch", "left:input/menu/click",
        "right:input/a/click", "right:input/a/touch", "right:input/b/click", "right:input/b/touch",
        "right:input/system/click", "input/squeeze/value", "input/trigger/value", "input/trigger/touch",
        "input/thumbstick/x", "input/thumbstick/y", "input/thumbstick/click", "input/thumbstick/touch",
        "input/thumbrest/touch", "input/grip/pose", "input/aim/pose", "output/haptic"}},
      {"/interaction_profiles/valve/index_controller",
       {"/user/hand/left", "/user/hand/right"},
       {"input/system/click", "input/system/touch", "input/a/click", "input/a/touch", "input/b/click", "input/b/touch",
        "input/squeeze/value", "input/squeeze/force", "input/trigger/click", "input/trigger/value",
        "input/trigger/touch", "input/thumbstick/x", "input/thumbstick/y", "input/thumbstick/click",
        "input/thumbstick/touch", "input/trackpad/x", "input/trackpad/y", "input/trackpad/force",
        "input/trackpad/touch", "input/grip/pose", "input/aim/pose", "output/haptic"}},
      {kEyeGazeProfile, {"/user/eyes_ext"}, {"input/gaze_ext/pose"}},
  };
  return p;
}

bool is_top_level_user_path(const std::string& s, bool eye_gaze) {
  return s == "/user/hand/left" || s == "/user/hand/right" || s == "/user/head" || s == "/user/gamepad" ||
         (eye_gaze && s == "/user/eyes_ext");
}

// Action and action-set names: [a-z0-9-_.] only (emptiness is checked separately: it has
// its own error code).
bool well_formed_name(const char* s) {
  for (; *s; ++s)
    if (!((*s >= 'a' && *s <= 'z') || (*s >= '0' && *s <= '9') || *s == '-' || *s == '_' || *s == '.')) return false;
  return true;
}

// The error for a name field: XR_ERROR_NAME_INVALID when empty or unterminated,
// XR_ERROR_PATH_FORMAT_INVALID when not a well-formed path component.
XrResult check_name(const char* s, size_t size) {
  if (!terminated(s, size) || !*s) return XR_ERROR_NAME_INVALID;
  return well_formed_name(s) ? XR_SUCCESS : XR_ERROR_PATH_FORMAT_INVALID;
}

// The full component path a binding path names in the profile: "<user path>/<component>"
// for a component on that user path, or an input identifier without its component
// ("…/input/select"), which the specification lets the runtime resolve (to the first
// component listed). nullopt when the profile has no such input or output.
std::optional<std::string> bindable(const Profile& p, const std::string& b) {
  for (const char* u : p.users) {
    const std::string user = u;
    if (b.size() <= user.size() + 1 || b.compare(0, user.size() + 1, user + "/") != 0) continue;
    const std::string rest = b.substr(user.size() + 1);
    const std::string hand = user.substr(user.rfind('/') + 1);  // "left", "right", …
    for (std::string c : p.components) {
      if (const auto colon = c.find(':'); colon != std::string::npos) {
        if (c.substr(0, colon) != hand) continue;
        c = c.substr(colon + 1);
      }
      if (rest == c || (c.rfind("input/", 0) == 0 && rest == c.substr(0, c.rfind('/')))) return user + "/" + c;
    }
  }
  return std::nullopt;
}

// The action's set attached to `s`, or the result code saying why not.
XrResult attached_action(Session* s, XrAction handle, Action** out) {
  Action* a = find<Action>(handle);
  if (!a || a->set->instance != s->instance) return XR_ERROR_HANDLE_INVALID;
  if (!a->set->attached ||
      std::find(s->attached_sets.begin(), s->attached_sets.end(), a->set->id) == s->attached_sets.end())
    return XR_ERROR_ACTIONSET_NOT_ATTACHED;
  *out = a;
  return XR_SUCCESS;
}

XrResult check_subaction(const Session* s, const Action* a, XrPath sub) {
  if (sub == XR_NULL_PATH) return XR_SUCCESS;
  if (!s->instance->path_string(sub)) return XR_ERROR_PATH_INVALID;
  if (std::find(a->subactions.begin(), a->subactions.end(), sub) == a->subactions.end())
    return XR_ERROR_PATH_UNSUPPORTED;
  return XR_SUCCESS;
}

// Common checks of the xrGetActionState* family.
XrResult state_action(XrSession session, const XrActionStateGetInfo* info, const void* state, XrStructureType st,
                      XrActionType want, Session** s_out, Action** a_out) {
  Session* s = find<Session>(session);
  if (!s) return XR_ERROR_HANDLE_INVALID;
  if (!has_type(info, XR_TYPE_ACTION_STATE_GET_INFO) || !has_type(state, st)) return XR_ERROR_VALIDATION_FAILURE;
  Action* a = nullptr;
  if (XrResult r = attached_action(s, info->action, &a); r != XR_SUCCESS) return r;
  if (a->type != want) return XR_ERROR_ACTION_TYPE_MISMATCH;
  if (XrResult r = check_subaction(s, a, info->subactionPath); r != XR_SUCCESS) return r;
  *s_out = s;
  *a_out = a;
  return XR_SUCCESS;
}

}  // namespace

XrResult api::xrCreateActionSet(XrInstance instance, const XrActionSetCreateInfo* info, XrActionSet* set) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = find<Instance>(instance);
    if (!inst) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_ACTION_SET_CREATE_INFO) || !set) return XR_ERROR_VALIDATION_FAILURE;
    if (XrResult r = check_name(info->actionSetName, sizeof info->actionSetName); r != XR_SUCCESS) return r;
    if (!terminated(info->localizedActionSetName, sizeof info->localizedActionSetName) ||
        !info->localizedActionSetName[0])
      return XR_ERROR_LOCALIZED_NAME_INVALID;
    for (Object* o : children_of(inst->id, Kind::ActionSet)) {
      const auto* other = static_cast<ActionSet*>(o);
      if (other->name == info->actionSetName) return XR_ERROR_NAME_DUPLICATED;
      if (other->localized == info->localizedActionSetName) return XR_ERROR_LOCALIZED_NAME_DUPLICATED;
    }
    auto as = std::make_unique<ActionSet>();
    as->instance = inst;
    as->name = info->actionSetName;
    as->localized = info->localizedActionSetName;
    as->priority = info->priority;
    *set = to_handle<XrActionSet>(add_object(std::move(as), inst->id));
    return XR_SUCCESS;
  });
}

XrResult api::xrDestroyActionSet(XrActionSet set) {
  return guarded(__func__, [&]() -> XrResult {
    ActionSet* as = find<ActionSet>(set);
    if (!as) return XR_ERROR_HANDLE_INVALID;
    destroy_object(as->id);
    return XR_SUCCESS;
  });
}

XrResult api::xrCreateAction(XrActionSet set, const XrActionCreateInfo* info, XrAction* action) {
  return guarded(__func__, [&]() -> XrResult {
    ActionSet* as = find<ActionSet>(set);
    if (!as) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_ACTION_CREATE_INFO) || !action) return XR_ERROR_VALIDATION_FAILURE;
    if (as->attached) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
    if (XrResult r = check_name(info->actionName, sizeof info->actionName); r != XR_SUCCESS) return r;
    if (!terminated(info->localizedActionName, sizeof info->localizedActionName) || !info->localizedActionName[0])
      return XR_ERROR_LOCALIZED_NAME_INVALID;
    switch (info->actionType) {
      case XR_ACTION_TYPE_BOOLEAN_INPUT:
      case XR_ACTION_TYPE_FLOAT_INPUT:
      case XR_ACTION_TYPE_VECTOR2F_INPUT:
      case XR_ACTION_TYPE_POSE_INPUT:
      case XR_ACTION_TYPE_VIBRATION_OUTPUT: break;
      default: return XR_ERROR_VALIDATION_FAILURE;
    }
    if (info->countSubactionPaths && !info->subactionPaths) return XR_ERROR_VALIDATION_FAILURE;
    std::vector<XrPath> subs;
    const bool eye_gaze = as->instance->has(XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME);
    for (uint32_t i = 0; i < info->countSubactionPaths; ++i) {
      const std::string* p = as->instance->path_string(info->subactionPaths[i]);
      if (!p) return XR_ERROR_PATH_INVALID;
      if (!is_top_level_user_path(*p, eye_gaze)) return XR_ERROR_PATH_UNSUPPORTED;
      if (std::find(subs.begin(), subs.end(), info->subactionPaths[i]) != subs.end()) return XR_ERROR_PATH_UNSUPPORTED;
      subs.push_back(info->subactionPaths[i]);
    }
    for (Object* o : children_of(as->id, Kind::Action)) {
      const auto* other = static_cast<Action*>(o);
      if (other->name == info->actionName) return XR_ERROR_NAME_DUPLICATED;
      if (other->localized == info->localizedActionName) return XR_ERROR_LOCALIZED_NAME_DUPLICATED;
    }
    auto a = std::make_unique<Action>();
    a->set = as;
    a->name = info->actionName;
    a->localized = info->localizedActionName;
    a->type = info->actionType;
    a->subactions = std::move(subs);
    *action = to_handle<XrAction>(add_object(std::move(a), as->id));
    return XR_SUCCESS;
  });
}

XrResult api::xrDestroyAction(XrAction action) {
  return guarded(__func__, [&]() -> XrResult {
    Action* a = find<Action>(action);
    if (!a) return XR_ERROR_HANDLE_INVALID;
    destroy_object(a->id);
    return XR_SUCCESS;
  });
}

XrResult api::xrSuggestInteractionProfileBindings(XrInstance instance,
                                                  const XrInteractionProfileSuggestedBinding* info) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = find<Instance>(instance);
    if (!inst) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING)) return XR_ERROR_VALIDATION_FAILURE;
    if (info->countSuggestedBindings == 0 || !info->suggestedBindings) return XR_ERROR_VALIDATION_FAILURE;
    const std::string* profile_path = inst->path_string(info->interactionProfile);
    if (!profile_path) return XR_ERROR_PATH_INVALID;
    const Profile* profile = nullptr;
    for (const Profile& p : profiles())
      if (*profile_path == p.path) profile = &p;
    if (!profile) return XR_ERROR_PATH_UNSUPPORTED;
    if (*profile_path == kEyeGazeProfile && !inst->has(XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME))
      return XR_ERROR_PATH_UNSUPPORTED;
    for (Object* o : children_of(inst->id, Kind::ActionSet))
      if (static_cast<ActionSet*>(o)->attached) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
    std::vector<XrActionSuggestedBinding> bindings;
    for (uint32_t i = 0; i < info->countSuggestedBindings; ++i) {
      const XrActionSuggestedBinding& b = info->suggestedBindings[i];
      const Action* a = find<Action>(b.action);
      if (!a || a->set->instance != inst) return XR_ERROR_HANDLE_INVALID;
      const std::string* bp = inst->path_string(b.binding);
      if (!bp) return XR_ERROR_PATH_INVALID;
      const std::optional<std::string> component = bindable(*profile, *bp);
      if (!component) {
        FOVEA_LOG_WARN("xrSuggestInteractionProfileBindings: binding %s is not in %s", bp->c_str(), profile->path);
        return XR_ERROR_PATH_UNSUPPORTED;
      }
      bindings.push_back({b.action, inst->path(*component)});
    }
    inst->suggested[info->interactionProfile] = std::move(bindings);
    return XR_SUCCESS;
  });
}

XrResult api::xrAttachSessionActionSets(XrSession session, const XrSessionActionSetsAttachInfo* info) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO)) return XR_ERROR_VALIDATION_FAILURE;
    if (info->countActionSets == 0 || !info->actionSets) return XR_ERROR_VALIDATION_FAILURE;
    if (s->actions_attached) return XR_ERROR_ACTIONSETS_ALREADY_ATTACHED;
    std::vector<ActionSet*> sets;
    for (uint32_t i = 0; i < info->countActionSets; ++i) {
      ActionSet* as = find<ActionSet>(info->actionSets[i]);
      if (!as || as->instance != s->instance) return XR_ERROR_HANDLE_INVALID;
      sets.push_back(as);
    }
    bool gaze = false;
    for (ActionSet* as : sets) {
      as->attached = true;
      s->attached_sets.push_back(as->id);
      for (Object* o : children_of(as->id, Kind::Action)) {
        auto* a = static_cast<Action*>(o);
        for (const auto& [profile, bindings] : s->instance->suggested)
          for (const auto& b : bindings)
            if (b.action == to_handle<XrAction>(a->id)) a->bound.push_back(b.binding);
        gaze |= a->gaze_bound();
      }
    }
    s->actions_attached = true;
    s->gaze_profile_bound = gaze && s->instance->has(XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME);
    FOVEA_LOG_INFO("action sets attached: %u, eye gaze %s", info->countActionSets,
                   s->gaze_profile_bound ? "bound" : "not bound");
    return XR_SUCCESS;
  });
}

XrResult api::xrGetCurrentInteractionProfile(XrSession session, XrPath topLevelUserPath,
                                             XrInteractionProfileState* state) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(state, XR_TYPE_INTERACTION_PROFILE_STATE)) return XR_ERROR_VALIDATION_FAILURE;
    const std::string* user = s->instance->path_string(topLevelUserPath);
    if (!user) return XR_ERROR_PATH_INVALID;
    if (!is_top_level_user_path(*user, s->instance->has(XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME)))
      return XR_ERROR_PATH_UNSUPPORTED;
    if (!s->actions_attached) return XR_ERROR_ACTIONSET_NOT_ATTACHED;
    state->interactionProfile =
        (*user == "/user/eyes_ext" && s->gaze_profile_active) ? s->instance->path(kEyeGazeProfile) : XR_NULL_PATH;
    return XR_SUCCESS;
  });
}

XrResult api::xrGetActionStateBoolean(XrSession session, const XrActionStateGetInfo* info,
                                      XrActionStateBoolean* state) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = nullptr;
    Action* a = nullptr;
    if (XrResult r = state_action(session, info, state, XR_TYPE_ACTION_STATE_BOOLEAN, XR_ACTION_TYPE_BOOLEAN_INPUT, &s, &a);
        r != XR_SUCCESS)
      return r;
    state->currentState = XR_FALSE;
    state->changedSinceLastSync = XR_FALSE;
    state->lastChangeTime = 0;
    state->isActive = XR_FALSE;  // no controller is connected
    return XR_SUCCESS;
  });
}

XrResult api::xrGetActionStateFloat(XrSession session, const XrActionStateGetInfo* info, XrActionStateFloat* state) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = nullptr;
    Action* a = nullptr;
    if (XrResult r = state_action(session, info, state, XR_TYPE_ACTION_STATE_FLOAT, XR_ACTION_TYPE_FLOAT_INPUT, &s, &a);
        r != XR_SUCCESS)
      return r;
    state->currentState = 0;
    state->changedSinceLastSync = XR_FALSE;
    state->lastChangeTime = 0;
    state->isActive = XR_FALSE;
    return XR_SUCCESS;
  });
}

XrResult api::xrGetActionStateVector2f(XrSession session, const XrActionStateGetInfo* info,
                                       XrActionStateVector2f* state) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = nullptr;
    Action* a = nullptr;
    if (XrResult r =
            state_action(session, info, state, XR_TYPE_ACTION_STATE_VECTOR2F, XR_ACTION_TYPE_VECTOR2F_INPUT, &s, &a);
        r != XR_SUCCESS)
      return r;
    state->currentState = {0, 0};
    state->changedSinceLastSync = XR_FALSE;
    state->lastChangeTime = 0;
    state->isActive = XR_FALSE;
    return XR_SUCCESS;
  });
}

XrResult api::xrGetActionStatePose(XrSession session, const XrActionStateGetInfo* info, XrActionStatePose* state) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = nullptr;
    Action* a = nullptr;
    if (XrResult r = state_action(session, info, state, XR_TYPE_ACTION_STATE_POSE, XR_ACTION_TYPE_POSE_INPUT, &s, &a);
        r != XR_SUCCESS)
      return r;
    const std::string* sub = s->instance->path_string(info->subactionPath);
    const bool eyes = !sub || *sub == "/user/eyes_ext";
    // Input reaches only the focused session (core spec, "Input Actions and Focus").
    state->isActive =
        (s->state == XR_SESSION_STATE_FOCUSED && s->gaze_profile_active && a->gaze_bound() && eyes) ? XR_TRUE : XR_FALSE;
    return XR_SUCCESS;
  });
}

XrResult api::xrSyncActions(XrSession session, const XrActionsSyncInfo* info) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_ACTIONS_SYNC_INFO)) return XR_ERROR_VALIDATION_FAILURE;
    if (info->countActiveActionSets && !info->activeActionSets) return XR_ERROR_VALIDATION_FAILURE;
    for (uint32_t i = 0; i < info->countActiveActionSets; ++i) {
      const XrActiveActionSet& as = info->activeActionSets[i];
      ActionSet* set = find<ActionSet>(as.actionSet);
      if (!set || set->instance != s->instance) return XR_ERROR_HANDLE_INVALID;
      if (std::find(s->attached_sets.begin(), s->attached_sets.end(), set->id) == s->attached_sets.end())
        return XR_ERROR_ACTIONSET_NOT_ATTACHED;
      if (as.subactionPath != XR_NULL_PATH) {
        const std::string* p = s->instance->path_string(as.subactionPath);
        if (!p) return XR_ERROR_PATH_INVALID;
        if (!is_top_level_user_path(*p, s->instance->has(XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME)))
          return XR_ERROR_PATH_UNSUPPORTED;
      }
    }
    if (s->running && s->gaze_profile_bound && !s->gaze_profile_active) {
      s->gaze_profile_active = true;
      QueuedEvent e;
      auto* ev = reinterpret_cast<XrEventDataInteractionProfileChanged*>(&e.data);
      ev->type = XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED;
      ev->next = nullptr;
      ev->session = session;
      e.session = s->id;
      s->instance->events.push_back(e);
    }
    return s->state == XR_SESSION_STATE_FOCUSED ? XR_SUCCESS : XR_SESSION_NOT_FOCUSED;
  });
}

XrResult api::xrEnumerateBoundSourcesForAction(XrSession session, const XrBoundSourcesForActionEnumerateInfo* info,
                                               uint32_t capacity, uint32_t* count, XrPath* sources) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_BOUND_SOURCES_FOR_ACTION_ENUMERATE_INFO)) return XR_ERROR_VALIDATION_FAILURE;
    Action* a = nullptr;
    if (XrResult r = attached_action(s, info->action, &a); r != XR_SUCCESS) return r;
    std::vector<XrPath> out;
    if (s->gaze_profile_active && a->gaze_bound()) out.push_back(s->instance->path(kEyeGazePose));
    return two_call(capacity, count, sources, out);
  });
}

XrResult api::xrGetInputSourceLocalizedName(XrSession session, const XrInputSourceLocalizedNameGetInfo* info,
                                            uint32_t capacity, uint32_t* count, char* buffer) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_INPUT_SOURCE_LOCALIZED_NAME_GET_INFO)) return XR_ERROR_VALIDATION_FAILURE;
    constexpr XrInputSourceLocalizedNameFlags all = XR_INPUT_SOURCE_LOCALIZED_NAME_USER_PATH_BIT |
                                                    XR_INPUT_SOURCE_LOCALIZED_NAME_INTERACTION_PROFILE_BIT |
                                                    XR_INPUT_SOURCE_LOCALIZED_NAME_COMPONENT_BIT;
    if (info->whichComponents == 0 || (info->whichComponents & ~all)) return XR_ERROR_VALIDATION_FAILURE;
    const std::string* src = s->instance->path_string(info->sourcePath);
    if (!src) return XR_ERROR_PATH_INVALID;
    if (!s->actions_attached) return XR_ERROR_ACTIONSET_NOT_ATTACHED;
    if (*src != kEyeGazePose) return XR_ERROR_PATH_UNSUPPORTED;
    std::string name;
    auto add = [&](const char* part) { name += (name.empty() ? "" : " ") + std::string(part); };
    if (info->whichComponents & XR_INPUT_SOURCE_LOCALIZED_NAME_USER_PATH_BIT) add("Eyes");
    if (info->whichComponents & XR_INPUT_SOURCE_LOCALIZED_NAME_INTERACTION_PROFILE_BIT) add("Eye Gaze Interaction");
    if (info->whichComponents & XR_INPUT_SOURCE_LOCALIZED_NAME_COMPONENT_BIT) add("Gaze Pose");
    return two_call_string(capacity, count, buffer, name);
  });
}

XrResult api::xrApplyHapticFeedback(XrSession session, const XrHapticActionInfo* info,
                                    const XrHapticBaseHeader* feedback) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_HAPTIC_ACTION_INFO) || !has_type(feedback, XR_TYPE_HAPTIC_VIBRATION))
      return XR_ERROR_VALIDATION_FAILURE;
    Action* a = nullptr;
    if (XrResult r = attached_action(s, info->action, &a); r != XR_SUCCESS) return r;
    if (a->type != XR_ACTION_TYPE_VIBRATION_OUTPUT) return XR_ERROR_ACTION_TYPE_MISMATCH;
    if (XrResult r = check_subaction(s, a, info->subactionPath); r != XR_SUCCESS) return r;
    return XR_SUCCESS;  // no haptic device is connected
  });
}

XrResult api::xrStopHapticFeedback(XrSession session, const XrHapticActionInfo* info) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_HAPTIC_ACTION_INFO)) return XR_ERROR_VALIDATION_FAILURE;
    Action* a = nullptr;
    if (XrResult r = attached_action(s, info->action, &a); r != XR_SUCCESS) return r;
    if (a->type != XR_ACTION_TYPE_VIBRATION_OUTPUT) return XR_ERROR_ACTION_TYPE_MISMATCH;
    return check_subaction(s, a, info->subactionPath);
  });
}

}  // namespace fovea::runtime

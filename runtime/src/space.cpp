// Reference spaces (VIEW, LOCAL, STAGE), action spaces (eye gaze; controllers are never
// tracked), xrLocateSpace and xrLocateViews. World coordinates are LOCAL space: its origin is
// the head's position at the display epoch, the floor (STAGE origin) 1.6 m below it.
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include <glm/gtx/quaternion.hpp>

#include <algorithm>

#include "api.hpp"
#include "fovea/core/stereo_views.hpp"
#include "state.hpp"

namespace fovea::runtime {
namespace {

constexpr double kEyeHeight = 1.6;

core::Pose from_xr(const XrPosef& p) {
  return {glm::dquat(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z),
          {p.position.x, p.position.y, p.position.z}};
}

XrPosef to_xr(const core::Pose& p) {
  const glm::dquat q = glm::normalize(p.orientation);
  return {{float(q.x), float(q.y), float(q.z), float(q.w)},
          {float(p.position.x), float(p.position.y), float(p.position.z)}};
}

core::Pose compose(const core::Pose& a, const core::Pose& b) {  // a * b: b expressed in a's frame
  return {a.orientation * b.orientation, a.position + a.orientation * b.position};
}

core::Pose inverse(const core::Pose& p) {
  const glm::dquat qi = glm::inverse(p.orientation);
  return {qi, qi * -p.position};
}

bool known_reference(XrReferenceSpaceType t) {
  return t == XR_REFERENCE_SPACE_TYPE_VIEW || t == XR_REFERENCE_SPACE_TYPE_LOCAL || t == XR_REFERENCE_SPACE_TYPE_STAGE;
}

core::Pose head_pose(const Session& s, XrTime t) { return s.instance->head.at(t - display_epoch(s)); }

// The pose of `sp` in LOCAL space at time t, or nullopt when it is not tracked. For the eye
// gaze action space `gaze` receives the tracker sample used.
std::optional<core::Pose> world_pose(Session& s, const Space& sp, XrTime t, GazeSample* gaze) {
  core::Pose base;
  if (!sp.is_action) {
    switch (sp.reference) {
      case XR_REFERENCE_SPACE_TYPE_VIEW: base = head_pose(s, t); break;
      case XR_REFERENCE_SPACE_TYPE_STAGE: base.position = {0, -kEyeHeight, 0}; break;
      default: break;  // LOCAL
    }
  } else {
    const auto* action = static_cast<const Action*>(find_object(sp.action, Kind::Action));
    // Untracked unless focused: an unfocused session receives no input.
    if (!action || s.state != XR_SESSION_STATE_FOCUSED || !s.gaze_profile_active || !action->gaze_bound())
      return std::nullopt;
    // Honest: the samples delivered by the read time (never one measured after it),
    // predicted to t when the source predicts.
    const GazeSample g = s.instance->gaze->read(tracker_read_time(s), t, display_epoch(s));
    if (gaze) *gaze = g;
    if (!g.valid) return std::nullopt;
    base = compose(head_pose(s, t), core::Pose{glm::rotation(glm::dvec3(0, 0, -1), g.dir), {0, 0, 0}});
  }
  return compose(base, from_xr(sp.offset));
}

// The frames waited on or open whose predicted display time is t.
std::vector<FrameRecord*> frames_for(Session& s, XrTime t) {
  std::vector<FrameRecord*> out;
  for (FrameRecord& f : s.waited)
    if (f.predicted_display_ns == t) out.push_back(&f);
  if (s.frame_open && s.current.predicted_display_ns == t) out.push_back(&s.current);
  return out;
}

}  // namespace

bool valid_pose(const XrPosef& p) {
  const auto& q = p.orientation;
  const auto& v = p.position;
  for (float x : {q.x, q.y, q.z, q.w, v.x, v.y, v.z})
    if (!std::isfinite(x)) return false;
  const double len = std::sqrt(double(q.x) * q.x + double(q.y) * q.y + double(q.z) * q.z + double(q.w) * q.w);
  return std::abs(len - 1.0) <= 0.01;  // the core spec's tolerance for a unit quaternion
}

core::Pose session_head_pose(const Session& s, XrTime t) { return head_pose(s, t); }

core::TimeNs display_epoch(const Session& s) { return s.clock.started() ? s.clock.epoch() : s.created_ns; }

core::TimeNs tracker_read_time(const Session& s) {
  if (s.clock.pacing() != Pacing::Lockstep) return core::now_ns();
  const FrameRecord* newest = !s.waited.empty() ? &s.waited.back() : &s.current;
  return newest->wake_ns ? newest->wake_ns : core::now_ns();
}

XrResult api::xrEnumerateReferenceSpaces(XrSession session, uint32_t capacity, uint32_t* count,
                                         XrReferenceSpaceType* spaces) {
  return guarded(__func__, [&]() -> XrResult {
    if (!find<Session>(session)) return XR_ERROR_HANDLE_INVALID;
    return two_call(capacity, count, spaces,
                    std::vector<XrReferenceSpaceType>{XR_REFERENCE_SPACE_TYPE_VIEW, XR_REFERENCE_SPACE_TYPE_LOCAL,
                                                      XR_REFERENCE_SPACE_TYPE_STAGE});
  });
}

XrResult api::xrCreateReferenceSpace(XrSession session, const XrReferenceSpaceCreateInfo* info, XrSpace* space) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_REFERENCE_SPACE_CREATE_INFO) || !space) return XR_ERROR_VALIDATION_FAILURE;
    // Any other type, known or not (the CTS passes MAX_ENUM), is unsupported.
    if (!known_reference(info->referenceSpaceType)) return XR_ERROR_REFERENCE_SPACE_UNSUPPORTED;
    if (!valid_pose(info->poseInReferenceSpace)) return XR_ERROR_POSE_INVALID;
    auto sp = std::make_unique<Space>();
    sp->session = s;
    sp->reference = info->referenceSpaceType;
    sp->offset = info->poseInReferenceSpace;
    *space = to_handle<XrSpace>(add_object(std::move(sp), s->id));
    return XR_SUCCESS;
  });
}

XrResult api::xrGetReferenceSpaceBoundsRect(XrSession session, XrReferenceSpaceType type, XrExtent2Df* bounds) {
  return guarded(__func__, [&]() -> XrResult {
    if (!find<Session>(session)) return XR_ERROR_HANDLE_INVALID;
    if (!bounds) return XR_ERROR_VALIDATION_FAILURE;
    // Any other type, known or not (the CTS passes MAX_ENUM), is unsupported.
    if (!known_reference(type)) return XR_ERROR_REFERENCE_SPACE_UNSUPPORTED;
    if (type == XR_REFERENCE_SPACE_TYPE_STAGE) {
      *bounds = {2.0f, 2.0f};  // a 2 m x 2 m play area
      return XR_SUCCESS;
    }
    *bounds = {0, 0};
    return XR_SPACE_BOUNDS_UNAVAILABLE;
  });
}

XrResult api::xrCreateActionSpace(XrSession session, const XrActionSpaceCreateInfo* info, XrSpace* space) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_ACTION_SPACE_CREATE_INFO) || !space) return XR_ERROR_VALIDATION_FAILURE;
    Action* a = find<Action>(info->action);
    if (!a || a->set->instance != s->instance) return XR_ERROR_HANDLE_INVALID;
    if (a->type != XR_ACTION_TYPE_POSE_INPUT) return XR_ERROR_ACTION_TYPE_MISMATCH;
    if (info->subactionPath != XR_NULL_PATH) {
      if (!s->instance->path_string(info->subactionPath)) return XR_ERROR_PATH_INVALID;
      if (std::find(a->subactions.begin(), a->subactions.end(), info->subactionPath) == a->subactions.end())
        return XR_ERROR_PATH_UNSUPPORTED;
    }
    if (!valid_pose(info->poseInActionSpace)) return XR_ERROR_POSE_INVALID;
    auto sp = std::make_unique<Space>();
    sp->session = s;
    sp->is_action = true;
    sp->action = a->id;
    sp->subaction = info->subactionPath;
    sp->offset = info->poseInActionSpace;
    *space = to_handle<XrSpace>(add_object(std::move(sp), s->id));
    return XR_SUCCESS;
  });
}

XrResult api::xrDestroySpace(XrSpace space) {
  return guarded(__func__, [&]() -> XrResult {
    Space* sp = find<Space>(space);
    if (!sp) return XR_ERROR_HANDLE_INVALID;
    destroy_object(sp->id);
    return XR_SUCCESS;
  });
}

XrResult api::xrLocateSpace(XrSpace space, XrSpace baseSpace, XrTime time, XrSpaceLocation* location) {
  return guarded(__func__, [&]() -> XrResult {
    Space* sp = find<Space>(space);
    Space* base = find<Space>(baseSpace);
    if (!sp || !base) return XR_ERROR_HANDLE_INVALID;
    if (sp->session != base->session) return XR_ERROR_VALIDATION_FAILURE;
    if (!has_type(location, XR_TYPE_SPACE_LOCATION)) return XR_ERROR_VALIDATION_FAILURE;
    if (time <= 0) return XR_ERROR_TIME_INVALID;
    Session& s = *sp->session;
    GazeSample gaze;
    gaze.sample_ns = 0;
    const auto a = world_pose(s, *sp, time, &gaze);
    const auto b = world_pose(s, *base, time, &gaze);
    if (a && b) {
      location->pose = to_xr(compose(inverse(*b), *a));
      location->locationFlags = XR_SPACE_LOCATION_ORIENTATION_VALID_BIT | XR_SPACE_LOCATION_POSITION_VALID_BIT |
                                XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT | XR_SPACE_LOCATION_POSITION_TRACKED_BIT;
    } else {
      location->pose = {{0, 0, 0, 1}, {0, 0, 0}};
      location->locationFlags = 0;
    }
    if (auto* v = find_next<XrSpaceVelocity>(location->next, XR_TYPE_SPACE_VELOCITY)) {
      v->velocityFlags = 0;  // the simulated devices report no velocities
      v->linearVelocity = {0, 0, 0};
      v->angularVelocity = {0, 0, 0};
    }
    if (auto* st = find_next<XrEyeGazeSampleTimeEXT>(location->next, XR_TYPE_EYE_GAZE_SAMPLE_TIME_EXT))
      st->time = (a && b) ? gaze.sample_ns : 0;
    return XR_SUCCESS;
  });
}

XrResult api::xrLocateViews(XrSession session, const XrViewLocateInfo* info, XrViewState* state, uint32_t capacity,
                            uint32_t* count, XrView* views) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_VIEW_LOCATE_INFO) || !has_type(state, XR_TYPE_VIEW_STATE))
      return XR_ERROR_VALIDATION_FAILURE;
    if (info->viewConfigurationType != XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO)
      return info->viewConfigurationType == XR_VIEW_CONFIGURATION_TYPE_PRIMARY_MONO
                 ? XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED
                 : XR_ERROR_VALIDATION_FAILURE;
    Space* base = find<Space>(info->space);
    if (!base || base->session != s) return XR_ERROR_HANDLE_INVALID;
    if (info->displayTime <= 0) return XR_ERROR_TIME_INVALID;
    if (!count || (capacity && !views)) return XR_ERROR_VALIDATION_FAILURE;
    *count = 2;
    if (capacity == 0) return XR_SUCCESS;
    if (capacity < 2) return XR_ERROR_SIZE_INSUFFICIENT;
    for (uint32_t i = 0; i < 2; ++i)
      if (views[i].type != XR_TYPE_VIEW) return XR_ERROR_VALIDATION_FAILURE;
    const auto b = world_pose(*s, *base, info->displayTime, nullptr);
    const core::Pose head = head_pose(*s, info->displayTime);
    // The frame these views are for (same display time) records when its head pose was
    // read and the time it was predicted for; the last locate before xrEndFrame wins.
    const core::TimeNs read = tracker_read_time(*s);
    for (FrameRecord* f : frames_for(*s, info->displayTime)) {
      f->head_pose_ns = std::min<core::TimeNs>(read, info->displayTime);
      f->head_pose_target_ns = info->displayTime;
    }
    const core::DisplayPreset& d = s->instance->display;
    const std::array<core::Pose, 2> eyes_in_head = core::eye_poses(core::Pose{}, d);  // IPD and cant
    for (uint32_t i = 0; i < 2; ++i) {
      const core::Eye eye = i == 0 ? core::Eye::Left : core::Eye::Right;
      const core::Pose& eye_in_head = eyes_in_head[i];
      views[i].pose = b ? to_xr(compose(inverse(*b), compose(head, eye_in_head))) : XrPosef{{0, 0, 0, 1}, {0, 0, 0}};
      const core::Fov& f = d.fov(eye);
      views[i].fov = {float(f.angle_left), float(f.angle_right), float(f.angle_up), float(f.angle_down)};
    }
    state->viewStateFlags = b ? (XR_VIEW_STATE_ORIENTATION_VALID_BIT | XR_VIEW_STATE_POSITION_VALID_BIT |
                                 XR_VIEW_STATE_ORIENTATION_TRACKED_BIT | XR_VIEW_STATE_POSITION_TRACKED_BIT)
                              : 0;
    return XR_SUCCESS;
  });
}

}  // namespace fovea::runtime

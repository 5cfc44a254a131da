// The frame loop: xrWaitFrame paces the application on the simulated display clock,
// xrBeginFrame/xrEndFrame bracket a frame, xrEndFrame validates the layers, runs the
// compositor and writes the frame's timing record.
#include <time.h>

#include <cmath>

#include "api.hpp"
#include "compositor.hpp"
#include "state.hpp"

namespace fovea::runtime {
namespace {

void sleep_until(core::TimeNs t) {
  timespec ts{static_cast<time_t>(t / 1'000'000'000), static_cast<long>(t % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

XrResult check_released(const Swapchain* sc, const Session* s) {
  if (!sc || sc->session != s) return XR_ERROR_HANDLE_INVALID;
  if (sc->last_released < 0) return XR_ERROR_LAYER_INVALID;  // nothing released yet
  return XR_SUCCESS;
}

XrResult check_rect(const XrRect2Di& r, const Swapchain& sc) {
  if (r.offset.x < 0 || r.offset.y < 0 || r.extent.width <= 0 || r.extent.height <= 0 ||
      std::int64_t(r.offset.x) + r.extent.width > std::int64_t(sc.info.width) ||
      std::int64_t(r.offset.y) + r.extent.height > std::int64_t(sc.info.height))
    return XR_ERROR_SWAPCHAIN_RECT_INVALID;
  return XR_SUCCESS;
}

XrResult check_sub_image(const Session* s, const XrSwapchainSubImage& sub, Swapchain** out) {
  Swapchain* sc = find<Swapchain>(sub.swapchain);
  if (XrResult r = check_released(sc, s); r != XR_SUCCESS) return r;
  if (XrResult r = check_rect(sub.imageRect, *sc); r != XR_SUCCESS) return r;
  if (sub.imageArrayIndex >= sc->info.arraySize) return XR_ERROR_VALIDATION_FAILURE;
  *out = sc;
  return XR_SUCCESS;
}

XrResult check_projection(const Session* s, const XrCompositionLayerProjection& l, ProjectionLayer* out) {
  const Space* space = find<Space>(l.space);
  if (!space || space->session != s) return XR_ERROR_HANDLE_INVALID;
  if (l.viewCount != 2 || !l.views) return XR_ERROR_VALIDATION_FAILURE;
  for (uint32_t i = 0; i < 2; ++i) {
    const XrCompositionLayerProjectionView& v = l.views[i];
    if (v.type != XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW) return XR_ERROR_VALIDATION_FAILURE;
    if (!valid_pose(v.pose)) return XR_ERROR_POSE_INVALID;
    if (!(std::isfinite(v.fov.angleLeft) && std::isfinite(v.fov.angleRight) && std::isfinite(v.fov.angleUp) &&
          std::isfinite(v.fov.angleDown)))
      return XR_ERROR_VALIDATION_FAILURE;
    Swapchain* sc = nullptr;
    if (XrResult r = check_sub_image(s, v.subImage, &sc); r != XR_SUCCESS) return r;
    if (sc->is_depth()) return XR_ERROR_LAYER_INVALID;
    if (s->instance->has(XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME)) {
      // XR_KHR_composition_layer_depth: validated and accepted; the compositor does not use depth.
      if (const auto* d = find_next<const XrCompositionLayerDepthInfoKHR>(v.next, XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR)) {
        Swapchain* dsc = nullptr;
        if (XrResult r = check_sub_image(s, d->subImage, &dsc); r != XR_SUCCESS) return r;
        if (!dsc->is_depth()) return XR_ERROR_VALIDATION_FAILURE;
        // nearZ, farZ in (0, +infinity] and not equal: an infinite plane is allowed (the
        // extension's valid usage); NaN fails every comparison below.
        if (!(d->minDepth >= 0 && d->minDepth <= d->maxDepth && d->maxDepth <= 1) || !(d->nearZ > 0) ||
            !(d->farZ > 0) || d->nearZ == d->farZ)
          return XR_ERROR_VALIDATION_FAILURE;
      }
    }
    LayerView& lv = out->views[i];
    lv.image = sc->images[size_t(sc->last_released)];
    lv.format = VkFormat(sc->info.format);
    lv.array_layer = v.subImage.imageArrayIndex;
    lv.rect = v.subImage.imageRect;
    lv.fov = core::Fov{v.fov.angleLeft, v.fov.angleRight, v.fov.angleUp, v.fov.angleDown};
    if (!Compositor::readable_format(lv.format)) return XR_ERROR_LAYER_INVALID;
  }
  out->alpha_blend = (l.layerFlags & XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT) != 0;
  return XR_SUCCESS;
}

XrResult check_quad(const Session* s, const XrCompositionLayerQuad& q) {
  const Space* space = find<Space>(q.space);
  if (!space || space->session != s) return XR_ERROR_HANDLE_INVALID;
  if (q.eyeVisibility > XR_EYE_VISIBILITY_RIGHT) return XR_ERROR_VALIDATION_FAILURE;
  if (!valid_pose(q.pose)) return XR_ERROR_POSE_INVALID;
  Swapchain* sc = nullptr;
  return check_sub_image(s, q.subImage, &sc);
}

}  // namespace

XrResult api::xrWaitFrame(XrSession session, const XrFrameWaitInfo* info, XrFrameState* state) {
  try {
    std::unique_lock lock(api_mutex());
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if ((info && info->type != XR_TYPE_FRAME_WAIT_INFO) || !has_type(state, XR_TYPE_FRAME_STATE))
      return XR_ERROR_VALIDATION_FAILURE;
    if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
    const std::uint64_t id = s->id;
    FrameRecord r;
    r.wait_call_ns = core::now_ns();
    // A further xrWaitFrame blocks until the previous one's frame has been begun (core spec,
    // xrWaitFrame), e.g. the render thread of a pipelined engine is still behind.
    while (!s->waited.empty() || s->wait_sleeping) {
      frame_begun().wait(lock);
      s = static_cast<Session*>(find_object(id, Kind::Session));
      if (!s) return XR_ERROR_HANDLE_INVALID;
      if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
    }
    FrameSlot slot = s->clock.next(core::now_ns());
    if (s->queued_state == XR_SESSION_STATE_READY) s->queue_state(XR_SESSION_STATE_SYNCHRONIZED);
    // Other threads may use the runtime while this one sleeps.
    s->wait_sleeping = true;
    lock.unlock();
    sleep_until(slot.wake_ns);
    lock.lock();
    s = static_cast<Session*>(find_object(id, Kind::Session));
    if (!s) return XR_ERROR_HANDLE_INVALID;
    s->wait_sleeping = false;
    if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;  // ended while this call slept
    r.wait_return_ns = core::now_ns();
    r.late_ns = std::max<core::TimeNs>(0, r.wait_return_ns - slot.wake_ns);
    s->clock.reslot(slot, r.wait_return_ns);
    r.frame = slot.index;
    r.wake_ns = slot.wake_ns;
    r.predicted_display_ns = slot.display_ns;
    r.missed_vsyncs = slot.missed;
    s->waited.push_back(r);
    state->predictedDisplayTime = slot.display_ns;
    state->predictedDisplayPeriod = s->clock.period();
    state->shouldRender =
        (s->state == XR_SESSION_STATE_VISIBLE || s->state == XR_SESSION_STATE_FOCUSED) ? XR_TRUE : XR_FALSE;
    return XR_SUCCESS;
  } catch (const std::exception& e) {
    FOVEA_LOG_ERROR("xrWaitFrame: %s", e.what());
    return XR_ERROR_RUNTIME_FAILURE;
  }
}

XrResult api::xrBeginFrame(XrSession session, const XrFrameBeginInfo* info) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (info && info->type != XR_TYPE_FRAME_BEGIN_INFO) return XR_ERROR_VALIDATION_FAILURE;
    if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
    if (s->waited.empty()) return XR_ERROR_CALL_ORDER_INVALID;
    const bool discarded = s->frame_open;  // a begun frame that was never ended
    s->current = s->waited.front();
    s->waited.pop_front();
    s->current.begin_ns = core::now_ns();
    s->frame_open = true;
    frame_begun().notify_all();
    return discarded ? XR_FRAME_DISCARDED : XR_SUCCESS;
  });
}

XrResult api::xrEndFrame(XrSession session, const XrFrameEndInfo* info) {
  return guarded(__func__, [&]() -> XrResult {
    const core::TimeNs t_call = core::now_ns();
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_FRAME_END_INFO)) return XR_ERROR_VALIDATION_FAILURE;
    if (!s->running) return XR_ERROR_SESSION_NOT_RUNNING;
    if (!s->frame_open) return XR_ERROR_CALL_ORDER_INVALID;
    if (info->displayTime <= 0) return XR_ERROR_TIME_INVALID;
    if (info->environmentBlendMode < XR_ENVIRONMENT_BLEND_MODE_OPAQUE ||
        info->environmentBlendMode > XR_ENVIRONMENT_BLEND_MODE_ALPHA_BLEND)
      return XR_ERROR_VALIDATION_FAILURE;
    if (info->environmentBlendMode != XR_ENVIRONMENT_BLEND_MODE_OPAQUE)
      return XR_ERROR_ENVIRONMENT_BLEND_MODE_UNSUPPORTED;
    if (info->layerCount > kMaxLayers) return XR_ERROR_LAYER_LIMIT_EXCEEDED;
    if (info->layerCount && !info->layers) return XR_ERROR_VALIDATION_FAILURE;
    std::vector<ProjectionLayer> projections;
    for (uint32_t i = 0; i < info->layerCount; ++i) {
      const XrCompositionLayerBaseHeader* l = info->layers[i];
      if (!l) return XR_ERROR_LAYER_INVALID;
      if (l->type == XR_TYPE_COMPOSITION_LAYER_PROJECTION) {
        ProjectionLayer p;
        if (XrResult r = check_projection(s, *reinterpret_cast<const XrCompositionLayerProjection*>(l), &p);
            r != XR_SUCCESS)
          return r;
        projections.push_back(p);
      } else if (l->type == XR_TYPE_COMPOSITION_LAYER_QUAD) {
        // Accepted and validated, not composited: the panel shows projection layers only.
        if (XrResult r = check_quad(s, *reinterpret_cast<const XrCompositionLayerQuad*>(l)); r != XR_SUCCESS) return r;
      } else {
        return XR_ERROR_LAYER_INVALID;
      }
    }

    FrameRecord r = s->current;
    r.end_call_ns = t_call;
    r.layers = info->layerCount;
    const core::TimeNs t_gaze = core::now_ns();
    r.cpu_validate_ms = core::ns_to_ms(t_gaze - t_call);
    // The gaze a renderer has for this frame: what the tracker had delivered when it read
    // (now; in lockstep the frame's wake time), for the predicted display time. Never a
    // sample measured later than the read.
    const core::TimeNs read = s->clock.pacing() == Pacing::Lockstep ? r.wake_ns : t_gaze;
    const GazeSample g = s->instance->gaze->read(read, r.predicted_display_ns, display_epoch(*s));
    r.cpu_gaze_ms = core::ns_to_ms(core::now_ns() - t_gaze);
    r.gaze_sample_ns = g.sample_ns;
    r.gaze_receive_ns = g.receive_ns;
    r.gaze_read_ns = g.read_ns;
    r.gaze_valid = g.valid;
    r.gaze_dir = g.dir;
    s->frame_open = false;
    ++s->frames_ended;
    if (s->queued_state == XR_SESSION_STATE_SYNCHRONIZED && !s->exit_requested) {
      s->queue_state(XR_SESSION_STATE_VISIBLE);
      s->queue_state(XR_SESSION_STATE_FOCUSED);
    }
    const std::int64_t exit_after = s->instance->config.exit_after_frames;
    if (exit_after > 0 && s->frames_ended >= exit_after && !s->exit_requested) {
      FOVEA_LOG_INFO("FOVEA_EXIT_AFTER_FRAMES=%lld reached: stopping the session", static_cast<long long>(exit_after));
      request_exit(*s);
    }
    // Submitted at the call: the panel images below are the simulator's output, not part of
    // the application's frame, so their cost does not delay the display of this frame.
    r.displayed_ns = s->clock.displayed(r.predicted_display_ns, t_call);
    r.missed_vsyncs += (r.displayed_ns - r.predicted_display_ns) / s->clock.period();
    for (core::Eye e : {core::Eye::Left, core::Eye::Right})
      r.photon[std::size_t(e)] = s->clock.model().photons(r.displayed_ns, e);
    r.true_gaze_dir = s->instance->gaze->truth_at(r.photon[0].mid, display_epoch(*s));
    s->compositor->observe_frame(r.frame, g, r.displayed_ns);
    if (s->compositor->wants(r.frame)) {
      const core::TimeNs t0 = core::now_ns();
      try {
        const ComposeTimes t = s->compositor->compose(r.frame, projections);
        r.cpu_readback_ms = t.readback_ms;
        r.cpu_resample_ms = t.resample_ms;
        r.cpu_lens_ms = t.lens_ms;
        r.cpu_write_ms = t.write_ms;
        r.composited = true;
      } catch (const std::exception& e) {
        // Reported, and the application's frame still succeeds: it did nothing wrong.
        FOVEA_LOG_ERROR("compositor, frame %lld: %s", static_cast<long long>(r.frame), e.what());
      }
      r.compositor_ms = core::ns_to_ms(core::now_ns() - t0);
    }
    r.end_return_ns = core::now_ns();
    s->timing.write(r);
    return XR_SUCCESS;
  });
}

}  // namespace fovea::runtime

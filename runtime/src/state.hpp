#pragma once
// The runtime's objects and the handle table. Handles given to the application are opaque
// ids looked up in one table (never dereferenced), so a stale or garbage handle is reported
// as XR_ERROR_HANDLE_INVALID instead of crashing. One mutex serialises all commands.
#include <array>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "compositor.hpp"
#include "display_clock.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/hidden_area.hpp"
#include "gaze.hpp"
#include "head_motion.hpp"
#include "log.hpp"
#include "timing_log.hpp"
#include "vk_util.hpp"
#include "xr.hpp"

namespace fovea::runtime {

enum class Kind : std::uint8_t { Instance, Session, Space, ActionSet, Action, Swapchain };

struct Object {
  Kind kind;
  std::uint64_t id = 0;
  std::uint64_t parent = 0;  // destroying the parent destroys this object
  explicit Object(Kind k) : kind(k) {}
  virtual ~Object() = default;
};

// Settings read from the environment when the instance is created.
struct Config {
  std::string display = core::kDefaultDisplay;  // FOVEA_DISPLAY
  std::int64_t exit_after_frames = 0;  // FOVEA_EXIT_AFTER_FRAMES (0: never)
  std::string out_dir;                 // FOVEA_RUNTIME_OUT
  std::int64_t png_every = 1;          // FOVEA_RUNTIME_PNG_EVERY
  std::string gaze = "synthetic:1";    // FOVEA_GAZE (a devices::GazeSource URI)
  std::string head = "scripted";       // FOVEA_HEAD_POSE
  bool vk_validation = false;          // FOVEA_VK_VALIDATION=1
  LensMode lens = LensMode::Gpu;       // FOVEA_RUNTIME_LENS: gpu | cpu | off
  Pacing pacing = Pacing::Realtime;    // FOVEA_RUNTIME_PACING: realtime | lockstep
};
// Throws core::InputError naming the variable.
Config read_config();

struct QueuedEvent {
  XrEventDataBuffer data{};
  std::uint64_t session = 0;                   // for session state changes
  std::optional<XrSessionState> state;         // applied when delivered
};

struct Instance final : Object {
  Instance() : Object(Kind::Instance) {}
  Config config;
  core::DisplayPreset display;
  std::set<std::string> extensions;
  std::string app_name;
  std::vector<std::string> paths;  // XrPath p names paths[p - 1]
  std::deque<QueuedEvent> events;
  bool system_queried = false;
  bool graphics_requirements_queried = false;
  std::uint64_t session = 0;  // the one live session (0: none)
  // Suggested bindings per interaction profile, replaced wholesale by each suggestion.
  std::map<XrPath, std::vector<XrActionSuggestedBinding>> suggested;
  HeadMotion head;
  std::unique_ptr<GazeTracker> gaze;
  // The lens-derived hidden area of each eye (visibility masks, compositor).
  std::array<std::unique_ptr<core::HiddenAreaMask>, 2> hidden;
  // The VkInstance the runtime created for the application (enable2): xrCreateVulkanDeviceKHR
  // resolves vkCreateDevice through it.
  VkInstance vk_instance = VK_NULL_HANDLE;

  bool has(const char* ext) const { return extensions.count(ext) != 0; }
  XrPath path(const std::string& s);                  // interns
  const std::string* path_string(XrPath p) const;     // nullptr if invalid
};

struct Session final : Object {
  Session() : Object(Kind::Session) {}
  ~Session() override;
  Instance* instance = nullptr;
  XrSessionState state = XR_SESSION_STATE_UNKNOWN;  // as last delivered by xrPollEvent
  XrSessionState queued_state = XR_SESSION_STATE_UNKNOWN;  // after all queued transitions
  core::TimeNs created_ns = 0;
  bool running = false;
  bool exit_requested = false;
  // Graphics binding (XR_KHR_vulkan_enable / enable2).
  VkPhysicalDevice vk_physical = VK_NULL_HANDLE;
  VkDevice vk_device = VK_NULL_HANDLE;
  std::uint32_t queue_family = 0, queue_index = 0;
  VkQueue queue = VK_NULL_HANDLE;
  // Frame loop.
  DisplayClock clock{90};
  std::int64_t frames_ended = 0;
  bool frame_open = false;  // between xrBeginFrame and xrEndFrame
  std::deque<FrameRecord> waited;  // frames returned by xrWaitFrame, not yet begun
  bool wait_sleeping = false;      // an xrWaitFrame is sleeping until its wake time
  FrameRecord current;             // the open frame
  TimingLog timing;
  // Actions.
  bool actions_attached = false;
  std::vector<std::uint64_t> attached_sets;
  // The eye-gaze profile becomes current (and its change event is queued) at the first
  // xrSyncActions of a running session after an attach with an eye-gaze binding: the core
  // specification allows interaction-profile changes only during xrSyncActions.
  bool gaze_profile_bound = false;
  bool gaze_profile_active = false;
  std::unique_ptr<OneShotQueue> gpu;  // created at xrCreateSession
  std::unique_ptr<Compositor> compositor;

  void queue_state(XrSessionState s);
};

struct Space final : Object {
  Space() : Object(Kind::Space) {}
  Session* session = nullptr;
  bool is_action = false;
  XrReferenceSpaceType reference = XR_REFERENCE_SPACE_TYPE_LOCAL;
  std::uint64_t action = 0;
  XrPath subaction = XR_NULL_PATH;
  XrPosef offset{{0, 0, 0, 1}, {0, 0, 0}};
};

struct ActionSet final : Object {
  ActionSet() : Object(Kind::ActionSet) {}
  Instance* instance = nullptr;
  std::string name, localized;
  std::uint32_t priority = 0;
  bool attached = false;
};

struct Action final : Object {
  Action() : Object(Kind::Action) {}
  ActionSet* set = nullptr;
  std::string name, localized;
  XrActionType type = XR_ACTION_TYPE_BOOLEAN_INPUT;
  std::vector<XrPath> subactions;
  std::vector<XrPath> bound;  // binding paths in effect after attach
  bool gaze_bound() const;
};

struct Swapchain final : Object {
  Swapchain() : Object(Kind::Swapchain) {}
  ~Swapchain() override;
  Session* session = nullptr;
  XrSwapchainCreateInfo info{};
  std::vector<VkImage> images;
  std::vector<VkDeviceMemory> memory;
  std::vector<bool> layout_ready;  // transitioned to the layout the application expects
  std::deque<std::uint32_t> acquired;  // acquired, not yet released, oldest first
  bool waited = false;                 // the oldest of `acquired` has been waited on
  std::uint32_t next_image = 0;
  std::int64_t last_released = -1;
  bool ever_acquired = false;
  bool is_depth() const;
};

// ---- handle table -----------------------------------------------------------------------

std::mutex& api_mutex();
// Signalled (under api_mutex) when a frame is begun, a session ends or an object is
// destroyed: a pipelined xrWaitFrame blocks on it until the previous frame has begun.
std::condition_variable& frame_begun();
std::uint64_t add_object(std::unique_ptr<Object> obj, std::uint64_t parent);
Object* find_object(std::uint64_t id, Kind kind);
void destroy_object(std::uint64_t id);  // and its children, children first
std::vector<Object*> children_of(std::uint64_t id, Kind kind);

template <class T>
constexpr Kind kind_of();
template <> constexpr Kind kind_of<Instance>() { return Kind::Instance; }
template <> constexpr Kind kind_of<Session>() { return Kind::Session; }
template <> constexpr Kind kind_of<Space>() { return Kind::Space; }
template <> constexpr Kind kind_of<ActionSet>() { return Kind::ActionSet; }
template <> constexpr Kind kind_of<Action>() { return Kind::Action; }
template <> constexpr Kind kind_of<Swapchain>() { return Kind::Swapchain; }

template <class T, class Handle>
T* find(Handle h) {
  return static_cast<T*>(find_object(reinterpret_cast<std::uint64_t>(h), kind_of<T>()));
}
template <class Handle>
Handle to_handle(std::uint64_t id) {
  return reinterpret_cast<Handle>(id);
}

// ---- shared helpers ----------------------------------------------------------------------

// A non-null input/output structure of the given type, else XR_ERROR_VALIDATION_FAILURE.
inline bool has_type(const void* s, XrStructureType t) {
  return s && static_cast<const XrBaseInStructure*>(s)->type == t;
}
// The first structure of the given type in a `next` chain, or nullptr.
template <class T>
T* find_next(const void* next, XrStructureType t) {
  for (auto* p = static_cast<const XrBaseInStructure*>(next); p; p = p->next)
    if (p->type == t) return reinterpret_cast<T*>(const_cast<XrBaseInStructure*>(p));
  return nullptr;
}

// The two-call idiom for arrays of plain values.
template <class T>
XrResult two_call(std::uint32_t capacity, std::uint32_t* count, T* out, const std::vector<T>& items) {
  if (!count || (capacity && !out)) return XR_ERROR_VALIDATION_FAILURE;
  *count = static_cast<std::uint32_t>(items.size());
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < items.size()) return XR_ERROR_SIZE_INSUFFICIENT;
  for (size_t i = 0; i < items.size(); ++i) out[i] = items[i];
  return XR_SUCCESS;
}
XrResult two_call_string(std::uint32_t capacity, std::uint32_t* count, char* out, const std::string& s);

// A name field of fixed size holding a NUL-terminated string.
bool terminated(const char* s, size_t size);

XrTime xr_now();
// A unit quaternion (core-spec tolerance) and finite position.
bool valid_pose(const XrPosef& p);
// The head (VIEW space) in LOCAL space at time t.
core::Pose session_head_pose(const Session& s, XrTime t);
// Origin of the scripted head and gaze models: the display clock's epoch (the session's
// creation before the first frame).
core::TimeNs display_epoch(const Session& s);
// When the runtime reads its trackers for the application: now on the realtime clock; in
// lockstep the wake time of the newest frame xrWaitFrame returned (reads are then a function
// of the frame index), now before the first frame.
core::TimeNs tracker_read_time(const Session& s);
// Queues the state transitions that end a running session (down to STOPPING).
void request_exit(Session& s);
constexpr XrSystemId kSystemId = 1;
constexpr std::uint32_t kMaxLayers = 16;
constexpr std::uint32_t kMaxSwapchainSize = 4096;

// Runs a command body: serialised, exceptions turned into result codes (never thrown to the
// application).
template <class F>
XrResult guarded(const char* name, F&& body) {
  try {
    std::lock_guard lock(api_mutex());
    return body();
  } catch (const std::bad_alloc&) {
    return XR_ERROR_OUT_OF_MEMORY;
  } catch (const std::exception& e) {
    FOVEA_LOG_ERROR("%s: %s", name, e.what());
    return XR_ERROR_RUNTIME_FAILURE;
  }
}
}  // namespace fovea::runtime

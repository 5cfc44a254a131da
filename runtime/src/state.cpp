#include "state.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <unordered_map>

#include "fovea/core/error.hpp"

namespace fovea::runtime {
namespace {

struct Table {
  std::unordered_map<std::uint64_t, std::unique_ptr<Object>> objects;
  // Ids are never reused; the stride keeps them from looking like small integers or
  // pointers, so accidental confusion between handle types is caught too.
  std::uint64_t next = 0x1000;
};

Table& table() {
  static Table t;
  return t;
}

std::string env(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : fallback;
}

std::int64_t env_int(const char* name, std::int64_t fallback, std::int64_t min) {
  const char* v = std::getenv(name);
  if (!v || !*v) return fallback;
  char* end = nullptr;
  errno = 0;
  const long long x = std::strtoll(v, &end, 10);
  if (*end != '\0' || errno == ERANGE || x < min)
    throw core::InputError(std::string(name) + "=" + v + ": expected an integer >= " + std::to_string(min));
  return x;
}

}  // namespace

Config read_config() {
  Config c;
  c.display = env("FOVEA_DISPLAY", c.display);
  c.exit_after_frames = env_int("FOVEA_EXIT_AFTER_FRAMES", 0, 0);
  c.out_dir = env("FOVEA_RUNTIME_OUT", "");
  c.png_every = env_int("FOVEA_RUNTIME_PNG_EVERY", 1, 1);
  c.gaze = env("FOVEA_GAZE", c.gaze);
  c.head = env("FOVEA_HEAD_POSE", c.head);
  c.vk_validation = env("FOVEA_VK_VALIDATION", "0") == "1";
  c.lens = parse_lens_mode(env("FOVEA_RUNTIME_LENS", "gpu"));
  const std::string pacing = env("FOVEA_RUNTIME_PACING", "realtime");
  if (pacing != "realtime" && pacing != "lockstep")
    throw core::InputError("FOVEA_RUNTIME_PACING=" + pacing + ": expected realtime or lockstep");
  c.pacing = pacing == "lockstep" ? Pacing::Lockstep : Pacing::Realtime;
  return c;
}

XrPath Instance::path(const std::string& s) {
  for (size_t i = 0; i < paths.size(); ++i)
    if (paths[i] == s) return XrPath(i + 1);
  paths.push_back(s);
  return XrPath(paths.size());
}

const std::string* Instance::path_string(XrPath p) const {
  if (p == XR_NULL_PATH || p > paths.size()) return nullptr;
  return &paths[p - 1];
}

void Session::queue_state(XrSessionState s) {
  QueuedEvent e;
  auto* ev = reinterpret_cast<XrEventDataSessionStateChanged*>(&e.data);
  ev->type = XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED;
  ev->next = nullptr;
  ev->session = to_handle<XrSession>(id);
  ev->state = s;
  ev->time = xr_now();
  e.session = id;
  e.state = s;
  instance->events.push_back(e);
  queued_state = s;
}

bool Action::gaze_bound() const {
  for (XrPath p : bound) {
    const std::string* s = set->instance->path_string(p);
    if (s && *s == "/user/eyes_ext/input/gaze_ext/pose") return true;
  }
  return false;
}

bool Swapchain::is_depth() const {
  return (info.usageFlags & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) != 0;
}

std::mutex& api_mutex() {
  static std::mutex m;
  return m;
}

std::condition_variable& frame_begun() {
  static std::condition_variable cv;
  return cv;
}

std::uint64_t add_object(std::unique_ptr<Object> obj, std::uint64_t parent) {
  Table& t = table();
  const std::uint64_t id = t.next;
  t.next += 0x10;
  obj->id = id;
  obj->parent = parent;
  t.objects.emplace(id, std::move(obj));
  return id;
}

Object* find_object(std::uint64_t id, Kind kind) {
  Table& t = table();
  auto it = t.objects.find(id);
  if (it == t.objects.end() || it->second->kind != kind) return nullptr;
  return it->second.get();
}

std::vector<Object*> children_of(std::uint64_t id, Kind kind) {
  std::vector<Object*> out;
  for (auto& [oid, obj] : table().objects)
    if (obj->parent == id && obj->kind == kind) out.push_back(obj.get());
  return out;
}

void destroy_object(std::uint64_t id) {
  Table& t = table();
  std::vector<std::uint64_t> kids;
  for (auto& [oid, obj] : t.objects)
    if (obj->parent == id) kids.push_back(oid);
  for (std::uint64_t k : kids) destroy_object(k);
  t.objects.erase(id);
  frame_begun().notify_all();  // a blocked xrWaitFrame rechecks its session
}

XrResult two_call_string(std::uint32_t capacity, std::uint32_t* count, char* out, const std::string& s) {
  if (!count || (capacity && !out)) return XR_ERROR_VALIDATION_FAILURE;
  *count = static_cast<std::uint32_t>(s.size() + 1);
  if (capacity == 0) return XR_SUCCESS;
  if (capacity < s.size() + 1) return XR_ERROR_SIZE_INSUFFICIENT;
  std::memcpy(out, s.c_str(), s.size() + 1);
  return XR_SUCCESS;
}

bool terminated(const char* s, size_t size) { return std::memchr(s, '\0', size) != nullptr; }

XrTime xr_now() { return core::now_ns(); }

}  // namespace fovea::runtime

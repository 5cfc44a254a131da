#include "fovea/devices/hid_emulator.hpp"

#include <chrono>
#include <cmath>
#include <cstring>

#include "fovea/core/error.hpp"

namespace fovea::devices::hid {

namespace {

// Writes short items, choosing the smallest data size that holds the value.
class Builder {
 public:
  std::vector<std::uint8_t> bytes;
  Builder& item(int type, int tag, std::int64_t v, bool is_signed, int force_size = 0) {
    int n = force_size;
    if (!n) {
      if (is_signed) n = (v >= -128 && v <= 127) ? 1 : (v >= -32768 && v <= 32767) ? 2 : 4;
      else n = v <= 0xFF ? 1 : v <= 0xFFFF ? 2 : 4;
    }
    bytes.push_back(static_cast<std::uint8_t>(tag << 4 | type << 2 | (n == 4 ? 3 : n)));
    for (int i = 0; i < n; ++i) bytes.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * i)));
    return *this;
  }
  Builder& page(std::uint16_t p) { return item(1, 0x0, p, false); }
  Builder& use(std::uint32_t u) { return item(2, 0x0, u, false); }
  Builder& use_ext(std::uint16_t p, std::uint16_t u) { return item(2, 0x0, std::int64_t(p) << 16 | u, false, 4); }
  Builder& use_min(std::uint32_t u) { return item(2, 0x1, u, false); }
  Builder& use_max(std::uint32_t u) { return item(2, 0x2, u, false); }
  Builder& collection(int kind) { return item(0, 0xA, kind, false); }
  Builder& end() {
    bytes.push_back(0xC0);
    return *this;
  }
  Builder& logical(std::int64_t lo, std::int64_t hi) { return item(1, 0x1, lo, true).item(1, 0x2, hi, true); }
  Builder& unit(std::uint32_t u) { return item(1, 0x6, u, false); }
  Builder& exponent(int e) { return item(1, 0x5, e & 0xF, false, 1); }
  Builder& size(int s) { return item(1, 0x7, s, false); }
  Builder& count(int c) { return item(1, 0x9, c, false); }
  Builder& id(int i) { return item(1, 0x8, i, false); }
  Builder& input(int f) { return item(0, 0x8, f, false); }
  Builder& feature(int f) { return item(0, 0xB, f, false); }
  Builder& push() {  // no data bytes
    bytes.push_back(0xA4);
    return *this;
  }
  Builder& pop() {
    bytes.push_back(0xB4);
    return *this;
  }
};

constexpr int kApplication = 1, kPhysical = 0, kLogical = 2;
constexpr std::uint32_t kUnitCm = 0x11, kUnitSecond = 0x1001, kUnitHertz = 0xF001;
constexpr int kCnstVarAbs = 0x03, kDataVarAbs = 0x02, kDataVarAbsNull = 0x42, kCnst = 0x01;

std::vector<std::uint8_t> ms_descriptor() {
  namespace u = usage;
  Builder b;
  b.page(kEyeTrackerPage).use(u::kEyeTracker).collection(kApplication);
  // 0x10 Tracking Data (input): 64-bit µs timestamp as 8 bytes, then int32 µm positions.
  b.id(0x10).use(u::kTrackingData).collection(kPhysical);
  b.use(u::kSensorTimestamp).logical(0, 0xFF).size(8).count(8).unit(kUnitSecond).exponent(-6).input(kCnstVarAbs);
  b.logical(-2000000, 2000000).size(32).unit(kUnitCm).exponent(-4);
  b.use(u::kGazePoint).collection(kPhysical).use(u::kPositionX).use(u::kPositionY).count(2).input(kCnstVarAbs).end();
  for (int c : {u::kLeftEyePosition, u::kRightEyePosition, u::kHeadPosition, u::kHeadDirectionPoint})
    b.use(c).collection(kPhysical).use(u::kPositionX).use(u::kPositionY).use(u::kPositionZ).count(3).input(kCnstVarAbs).end();
  b.end();
  // 0x11 Capabilities (feature): tracker quality, then 5 × int32 µm.
  b.id(0x11).use(u::kCapabilities).collection(kLogical);
  b.unit(0).exponent(0).use(u::kTrackerQuality).logical(0, 1).size(8).count(1).feature(kCnstVarAbs);
  b.unit(kUnitCm).exponent(-4).logical(0, 2000000).size(32).count(5);
  for (int x = u::kMinimumTrackingDistance; x <= u::kMaximumScreenPlaneHeight; ++x) b.use(x);
  b.feature(kCnstVarAbs).end();
  // 0x12 Configuration (feature).
  b.id(0x12).use(u::kConfiguration).collection(kLogical);
  b.unit(0).exponent(0).logical(0, 0xFFFF).size(16).count(2).use(u::kDisplayManufacturerId).use(u::kDisplayProductId).feature(kCnstVarAbs);
  b.logical(0, 0x7FFFFFFF).size(32).count(1).use(u::kDisplaySerialNumber).feature(kCnstVarAbs);
  b.logical(0, 0xFFFF).size(16).count(1).use(u::kDisplayManufacturerDate).feature(kCnstVarAbs);
  b.unit(kUnitCm).exponent(-4).logical(0, 2000000).size(32).count(2).use(u::kCalibratedScreenWidth).use(u::kCalibratedScreenHeight).feature(kCnstVarAbs);
  b.end();
  // 0x13 Status (feature and input): configuration status u8, sampling frequency u16 Hz.
  b.id(0x13).use(u::kStatus).collection(kLogical);
  b.unit(0).exponent(0).logical(0, 4).size(8).count(1).use(u::kConfigurationStatus).feature(kCnstVarAbs);
  b.unit(kUnitHertz).logical(0, 0xFFFF).size(16).count(1).use(u::kSamplingFrequency).feature(kCnstVarAbs);
  b.unit(0).logical(0, 4).size(8).count(1).use(u::kConfigurationStatus).input(kCnstVarAbs);
  b.unit(kUnitHertz).logical(0, 0xFFFF).size(16).count(1).use(u::kSamplingFrequency).input(kCnstVarAbs);
  b.end();
  // 0x14 Control (feature): Device Mode Request, written by the host.
  b.id(0x14).use(u::kControl).collection(kLogical);
  b.unit(0).logical(0, 7).size(8).count(1).use(u::kDeviceModeRequest).feature(kDataVarAbs).end();
  b.end();
  return b.bytes;
}

std::vector<std::uint8_t> compact_descriptor() {
  namespace u = usage;
  Builder b;
  b.page(kEyeTrackerPage).use(u::kEyeTracker).collection(kApplication);
  b.id(0x21);
  b.page(0xFF00).use(0x01).logical(0, 255).size(8).count(1).input(kDataVarAbs);  // vendor frame counter first
  b.page(kEyeTrackerPage).use(u::kTrackingData).collection(kPhysical);
  b.use(u::kGazePoint).collection(kPhysical).push();
  b.unit(kUnitCm).exponent(-2).logical(0, 32767).size(16).count(2).use(u::kPositionY).use(u::kPositionX).input(kDataVarAbsNull);
  b.pop().end();
  b.size(4).count(1).input(kCnst);                                                  // padding nibble
  b.page(0xFF00).use(0x02).logical(0, 15).size(4).count(1).input(kDataVarAbs);     // vendor nibble
  b.use_ext(kEyeTrackerPage, u::kSensorTimestamp).unit(kUnitSecond).exponent(-5).logical(0, 0xFFFF).size(16).count(2).input(kDataVarAbs);
  b.page(kEyeTrackerPage).use(u::kLeftEyePosition).collection(kPhysical);
  b.unit(kUnitCm).exponent(-1).logical(-32768, 32767).size(16).count(3).use_min(u::kPositionX).use_max(u::kPositionZ).input(kDataVarAbs);
  b.end().end();
  b.id(0x22).unit(0).exponent(0).use(u::kConfiguration).collection(kLogical);
  b.unit(kUnitCm).exponent(-1).logical(0, 32767).size(16).count(2).use(u::kCalibratedScreenHeight).use(u::kCalibratedScreenWidth).feature(kDataVarAbs);
  b.end();
  b.id(0x23).unit(0).exponent(0).use(u::kStatus).collection(kLogical);
  b.unit(kUnitHertz).logical(0, 2000).size(16).count(1).use(u::kSamplingFrequency).feature(kDataVarAbs);
  b.unit(0).logical(0, 4).size(8).count(1).use(u::kConfigurationStatus).feature(kDataVarAbs);
  b.end();
  b.id(0x24).use(u::kControl).collection(kLogical);
  b.logical(0, 7).size(8).count(1).use(u::kDeviceModeRequest).feature(kDataVarAbs).end();
  b.end();
  return b.bytes;
}

}  // namespace

std::vector<std::uint8_t> reference_descriptor(std::string_view layout) {
  if (layout == "ms") return ms_descriptor();
  if (layout == "compact") return compact_descriptor();
  throw core::InputError("unknown emulated HID layout \"" + std::string(layout) + "\" (ms, compact)");
}

EmulatedEyeTracker::EmulatedEyeTracker(std::vector<std::uint8_t> descriptor, const DeviceConfig& cfg, const core::View& screen)
    : codec_(descriptor), cfg_(cfg), screen_(screen) {
  // The device works with the values its reports can carry (e.g. a screen size in whole mm).
  DeviceConfig reported = cfg_;
  for (std::uint8_t id : codec_.startup_feature_ids()) codec_.decode_feature(codec_.encode_feature(id, cfg_), reported);
  cfg_ = reported;
}

std::vector<std::uint8_t> EmulatedEyeTracker::get_feature(std::uint8_t id) const { return codec_.encode_feature(id, cfg_); }

bool EmulatedEyeTracker::set_feature(std::span<const std::uint8_t> r) {
  const Value& v = codec_.layout().device_mode;
  const bool ids = codec_.descriptor().uses_report_ids;
  if (!v.found || r.empty() || (ids && r[0] != v.report_id) || r.size() < codec_.descriptor().report_bytes(ReportType::Feature, v.report_id))
    return false;
  std::int64_t raw = 0;
  if (!read_value(r, v, ids, raw) || !v.in_range(raw)) return false;
  mode_ = static_cast<std::uint8_t>(raw);
  return true;
}

std::vector<std::uint8_t> EmulatedEyeTracker::input_report(const GazeSample& s) const {
  HidGaze g;
  const Value& ts = codec_.layout().timestamp;
  g.timestamp_raw = std::llround(static_cast<double>(s.device_time_ns) * 1e-9 / ts.si_per_unit);  // wraps in write_bits
  g.gaze_valid = false;
  if (s.tracked()) {
    if (auto px = screen_.dir_to_pixel(s.combined.dir); px && screen_.contains_pixel(*px)) {
      g.gaze_valid = true;
      g.gaze_x_m = px->x / screen_.width() * cfg_.screen_w_m;
      g.gaze_y_m = px->y / screen_.height() * cfg_.screen_h_m;
    }
  }
  for (int e = 0; e < 2; ++e) {  // eyes 32 mm either side, 60 cm in front of the tracker
    g.eye_valid[e] = s.eye(e == 0 ? core::Eye::Left : core::Eye::Right).tracked();
    g.eye_pos_m[e] = glm::dvec3(e == 0 ? -0.032 : 0.032, 0.0, 0.6);
  }
  return codec_.encode_gaze(g);
}

namespace {
std::uint64_t splitmix(std::uint64_t& s) {
  std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
DeviceConfig emulated_config(const core::View& screen) {
  DeviceConfig c;
  c.screen_w_m = 0.5;  // a 0.5 m wide calibrated screen with the view's aspect ratio
  c.screen_h_m = 0.5 * screen.height() / screen.width();
  c.sampling_hz = 120;
  c.configuration_status = 1;
  c.tracker_quality = 1;
  c.min_distance_m = 0.5;
  c.optimum_distance_m = 0.65;
  c.max_distance_m = 0.9;
  return c;
}
}  // namespace

EmulatedTransport::EmulatedTransport(std::unique_ptr<SampleStream> gaze, std::string_view layout, const core::View& screen,
                                     const Faults& faults)
    : gaze_(std::move(gaze)),
      device_(reference_descriptor(layout), emulated_config(screen), screen),
      faults_(faults),
      layout_(layout),
      rng_(faults.seed) {
  if (faults_.realtime) thread_ = std::thread([this] { device_thread(); });
}

EmulatedTransport::~EmulatedTransport() {
  {
    std::lock_guard lock(mutex_);  // under the lock: the device thread cannot miss the wake-up
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

core::TimeNs EmulatedTransport::now() const {
  if (faults_.realtime) return core::now_ns();
  return last_host_ + faults_.clock_offset_ns * (last_host_ == 0);
}

DeviceInfo EmulatedTransport::info() const {
  DeviceInfo i;
  i.transport = "emulated";
  i.path = "emulated:" + layout_;
  i.vendor_id = 0xF0E0;
  i.product_id = layout_ == "ms" ? 0x0010 : 0x0021;
  i.usage_page = kEyeTrackerPage;
  i.usage = usage::kEyeTracker;
  i.manufacturer = "Fovea";
  i.product = "Emulated eye tracker (" + layout_ + " layout)";
  return i;
}

std::vector<std::uint8_t> EmulatedTransport::report_descriptor() { return device_.codec().descriptor_bytes(); }

bool EmulatedTransport::produce(Pending& out) {
  out = Pending{};
  if (!status_sent_ && !device_.codec().encode_status_input(device_.config()).empty()) {
    out.bytes = device_.codec().encode_status_input(device_.config());
    status_sent_ = true;
    return true;
  }
  GazeSample s;
  if (!gaze_->next(s)) return false;
  out.bytes = device_.input_report(s);
  out.gaze = true;
  out.device_ns = s.device_time_ns;
  return true;
}

void EmulatedTransport::device_thread() {
  std::unique_lock lock(mutex_);
  cv_.wait(lock, [&] { return enabled_ || stop_; });  // the stream is off until the host enables it
  const core::TimeNs start = core::now_ns();
  bool have_first = false;
  core::TimeNs first = 0;
  Pending p;
  while (!stop_) {
    lock.unlock();
    const bool more = produce(p);
    lock.lock();
    if (!more) break;
    if (!have_first && p.gaze) {
      have_first = true;
      first = p.device_ns;
    }
    // Due on the host clock at the sample's offset from the first sample.
    const core::TimeNs due = start + (have_first ? p.device_ns - first : 0);
    cv_.wait_for(lock, std::chrono::nanoseconds(std::max<core::TimeNs>(0, due - core::now_ns())), [&] { return stop_.load(); });
    if (stop_) break;
    p.host_ns = core::now_ns();
    if (p.host_ns < silent_until_) continue;  // stalled: the report is lost
    constexpr std::size_t kDeviceBuffer = 4096;  // a host that does not read loses the oldest
    if (queue_.size() >= kDeviceBuffer) queue_.pop_front();
    queue_.push_back(std::move(p));
    cv_.notify_all();
  }
  produced_all_ = true;
  cv_.notify_all();
}

InputReport EmulatedTransport::read_input(std::span<std::uint8_t> buf, int timeout_ms) {
  ++reads_;
  if (faults_.unplug_after >= 0 && reads_ > static_cast<std::uint64_t>(faults_.unplug_after))
    throw TransportError("emulated device: unplugged", true);
  if (faults_.stall_every > 0 && reads_ % faults_.stall_every == 0) {
    if (faults_.realtime) {
      std::lock_guard lock(mutex_);
      silent_until_ = core::now_ns() + faults_.stall_ns;
    }
    throw TransportError("emulated device: endpoint stalled", false);
  }
  Pending p;
  if (faults_.realtime) {
    std::unique_lock lock(mutex_);
    cv_.wait_for(lock, std::chrono::milliseconds(std::max(0, timeout_ms)), [&] { return !queue_.empty() || produced_all_; });
    if (queue_.empty()) {
      if (produced_all_) exhausted_ = true;
      return {};
    }
    p = std::move(queue_.front());
    queue_.pop_front();
  } else {
    if (!enabled_) return {};  // the stream is off until the host enables it
    if (!produce(p)) {
      exhausted_ = true;
      return {};
    }
  }
  if (faults_.garbage_every > 0 && reads_ % faults_.garbage_every == 0)
    for (auto& x : p.bytes) x = static_cast<std::uint8_t>(splitmix(rng_));
  std::size_t n = std::min(p.bytes.size(), buf.size());
  if (faults_.short_every > 0 && reads_ % faults_.short_every == 0) n = n / 2;
  std::memcpy(buf.data(), p.bytes.data(), n);
  if (faults_.realtime) return {n, p.host_ns};
  // Host receive time: device clock with offset and drift, plus an exponential delay.
  const double u = (static_cast<double>(splitmix(rng_) >> 11) + 0.5) * 0x1.0p-53;
  const core::TimeNs delay = std::llround(-std::log(u) * static_cast<double>(faults_.delay_ns));
  core::TimeNs host = p.device_ns + faults_.clock_offset_ns + std::llround(static_cast<double>(p.device_ns) * faults_.drift_ppm * 1e-6) + delay;
  host = std::max(host, last_host_);  // a host clock never runs backwards
  last_host_ = host;
  return {n, host};
}

std::vector<std::uint8_t> EmulatedTransport::get_feature(std::uint8_t id, std::size_t) {
  if (faults_.feature_stall) throw TransportError("emulated device: GET_REPORT stalled", false);
  auto r = device_.get_feature(id);
  if (r.empty()) throw TransportError("emulated device: no feature report " + std::to_string(id), false);
  return r;
}

void EmulatedTransport::set_feature(std::span<const std::uint8_t> report) {
  if (faults_.feature_stall) throw TransportError("emulated device: SET_REPORT stalled", false);
  if (!device_.set_feature(report)) throw TransportError("emulated device: SET_REPORT rejected", false);
  {
    std::lock_guard lock(mutex_);
    enabled_ = (device_.mode() & kModeGazePoint) != 0;
  }
  cv_.notify_all();
}

}  // namespace fovea::devices::hid

#include "fovea/devices/hid_stream.hpp"

#include "read_notes.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "fovea/core/error.hpp"
#include "line_reader.hpp"
#include "text.hpp"

namespace fovea::devices::hid {

// ---- GazeMapper ----------------------------------------------------------------------
bool GazeMapper::map(std::span<const std::uint8_t> report, GazeSample& out, std::string& reason) {
  HidGaze g;
  if (!codec_.decode_input(report, g, cfg_, reason)) return false;
  if (!(cfg_.screen_w_m > 0 && cfg_.screen_h_m > 0))
    throw core::InputError("HID eye tracker: no Calibrated Screen Width/Height (or Maximum Screen Plane size) known; "
                           "cannot map the gaze point");
  // Timestamps narrower than 64 bits wrap: unwrap by the value's width. The unwrapped count
  // and its value in ns must stay within int64; a report past that is dropped, not wrapped.
  const Value& ts = codec_.layout().timestamp;
  std::int64_t raw = g.timestamp_raw;
  if (ts.bits < 63) {
    const std::int64_t span = std::int64_t(1) << ts.bits;
    std::int64_t wraps = wraps_, unwrapped = 0;
    bool overflow = __builtin_add_overflow(raw, wraps, &unwrapped);
    if (!overflow && have_last_ && unwrapped < last_raw_ - span / 2)
      overflow = __builtin_add_overflow(wraps, span, &wraps) || __builtin_add_overflow(raw, wraps, &unwrapped);
    if (overflow) {
      reason = "time_overflow";
      return false;
    }
    wraps_ = wraps;
    raw = unwrapped;
  }
  const double device_d = static_cast<double>(raw) * ts.si_per_unit * 1e9;
  if (!(std::abs(device_d) < 9.2e18)) {  // e.g. a 2^62 µs stamp: not representable in int64 ns
    reason = "time_overflow";
    return false;
  }
  const core::TimeNs device = std::llround(device_d);
  if (have_last_ && device <= last_device_) {
    reason = device == last_device_ ? "duplicate_time" : "non_monotonic_time";
    return false;
  }
  have_last_ = true;
  last_raw_ = raw;
  last_device_ = device;
  out = GazeSample{};
  out.device_time_ns = device;
  if (g.gaze_valid) {
    const double px = g.gaze_x_m / cfg_.screen_w_m * screen_.width(), py = g.gaze_y_m / cfg_.screen_h_m * screen_.height();
    out.combined.dir = screen_.pixel_to_dir({px, py});
    out.combined.flags = kTracked;
    out.combined.confidence = 1;
  } else {
    out.combined.dir = screen_.centre_dir();
  }
  out.left = out.right = out.combined;
  if (g.gaze_valid)
    for (int e = 0; e < 2; ++e)
      if (codec_.layout().eye[e][0].found && !g.eye_valid[e]) {
        EyeGaze& eg = e == 0 ? out.left : out.right;
        eg.flags = kLost;
        eg.confidence = 0;
      }
  return true;
}

// ---- CaptureWriter -------------------------------------------------------------------
CaptureWriter::CaptureWriter(const std::string& path, const DeviceInfo& info, std::span<const std::uint8_t> descriptor)
    : path_(path), tmp_(path + ".tmp." + std::to_string(::getpid())) {
  f_ = std::fopen(tmp_.c_str(), "wb");
  if (!f_) throw std::runtime_error(path + ": cannot open for writing");
  const nlohmann::json j = {{"transport", info.transport}, {"path", info.path},     {"vendor_id", info.vendor_id},
                            {"product_id", info.product_id}, {"manufacturer", info.manufacturer}, {"product", info.product}};
  std::fprintf(f_, "fovea-hid-capture 1\n# times: host monotonic ns; reports: hex bytes, report ID first (docs/hid.md)\n");
  std::fprintf(f_, "info %s\ndescriptor %s\n", j.dump().c_str(), to_hex(descriptor).c_str());
}

CaptureWriter::~CaptureWriter() {
  if (f_) {
    std::fclose(f_);
    std::remove(tmp_.c_str());
  }
}

void CaptureWriter::line(const char* kind, core::TimeNs t, std::span<const std::uint8_t> r) {
  if (f_) std::fprintf(f_, "%s %lld %s\n", kind, static_cast<long long>(t), to_hex(r).c_str());
}
void CaptureWriter::get_feature(core::TimeNs t, std::span<const std::uint8_t> r) { line("get_feature", t, r); }
void CaptureWriter::set_feature(core::TimeNs t, std::span<const std::uint8_t> r) { line("set_feature", t, r); }
void CaptureWriter::input(core::TimeNs t, std::span<const std::uint8_t> r) { line("input", t, r); }

void CaptureWriter::finish() {
  if (!f_) return;
  const bool ok = !std::ferror(f_);
  const bool closed = std::fclose(f_) == 0;
  f_ = nullptr;
  if (!ok || !closed) {
    std::remove(tmp_.c_str());
    throw std::runtime_error(path_ + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp_, path_, ec);
  if (ec) throw std::runtime_error(path_ + ": rename failed: " + ec.message());
}

// ---- HidGazeStream -------------------------------------------------------------------
HidGazeStream::HidGazeStream(std::unique_ptr<Transport> t, const SourceOptions& opt, const std::string& capture_path)
    : transport_(std::move(t)) {
  info_ = transport_->info();
  std::vector<std::uint8_t> desc;
  try {
    desc = transport_->report_descriptor();
  } catch (const TransportError& e) {
    throw core::InputError(info_.path + ": cannot read the report descriptor: " + e.what());
  }
  try {
    codec_ = std::make_unique<EyeTrackerCodec>(desc);
  } catch (const core::InputError& e) {
    throw core::InputError(info_.path + ": " + e.what());
  }
  mapper_ = std::make_unique<GazeMapper>(*codec_, opt.screen_view());
  if (!capture_path.empty()) capture_ = std::make_unique<CaptureWriter>(capture_path, info_, desc);
  // Start-up: read capabilities / configuration / status, then enable the gaze stream.
  for (std::uint8_t id : codec_->startup_feature_ids()) {
    try {
      const auto r = transport_->get_feature(id, codec_->descriptor().report_bytes(ReportType::Feature, id));
      if (capture_) capture_->get_feature(transport_->now(), r);
      mapper_->feature(r);
    } catch (const TransportError& e) {
      stats_.notes.push_back("GET_REPORT(feature " + std::to_string(id) + ") failed: " + e.what());
    }
  }
  const auto mode = codec_->mode_request(static_cast<std::uint8_t>(
      kModeGazePoint | (codec_->layout().eye[0][0].found || codec_->layout().eye[1][0].found ? kModeEyePosition : 0)));
  if (!mode.empty()) {
    try {
      transport_->set_feature(mode);
      if (capture_) capture_->set_feature(transport_->now(), mode);
    } catch (const TransportError& e) {
      stats_.notes.push_back(std::string("SET_REPORT(Device Mode Request) failed: ") + e.what());
    }
  }
  config_ = mapper_->config();
  if (!(config_.screen_w_m > 0 && config_.screen_h_m > 0))
    throw core::InputError(info_.path + ": the device did not report its calibrated screen size" +
                           (stats_.notes.empty() ? std::string() : " (" + stats_.notes.front() + ")"));
  thread_ = std::thread([this] { run(); });
}

HidGazeStream::~HidGazeStream() {
  try {
    stop();
  } catch (const std::exception&) {  // a failed capture write must not escape a destructor
  }
}

void HidGazeStream::stop() {
  stop_ = true;
  space_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (capture_) capture_->finish();
}

void HidGazeStream::run() {
  std::vector<std::uint8_t> buf(4096);
  int consecutive_errors = 0;
  while (!stop_) {
    InputReport r;
    try {
      r = transport_->read_input(buf, 50);
      consecutive_errors = 0;
    } catch (const TransportError& e) {
      std::lock_guard lock(mutex_);
      ++stats_.transport_errors;
      if (e.disconnected() || ++consecutive_errors > 100) {
        stats_.disconnected = e.disconnected();
        stats_.notes.push_back(e.what());
        break;
      }
      continue;  // a stall: retry
    }
    if (r.size == 0) {
      if (transport_->exhausted()) break;
      continue;
    }
    const std::span<const std::uint8_t> rep(buf.data(), r.size);
    if (capture_) capture_->input(r.host_ns, rep);
    GazeSample s;
    std::string reason;
    std::unique_lock lock(mutex_);
    ++stats_.reports;
    bool ok = false;
    try {
      ok = mapper_->map(rep, s, reason);
    } catch (const core::InputError& e) {
      reason = "unmappable";
    }
    if (!ok) {
      if (reason.empty()) ++stats_.status_reports;
      else ++stats_.dropped[reason];
      continue;
    }
    clock_.add(s.device_time_ns, r.host_ns);
    s.host_time_ns = r.host_ns;
    s.t_ns = std::max(clock_.to_host(s.device_time_ns), last_t_ + 1);  // monotonic on the host clock
    last_t_ = s.t_ns;
    stats_.clock_drift_ppm = clock_.drift_ppm();
    ++stats_.samples;
    space_.wait(lock, [&] { return queue_.size() < 8192 || stop_; });
    queue_.push_back(s);
  }
  finished_ = true;
}

bool HidGazeStream::next(GazeSample& out) {
  std::lock_guard lock(mutex_);
  if (queue_.empty()) return false;
  out = queue_.front();
  queue_.pop_front();
  space_.notify_all();
  return true;
}

std::string HidGazeStream::describe() const {
  char id[16];
  std::snprintf(id, sizeof id, "%04x:%04x", info_.vendor_id, info_.product_id);
  return info_.transport + ":" + id + " " + info_.path;
}

StreamStats HidGazeStream::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

// ---- HidCaptureStream ----------------------------------------------------------------
struct HidCaptureStream::Lines {
  detail::LineReader reader;
  detail::OffViewCount off_view;
  explicit Lines(const std::string& p) : reader(p) {}
};

HidCaptureStream::HidCaptureStream(const std::string& path, const SourceOptions& opt)
    : path_(path), opt_(opt) {
  if (!std::filesystem::is_regular_file(path)) throw core::InputError(path + ": no such file");
  lines_ = std::make_unique<Lines>(path);
  rewind();
}
HidCaptureStream::~HidCaptureStream() = default;

void HidCaptureStream::rewind() {
  lines_->reader.rewind();
  stats_ = ReadStats{};
  lines_->off_view.reset();
  have_first_ = ended_ = false;
  detail::Line l;
  // Header: magic, then everything up to and including the descriptor.
  bool magic = false;
  while (lines_->reader.next(l)) {
    ++stats_.lines;
    const std::string_view t = detail::trim(l.text);
    if (t.empty() || t[0] == '#') continue;
    if (!magic) {
      if (t != "fovea-hid-capture 1") throw core::InputError(path_ + ":" + std::to_string(l.number) + ": not a fovea HID capture (expected \"fovea-hid-capture 1\")");
      magic = true;
      continue;
    }
    if (t.rfind("info ", 0) == 0) continue;
    if (t.rfind("descriptor ", 0) == 0) {
      if (!from_hex(t.substr(11), buf_)) throw core::InputError(path_ + ":" + std::to_string(l.number) + ": bad hex in the descriptor");
      try {
        codec_ = std::make_unique<EyeTrackerCodec>(buf_);
      } catch (const core::InputError& e) {
        throw core::InputError(path_ + ":" + std::to_string(l.number) + ": " + e.what());
      }
      mapper_ = std::make_unique<GazeMapper>(*codec_, opt_.screen_view());
      return;
    }
    throw core::InputError(path_ + ":" + std::to_string(l.number) + ": expected the descriptor line before any report");
  }
  throw core::InputError(path_ + ": no report descriptor in the capture");
}

bool HidCaptureStream::next(GazeSample& out) {
  detail::Line l;
  std::vector<std::string_view> f;
  while (lines_->reader.next(l)) {
    ++stats_.lines;
    stats_.peak_buffer_bytes = lines_->reader.peak_bytes();
    auto drop = [&](const char* why) { ++stats_.dropped[l.unterminated ? "truncated_last_line" : why]; };
    if (l.overlong) {
      drop("line_too_long");
      continue;
    }
    const std::string_view t = detail::trim(l.text);
    if (t.empty() || t[0] == '#') continue;
    const auto sp1 = t.find(' ');
    const std::string_view kind = t.substr(0, sp1);
    if (kind != "input" && kind != "get_feature" && kind != "set_feature") {
      drop("bad_line");
      continue;
    }
    const std::string_view rest = sp1 == std::string_view::npos ? std::string_view() : t.substr(sp1 + 1);
    const auto sp2 = rest.find(' ');
    std::int64_t host = 0;
    if (sp2 == std::string_view::npos || detail::parse_int64(rest.substr(0, sp2), host) != detail::Num::Ok ||
        !from_hex(rest.substr(sp2 + 1), buf_)) {
      drop("bad_line");
      continue;
    }
    if (kind == "get_feature") {
      mapper_->feature(buf_);
      continue;
    }
    if (kind == "set_feature") continue;  // the host's own writes: on record only
    std::string reason;
    if (!mapper_->map(buf_, out, reason)) {
      if (!reason.empty()) drop(reason.c_str());
      continue;
    }
    if (!have_first_) {
      have_first_ = true;
      first_ = out.device_time_ns;
    }
    if (__builtin_sub_overflow(out.device_time_ns, first_, &out.t_ns)) {
      drop("time_overflow");
      continue;
    }
    out.host_time_ns = host;
    ++stats_.samples;
    if (out.tracked()) ++stats_.tracked;
    lines_->off_view.add(opt_.screen_view(), out);
    return true;
  }
  stats_.peak_buffer_bytes = lines_->reader.peak_bytes();
  if (!ended_) {  // the notes once per pass, as the other readers give them
    ended_ = true;
    if (lines_->reader.truncated()) detail::add_note(stats_, detail::truncated_note(path_));
    const core::View v = opt_.screen_view();
    lines_->off_view.note(stats_, path_, v.width(), v.height());
  }
  return false;
}

}  // namespace fovea::devices::hid

// Streaming readers for recorded gaze. Coordinate conventions per format: docs/gaze.md.
#include "fovea/devices/readers.hpp"

#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <unistd.h>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "fovea/core/error.hpp"
#include "fovea/core/input_limits.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/json.hpp"
#include "fovea/devices/hid_stream.hpp"
#include "line_reader.hpp"
#include "read_notes.hpp"
#include "text.hpp"

namespace fovea::devices {

using detail::Line;
using detail::Num;

std::uint64_t ReadStats::dropped_total() const {
  std::uint64_t n = 0;
  for (const auto& [k, v] : dropped) n += v;
  return n;
}

const char* format_name(Format f) {
  switch (f) {
    case Format::Fovea: return "fovea";
    case Format::PupilCore: return "pupil-core";
    case Format::Neon: return "neon";
    case Format::TobiiG3: return "tobii-g3";
    case Format::EyelinkAsc: return "eyelink-asc";
    case Format::HidCapture: return "hid-capture";
  }
  return "?";
}

const char* device_clock_name(Format f) {
  switch (f) {
    case Format::Fovea: return "t_ns of the source recording";
    case Format::PupilCore: return "Pupil time (gaze_timestamp, s, arbitrary epoch)";
    case Format::Neon: return "UTC (timestamp [ns] since 1970)";
    case Format::TobiiG3: return "s since the Glasses 3 recording start";
    case Format::EyelinkAsc: return "EyeLink tracker clock (ms)";
    case Format::HidCapture: return "the tracker's sensor timestamp (unwrapped, docs/hid.md)";
  }
  return "?";
}

namespace {
constexpr const char* kFormatList = "fovea, pupil-core, neon, tobii-g3, eyelink-asc, hid-capture";
}

Format parse_format(std::string_view n) {
  for (Format f : {Format::Fovea, Format::PupilCore, Format::Neon, Format::TobiiG3, Format::EyelinkAsc, Format::HidCapture})
    if (n == format_name(f)) return f;
  throw core::InputError("unknown gaze format \"" + std::string(n) + "\" (" + kFormatList + ")");
}

Format detect_format(const std::string& path) {
  gzFile g = gzopen(path.c_str(), "rb");
  if (!g) throw core::InputError(path + ": cannot open for reading");
  std::string head(8192, '\0');
  const int n = gzread(g, head.data(), static_cast<unsigned>(head.size()));
  gzclose(g);
  head.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
  if (head.rfind("\xEF\xBB\xBF", 0) == 0) head.erase(0, 3);
  // From the first line that is not blank, as the readers skip blank lines: exports passed
  // through other tools or edited by hand can start with an empty line.
  for (std::size_t end; (end = head.find('\n')) != std::string::npos && head.find_first_not_of(" \t\r") >= end;)
    head.erase(0, end + 1);
  const std::string first = head.substr(0, head.find('\n'));
  // A raw HID capture (docs/hid.md), plain or gzip: its first line is the magic.
  if (first.rfind("fovea-hid-capture", 0) == 0) return Format::HidCapture;
  std::size_t p = head.find_first_not_of(" \t\r\n");
  if (p != std::string::npos && head[p] == '{') {
    // Glasses 3 gazedata: one JSON object per line with "type" and "timestamp" (any other
    // JSON file is not silently read as gaze).
    const std::string line = head.substr(p, head.find('\n', p) - p);
    if (line.find("\"timestamp\"") != std::string::npos && line.find("\"type\"") != std::string::npos)
      return Format::TobiiG3;
    throw core::InputError(path + ": a JSON file, but its first line is not Tobii Glasses 3 gazedata "
                           "(an object with \"type\" and \"timestamp\")");
  }
  if (first.find("t_ns") != std::string::npos && first.find("dir_x") != std::string::npos) return Format::Fovea;
  if (first.find("norm_pos_x") != std::string::npos &&
      (first.find("gaze_timestamp") != std::string::npos || first.rfind("timestamp,", 0) == 0))
    return Format::PupilCore;
  if (first.find("timestamp [ns]") != std::string::npos && first.find("gaze x [px]") != std::string::npos)
    return Format::Neon;
  if (head.rfind("**", 0) == 0 || head.find("\nMSG") != std::string::npos ||
      head.find("\nSAMPLES") != std::string::npos || head.find("\nSTART") != std::string::npos)
    return Format::EyelinkAsc;
  throw core::InputError(path + ": cannot detect the gaze format from its first line that is not blank; " +
                         "pass the format (" + kFormatList + ")");
}

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Shared machinery: line loop, drop accounting, time ordering and rebasing to t = 0.
class ReaderBase : public GazeReader {
 public:
  // `gaze_view`: the view the format's gaze refers to, where off-view samples are counted.
  ReaderBase(const std::string& path, const SourceOptions& opt, Format f, const core::View& gaze_view)
      : lines_(path), opt_(opt), format_(f), gaze_view_(gaze_view) {}

  bool next(GazeSample& out) override {
    detail::Line line;
    for (;;) {
      bool have = false;
      if (lines_.next(line)) {
        ++stats_.lines;
        current_unterminated_ = line.unterminated;
        if (line.overlong) {
          drop("line_too_long");
          continue;
        }
        if (detail::trim(line.text).empty()) continue;
        have = parse(line, out);
      } else {
        current_unterminated_ = false;
        stats_.peak_buffer_bytes = lines_.peak_bytes();
        if (lines_.truncated() && !truncated_noted_) {
          truncated_noted_ = true;
          note(detail::truncated_note(lines_.path()));
        }
        if (!flush(out)) {
          off_view_.note(stats_, lines_.path(), raster().x, raster().y);
          return false;
        }
        have = true;
      }
      if (have && accept(out)) return true;
    }
  }
  bool rewindable() const override { return true; }
  void rewind() override {
    lines_.rewind();
    stats_ = ReadStats{};
    have_last_ = false;
    truncated_noted_ = false;
    off_view_.reset();
    reset();
  }
  std::string describe() const override { return std::string("replay:") + lines_.path() + " (" + format_name(format_) + ")"; }
  const ReadStats& stats() const override {
    stats_.peak_buffer_bytes = lines_.peak_bytes();
    return stats_;
  }
  Format format() const override { return format_; }
  bool reports_blinks() const override { return false; }
  std::string metadata_json() const override { return "{}"; }
  core::TimeNs time_origin_ns() const override { return first_device_; }

 protected:
  // Parses one non-empty line; true if `out` holds a sample (device_time_ns set).
  virtual bool parse(const Line& line, GazeSample& out) = 0;
  // At end of file: a sample still held back (formats with several rows per sample).
  virtual bool flush(GazeSample&) { return false; }
  virtual void reset() {}

  void drop(const char* reason) { ++stats_.dropped[current_unterminated_ ? "truncated_last_line" : reason]; }
  void note(const std::string& what) { detail::add_note(stats_, what); }
  // The raster named in the off-view note: the gaze view's, or the file's own (EyeLink).
  virtual glm::dvec2 raster() const { return {gaze_view_.width(), gaze_view_.height()}; }
  void message(core::TimeNs device_ns, const char* kind, std::string_view text) {
    if (sink_) sink_(RecordingMessage{device_ns, kind, std::string(text)});
  }
  [[noreturn]] void fail(const Line& l, const std::string& what) const {
    throw core::InputError(lines_.path() + ":" + std::to_string(l.number) + ": " + what);
  }
  // Position in a column map, or -1.
  static int column(const std::vector<std::string>& header, std::string_view name) {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    return -1;
  }
  EyeGaze from_screen(const core::View& v, double px, double py, double conf) const {
    EyeGaze g;
    g.dir = v.pixel_to_dir({px, py});
    g.confidence = std::clamp(conf, 0.0, 1.0);
    g.flags = g.confidence >= opt_.min_confidence ? kTracked : kLost;
    return g;
  }

  detail::LineReader lines_;
  SourceOptions opt_;
  Format format_;
  core::View gaze_view_;
  mutable ReadStats stats_;
  std::vector<std::string_view> fields_;

 private:
  bool accept(GazeSample& s) {
    for (const EyeGaze* g : {&s.combined, &s.left, &s.right})
      if (!std::isfinite(g->dir.x + g->dir.y + g->dir.z)) {  // e.g. a coordinate of 1e300
        drop("bad_value");
        return false;
      }
    core::TimeNs rebased = 0;
    if (have_last_ && __builtin_sub_overflow(s.device_time_ns, first_device_, &rebased)) {
      drop("time_overflow");  // further from the first sample than int64 ns can express
      return false;
    }
    if (have_last_ && s.device_time_ns == last_device_) {
      drop("duplicate_time");
      return false;
    }
    if (have_last_ && s.device_time_ns < last_device_) {
      drop("non_monotonic_time");
      return false;
    }
    if (!have_last_) first_device_ = s.device_time_ns;
    have_last_ = true;
    last_device_ = s.device_time_ns;
    s.t_ns = rebased;
    s.host_time_ns = s.t_ns;
    ++stats_.samples;
    if (s.tracked()) ++stats_.tracked;
    off_view_.add(gaze_view_, s);
    return true;
  }
  detail::OffViewCount off_view_;
  bool current_unterminated_ = false, truncated_noted_ = false;
  bool have_last_ = false;
  core::TimeNs first_device_ = 0, last_device_ = 0;
};

bool unit_dir(double x, double y, double z, glm::dvec3& out) {
  const double n = std::sqrt(x * x + y * y + z * z);
  if (!(n > 1e-9) || !std::isfinite(n)) return false;
  out = glm::dvec3(x, y, z) / n;
  return true;
}

// ---- The project's format ------------------------------------------------------------
class FoveaReader final : public ReaderBase {
 public:
  FoveaReader(const std::string& path, const SourceOptions& opt)
      : ReaderBase(path, opt, Format::Fovea, opt.screen_view()) {
    const std::string side_path = path + ".json";
    if (std::filesystem::exists(side_path)) {
      // A sidecar holds a few fields: bound its size and nesting before parsing, so a hostile
      // file can neither exhaust memory nor the stack (parsing and dumping recurse per level).
      const std::string text = core::read_file_bounded(side_path, 1 << 20);
      core::check_json_nesting(text, side_path, 64);
      try {
        meta_ = core::parse_json(text).dump();
      } catch (const nlohmann::json::exception& e) {
        throw core::InputError(path + ".json: invalid JSON sidecar: " + e.what());
      }
    }
  }
  bool reports_blinks() const override { return true; }
  std::string metadata_json() const override { return meta_; }

 protected:
  void reset() override {
    cols_.clear();
    pending_ = false;
  }
  bool parse(const Line& l, GazeSample& out) override {
    detail::split_fields(l.text, ',', fields_);
    if (cols_.empty()) {
      std::vector<std::string> h(fields_.begin(), fields_.end());
      const char* names[7] = {"t_ns", "eye", "dir_x", "dir_y", "dir_z", "confidence", "flags"};
      for (int i = 0; i < 7; ++i) {
        const int c = column(h, names[i]);
        if (c < 0) fail(l, std::string("header lacks the column \"") + names[i] + "\"");
        idx_[i] = c;
      }
      cols_ = h;
      return false;
    }
    const int need = *std::max_element(idx_, idx_ + 7) + 1;
    if (static_cast<int>(fields_.size()) < need) {
      drop("missing_columns");
      return false;
    }
    std::int64_t t = 0, flags = 0;
    double d[4];
    Num n = detail::parse_int64(fields_[idx_[0]], t);
    for (int i = 0; i < 4 && n == Num::Ok; ++i) n = detail::parse_double(fields_[idx_[2 + i]], d[i]);
    if (n == Num::Ok) n = detail::parse_int64(fields_[idx_[6]], flags);
    if (n != Num::Ok) {
      drop(detail::num_reason(n));
      return false;
    }
    const std::string_view e = fields_[idx_[1]];
    const int eye = (e == "combined" || e == "C") ? 0 : (e == "left" || e == "L") ? 1 : (e == "right" || e == "R") ? 2 : -1;
    EyeGaze g;
    if (eye < 0 || (flags != kTracked && flags != kBlink && flags != kLost) || !unit_dir(d[0], d[1], d[2], g.dir) ||
        d[3] < 0 || d[3] > 1) {
      drop("bad_value");
      return false;
    }
    g.confidence = d[3];
    g.flags = static_cast<std::uint32_t>(flags);
    bool emitted = false;
    if (pending_ && t != group_.device_time_ns) {
      if (t < group_.device_time_ns) {
        drop("non_monotonic_time");
        return false;
      }
      out = finish_group();
      emitted = true;
    } else if (pending_ && (have_[eye])) {
      drop("duplicate_time");
      return false;
    }
    if (!pending_) {
      group_ = GazeSample{};
      group_.device_time_ns = t;
      have_[0] = have_[1] = have_[2] = false;
      pending_ = true;
    }
    have_[eye] = true;
    (eye == 0 ? group_.combined : eye == 1 ? group_.left : group_.right) = g;
    return emitted;
  }
  bool flush(GazeSample& out) override {
    if (!pending_) return false;
    out = finish_group();
    return true;
  }

 private:
  GazeSample finish_group() {
    pending_ = false;
    GazeSample s = group_;
    if (!have_[0]) s.combined = combine_eyes(s.left, s.right);  // per-eye rows only
    if (!have_[1]) s.left = have_[2] && !have_[0] ? s.right : s.combined;
    if (!have_[2]) s.right = have_[1] && !have_[0] ? s.left : s.combined;
    return s;
  }
  std::string meta_ = "{}";
  std::vector<std::string> cols_;
  int idx_[7] = {};
  bool pending_ = false, have_[3] = {};
  GazeSample group_;
};

// ---- Pupil Core gaze_positions.csv ---------------------------------------------------
class PupilCoreReader final : public ReaderBase {
 public:
  PupilCoreReader(const std::string& path, const SourceOptions& opt)
      : ReaderBase(path, opt, Format::PupilCore, opt.screen_view()), view_(opt.screen_view()) {}

 protected:
  void reset() override { header_ = false; }
  bool parse(const Line& l, GazeSample& out) override {
    detail::split_fields(l.text, ',', fields_);
    if (!header_) {
      std::vector<std::string> h(fields_.begin(), fields_.end());
      t_ = column(h, "gaze_timestamp");
      if (t_ < 0) t_ = column(h, "timestamp");  // older Pupil Player exports: timestamp, index
      c_ = column(h, "confidence");
      x_ = column(h, "norm_pos_x");
      y_ = column(h, "norm_pos_y");
      if (t_ < 0 || c_ < 0 || x_ < 0 || y_ < 0)
        fail(l, "header needs gaze_timestamp (or timestamp), confidence, norm_pos_x, norm_pos_y");
      for (int e = 0; e < 2; ++e)
        for (int k = 0; k < 3; ++k)
          n_[e][k] = column(h, "gaze_normal" + std::to_string(e) + "_" + "xyz"[k]);
      header_ = true;
      return false;
    }
    const int need = std::max({t_, c_, x_, y_}) + 1;
    if (static_cast<int>(fields_.size()) < need) {
      drop("missing_columns");
      return false;
    }
    double ts = 0, conf = 0, nx = 0, ny = 0;
    Num n = detail::parse_double(fields_[t_], ts);
    if (n == Num::Ok) n = detail::parse_double(fields_[c_], conf);
    if (n == Num::Ok) n = detail::parse_double(fields_[x_], nx);
    if (n == Num::Ok) n = detail::parse_double(fields_[y_], ny);
    if (n != Num::Ok) {
      drop(detail::num_reason(n));
      return false;
    }
    if (std::abs(ts) > 9.2e9) {  // would overflow int64 ns
      drop("bad_value");
      return false;
    }
    out = GazeSample{};
    out.device_time_ns = std::llround(ts * 1e9);
    // Normalised world-image coordinates: origin bottom-left, y up -> pixels top-left, y down.
    out.combined = from_screen(view_, nx * view_.width(), (1.0 - ny) * view_.height(), conf);
    out.left = out.right = out.combined;
    // gaze_normal0 = right eye, gaze_normal1 = left eye; world-camera frame x right, y down,
    // z forward -> view space (x, -y, -z). Empty for 2D mapping: keep the combined gaze.
    for (int e = 0; e < 2; ++e) {
      if (n_[e][0] < 0 || n_[e][1] < 0 || n_[e][2] < 0) continue;
      if (static_cast<int>(fields_.size()) <= std::max({n_[e][0], n_[e][1], n_[e][2]})) continue;
      double v[3];
      bool ok = true;
      for (int k = 0; k < 3; ++k) ok = ok && detail::parse_double(fields_[n_[e][k]], v[k]) == Num::Ok;
      EyeGaze& g = e == 0 ? out.right : out.left;
      if (ok && unit_dir(v[0], -v[1], -v[2], g.dir)) g.flags = out.combined.flags;
    }
    return true;
  }

 private:
  core::View view_;
  bool header_ = false;
  int t_ = -1, c_ = -1, x_ = -1, y_ = -1, n_[2][3] = {};
};

// ---- Pupil Neon / Pupil Cloud gaze.csv -----------------------------------------------
core::View neon_scene_camera() {  // Neon scene camera: 1600x1200, 103x77 deg (pinhole approximation)
  return core::View(core::Fov::from_degrees(-51.5, 51.5, 38.5, -38.5), 1600, 1200);
}

class NeonReader final : public ReaderBase {
 public:
  NeonReader(const std::string& path, const SourceOptions& opt)
      : ReaderBase(path, opt, Format::Neon, opt.screen ? *opt.screen : neon_scene_camera()),
        view_(opt.screen ? *opt.screen : neon_scene_camera()) {}
  bool reports_blinks() const override { return true; }

 protected:
  void reset() override { header_ = false; }
  bool parse(const Line& l, GazeSample& out) override {
    detail::split_fields(l.text, ',', fields_);
    if (!header_) {
      std::vector<std::string> h(fields_.begin(), fields_.end());
      t_ = column(h, "timestamp [ns]");
      x_ = column(h, "gaze x [px]");
      y_ = column(h, "gaze y [px]");
      w_ = column(h, "worn");
      b_ = column(h, "blink id");
      az_ = column(h, "azimuth [deg]");
      el_ = column(h, "elevation [deg]");
      if (t_ < 0 || x_ < 0 || y_ < 0) fail(l, "header needs \"timestamp [ns]\", \"gaze x [px]\", \"gaze y [px]\"");
      header_ = true;
      read_events();
      return false;
    }
    if (static_cast<int>(fields_.size()) <= std::max({t_, x_, y_})) {
      drop("missing_columns");
      return false;
    }
    std::int64_t t = 0;
    double px = 0, py = 0;
    Num n = detail::parse_int64(fields_[t_], t);
    if (n != Num::Ok) {
      drop(detail::num_reason(n));
      return false;
    }
    out = GazeSample{};
    out.device_time_ns = t;
    double worn = 1;
    if (w_ >= 0 && w_ < static_cast<int>(fields_.size()) && !fields_[w_].empty()) {
      const Num nw = detail::parse_double(fields_[w_], worn);
      if (nw != Num::Ok) {
        drop(detail::num_reason(nw));
        return false;
      }
    }
    const Num nx = detail::parse_double(fields_[x_], px), ny = detail::parse_double(fields_[y_], py);
    if (nx == Num::Ok && ny == Num::Ok) {
      out.combined = from_screen(view_, px, py, worn > 0.5 ? 1.0 : 0.0);
    } else {
      double az = 0, el = 0;  // fallback: the ray angles (azimuth right, elevation up)
      const bool have = az_ >= 0 && el_ >= 0 && std::max(az_, el_) < static_cast<int>(fields_.size()) &&
                        detail::parse_double(fields_[az_], az) == Num::Ok &&
                        detail::parse_double(fields_[el_], el) == Num::Ok;
      if (!have) {
        drop(detail::num_reason(nx != Num::Ok ? nx : ny));
        return false;
      }
      out.combined.dir = glm::dvec3(std::sin(az * kDeg) * std::cos(el * kDeg), std::sin(el * kDeg),
                                    -std::cos(az * kDeg) * std::cos(el * kDeg));
      out.combined.confidence = worn > 0.5 ? 1.0 : 0.0;
      out.combined.flags = worn > 0.5 ? kTracked : kLost;
    }
    // A sample inside a blink (non-empty "blink id"): the eye is closed and the gaze drifts
    // with the lid, so the direction is no measurement.
    if (b_ >= 0 && b_ < static_cast<int>(fields_.size()) && !fields_[b_].empty() && out.combined.tracked()) {
      out.combined.flags = kBlink;
      out.combined.confidence = 0;
    }
    out.left = out.right = out.combined;
    return true;
  }

 private:
  // Neon / Pupil Cloud exports put events (recording.begin, user events) in events.csv next
  // to gaze.csv: passed on as messages when the gaze header has been read.
  void read_events() {
    if (!sink_) return;
    const auto ev = std::filesystem::path(lines_.path()).parent_path() / "events.csv";
    if (!std::filesystem::is_regular_file(ev)) return;
    detail::LineReader r(ev.string());
    detail::Line l;
    std::vector<std::string_view> f;
    int t = -1, name = -1, type = -1;
    constexpr std::uint64_t kMaxEvents = 1'000'000;
    while (r.next(l) && l.number <= kMaxEvents) {
      detail::split_fields(l.text, ',', f);
      if (l.number == 1) {
        const std::vector<std::string> h(f.begin(), f.end());
        t = column(h, "timestamp [ns]");
        name = column(h, "name");
        type = column(h, "type");
        if (t < 0 || name < 0) return;
        continue;
      }
      std::int64_t ns = 0;
      if (static_cast<int>(f.size()) <= std::max(t, name) || detail::parse_int64(f[t], ns) != Num::Ok) continue;
      std::string text(f[name]);
      if (type >= 0 && type < static_cast<int>(f.size()) && !f[type].empty()) text += " (" + std::string(f[type]) + ")";
      message(ns, "event", text);
    }
  }
  core::View view_;
  bool header_ = false;
  int t_ = -1, x_ = -1, y_ = -1, w_ = -1, b_ = -1, az_ = -1, el_ = -1;
};

// ---- Tobii Pro Glasses 3 gazedata(.gz) -----------------------------------------------
core::View g3_scene_camera() {  // Glasses 3 scene camera: 1920x1080, 95x63 deg (pinhole approximation)
  return core::View(core::Fov::from_degrees(-47.5, 47.5, 31.5, -31.5), 1920, 1080);
}

class TobiiG3Reader final : public ReaderBase {
 public:
  TobiiG3Reader(const std::string& path, const SourceOptions& opt)
      : ReaderBase(path, opt, Format::TobiiG3, opt.screen ? *opt.screen : g3_scene_camera()),
        view_(opt.screen ? *opt.screen : g3_scene_camera()) {}

 protected:
  bool parse(const Line& l, GazeSample& out) override {
    nlohmann::json j;
    try {
      j = core::parse_json(l.text);
    } catch (const nlohmann::json::exception&) {
      drop("bad_json");
      return false;
    }
    if (!j.is_object()) {
      drop("bad_json");
      return false;
    }
    if (j.contains("type") && j["type"] != "gaze") return false;  // other event types
    if (!j.contains("timestamp") || !j["timestamp"].is_number()) {
      drop("missing_field");
      return false;
    }
    const double ts = j["timestamp"].get<double>();
    if (!std::isfinite(ts) || std::abs(ts) > 9.2e9) {
      drop("non_finite");
      return false;
    }
    out = GazeSample{};
    out.device_time_ns = std::llround(ts * 1e9);
    const auto data = j.find("data");
    if (data == j.end() || !data->is_object() || data->empty()) return true;  // lost: kept, flagged
    auto vec = [](const nlohmann::json& o, const char* key, int n, double* v) {
      const auto it = o.find(key);
      if (it == o.end() || !it->is_array() || static_cast<int>(it->size()) != n) return false;
      for (int i = 0; i < n; ++i) {
        if (!(*it)[i].is_number()) return false;
        v[i] = (*it)[i].get<double>();
        if (!std::isfinite(v[i])) return false;
      }
      return true;
    };
    // Per eye: gazedirection in the glasses frame (x left, y up, z forward) -> view (-x, y, -z).
    for (int e = 0; e < 2; ++e) {
      const auto it = data->find(e == 0 ? "eyeleft" : "eyeright");
      double v[3];
      EyeGaze& g = e == 0 ? out.left : out.right;
      if (it != data->end() && it->is_object() && vec(*it, "gazedirection", 3, v) && unit_dir(-v[0], v[1], -v[2], g.dir)) {
        g.flags = kTracked;
        g.confidence = 1;
      }
    }
    double p[2];
    if (vec(*data, "gaze2d", 2, p)) {  // normalised scene image, origin top-left, y down
      out.combined = from_screen(view_, p[0] * view_.width(), p[1] * view_.height(), 1.0);
    } else {
      out.combined = combine_eyes(out.left, out.right);
    }
    if (!out.left.tracked()) out.left.dir = out.combined.dir;
    if (!out.right.tracked()) out.right.dir = out.combined.dir;
    return true;
  }

 private:
  core::View view_;
};

// ---- EyeLink ASC (edf2asc) -----------------------------------------------------------
// An EyeLink file's own screen geometry: its raster (DISPLAY_COORDS, else GAZE_COORDS) and
// the angular resolution the tracker measured (RES x y on an END line: screen pixels per
// degree, averaged over the recording block), as a pinhole centred on the raster with the eye
// at RES·180/π pixels (1° spans RES pixels at the centre). Read from the start of the file up
// to the first END line with RES (at most kEyelinkScanBytes); nullopt without either.
constexpr std::uint64_t kEyelinkScanBytes = 64ull << 20;

// The size in pixels of a DISPLAY_COORDS / GAZE_COORDS rectangle (left top right bottom,
// inclusive) in f[first..first + 3]; false unless four numbers of a rectangle.
bool eyelink_rect(const std::vector<std::string_view>& f, std::size_t first, double& w, double& h) {
  double c[4];
  if (f.size() < first + 4) return false;
  for (int i = 0; i < 4; ++i)
    if (detail::parse_double(f[first + std::size_t(i)], c[i]) != Num::Ok) return false;
  if (!(c[2] > c[0] && c[3] > c[1] && c[2] - c[0] < 1e6 && c[3] - c[1] < 1e6)) return false;
  w = c[2] - c[0] + 1, h = c[3] - c[1] + 1;
  return true;
}

std::optional<core::View> eyelink_screen(const std::string& path) {
  detail::LineReader lines(path);
  detail::Line l;
  std::vector<std::string_view> f;
  double w = 0, h = 0;
  bool display = false;
  std::uint64_t bytes = 0;
  while (lines.next(l) && (bytes += l.text.size() + 1) <= kEyelinkScanBytes) {
    detail::split_blank(l.text, f);
    if (f.empty() || !(f[0] == "MSG" || f[0] == "END" || f[0] == "DISPLAY_COORDS" || f[0] == "GAZE_COORDS")) continue;
    const auto at = [&](std::string_view word) { return std::find(f.begin(), f.end(), word); };
    for (const std::string_view key : {"DISPLAY_COORDS", "GAZE_COORDS"}) {  // GAZE_COORDS when no DISPLAY_COORDS
      const auto k = at(key);
      if (k == f.end() || (display && key == "GAZE_COORDS") ||
          !eyelink_rect(f, std::size_t(k - f.begin()) + 1, w, h))
        continue;
      display = display || key == "DISPLAY_COORDS";
    }
    const auto r = at("RES");
    double rx = 0, ry = 0;
    if (f[0] == "END" && r != f.end() && f.end() - r >= 3 && detail::parse_double(r[1], rx) == Num::Ok &&
        detail::parse_double(r[2], ry) == Num::Ok && rx > 0 && ry > 0 && rx < 1e4 && ry < 1e4) {
      if (!(w > 0)) return std::nullopt;
      w = std::round(w), h = std::round(h);
      const double hx = std::atan(w / 2 / (rx / kDeg)) / kDeg, hy = std::atan(h / 2 / (ry / kDeg)) / kDeg;
      return core::View(core::Fov::from_degrees(-hx, hx, hy, -hy), int(w), int(h));
    }
  }
  return std::nullopt;
}

class EyelinkReader final : public ReaderBase {
 public:
  EyelinkReader(const std::string& path, const SourceOptions& opt)
      : EyelinkReader(path, opt, opt.screen ? std::nullopt : eyelink_screen(path)) {}
  bool reports_blinks() const override { return true; }

 protected:
  void reset() override {
    binocular_ = false;
    mono_right_ = false;
    blink_[0] = blink_[1] = false;
    coords_ = Coords::None;
    disp_w_ = view_.width();
    disp_h_ = view_.height();
    samples_ = 0;
    rate_hz_ = 0;
    have_prev_ = false;
  }
  bool parse(const Line& l, GazeSample& out) override {
    detail::split_blank(l.text, fields_);
    if (fields_.empty()) return false;
    // A sample starts with its time stamp in the first column; indented numbers are not
    // samples (the calibration's coefficient and residual tables in the preamble).
    if (!(l.text[0] >= '0' && l.text[0] <= '9')) {
      control(l);
      return false;
    }
    const std::size_t need = binocular_ ? 7 : 4;
    if (fields_.size() < need) {
      drop("missing_columns");
      return false;
    }
    double tms = 0;
    Num n = detail::parse_double(fields_[0], tms);
    if (n != Num::Ok || std::abs(tms) > 9.2e6 * 1e3) {
      drop(n != Num::Ok ? detail::num_reason(n) : "bad_value");
      return false;
    }
    out = GazeSample{};
    out.device_time_ns = std::llround(tms * 1e6);
    // Above 1 kHz edf2asc writes whole milliseconds unless asked for fractions (-ftime): the
    // second sample of a millisecond repeats its time stamp and was measured one sample
    // period (RATE of the SAMPLES line) after the first.
    if (rate_hz_ > 1000 && have_prev_ && tms == prev_ms_ && tms == std::floor(tms))
      out.device_time_ns = prev_ns_ + std::llround(1e9 / rate_hz_);
    have_prev_ = true;
    prev_ms_ = tms;
    prev_ns_ = out.device_time_ns;
    const int eyes = binocular_ ? 2 : 1;
    for (int i = 0; i < eyes; ++i) {
      const int eye = binocular_ ? i : (mono_right_ ? 1 : 0);  // 0 = left, 1 = right
      const std::string_view xs = fields_[1 + 3 * i], ys = fields_[2 + 3 * i];
      EyeGaze g;
      if (xs == "." || ys == ".") {  // missing: blink if inside SBLINK..EBLINK
        g.flags = blink_[eye] ? kBlink : kLost;
      } else {
        double x = 0, y = 0;
        n = detail::parse_double(xs, x);
        if (n == Num::Ok) n = detail::parse_double(ys, y);
        if (n != Num::Ok) {
          drop(detail::num_reason(n));
          return false;
        }
        // Display pixels (top-left, y down) scaled from DISPLAY_COORDS to the view raster.
        g = from_screen(view_, x * view_.width() / disp_w_, y * view_.height() / disp_h_, 1.0);
      }
      if (eye == 0) out.left = g;
      else out.right = g;
    }
    if (!binocular_) (mono_right_ ? out.left : out.right) = (mono_right_ ? out.right : out.left);
    out.combined = combine_eyes(out.left, out.right);
    if (!out.combined.tracked()) out.combined.flags = (out.left.flags | out.right.flags) & kBlink ? kBlink : kLost;
    ++samples_;
    return true;
  }
  bool flush(GazeSample&) override {
    if (own_screen_ && samples_ > 0) {
      char geometry[96];
      std::snprintf(geometry, sizeof geometry, "%dx%d px, %.1f x %.1f degrees", view_.width(), view_.height(),
                    (view_.fov().angle_right - view_.fov().angle_left) / kDeg,
                    (view_.fov().angle_up - view_.fov().angle_down) / kDeg);
      note(lines_.path() + ": gaze angles from the file's own screen, " + geometry +
           " (its DISPLAY_COORDS and the tracker's RES); --screen replaces it");
    }
    if (coords_ == Coords::None && samples_ > 0)
      note(lines_.path() + ": no DISPLAY_COORDS or GAZE_COORDS message; gaze pixels were taken as the screen raster (" +
           std::to_string(view_.width()) + "x" + std::to_string(view_.height()) + ")");
    samples_ = 0;
    return false;
  }
  glm::dvec2 raster() const override { return {disp_w_, disp_h_}; }

 private:
  // Where the pixel raster of the gaze samples comes from, by priority.
  enum class Coords { None, Gaze, Display };
  void control(const Line& l) {
    const std::string_view k = fields_[0];
    auto has = [&](std::string_view w) { return std::find(fields_.begin(), fields_.end(), w) != fields_.end(); };
    if (k == "SAMPLES" || k == "START") {
      if (k == "SAMPLES" && (has("HREF") || has("PUPIL")) && !has("GAZE"))
        fail(l, "only GAZE samples are supported (this file has HREF or PUPIL samples)");
      binocular_ = has("LEFT") && has("RIGHT");
      mono_right_ = !binocular_ && has("RIGHT");
      if (k == "SAMPLES") {
        const auto r = std::find(fields_.begin(), fields_.end(), "RATE");
        double hz = 0;
        rate_hz_ = r != fields_.end() && r + 1 != fields_.end() && detail::parse_double(*(r + 1), hz) == Num::Ok &&
                           hz > 0 && hz <= 1e5
                       ? hz
                       : 0;
      }
    } else if (k == "SBLINK" || k == "EBLINK") {
      const bool on = k == "SBLINK";
      if (fields_.size() > 1) blink_[fields_[1] == "R" ? 1 : 0] = on;
    } else if ((k == "MSG" || k == "INPUT" || k == "BUTTON") && fields_.size() >= 2) {
      double tms = 0;
      const bool timed = detail::parse_double(fields_[1], tms) == Num::Ok && std::abs(tms) <= 9.2e9;
      // The message text: everything after the time stamp, as written.
      const std::size_t at = fields_[1].data() + fields_[1].size() - l.text.data();
      if (timed) message(std::llround(tms * 1e6), k == "MSG" ? "msg" : k == "INPUT" ? "input" : "button", detail::trim(l.text.substr(at)));
      if (k == "MSG" && fields_.size() >= 7 && (fields_[2] == "DISPLAY_COORDS" || fields_[2] == "GAZE_COORDS"))
        coords(fields_[2] == "DISPLAY_COORDS" ? Coords::Display : Coords::Gaze, 3);
    } else if (k == "DISPLAY_COORDS" || k == "GAZE_COORDS") {  // also written without MSG
      coords(k == "DISPLAY_COORDS" ? Coords::Display : Coords::Gaze, 1);
    }
  }
  // DISPLAY_COORDS left top right bottom; GAZE_COORDS (the tracker's gaze raster) is used
  // only when the file has no DISPLAY_COORDS.
  void coords(Coords kind, std::size_t first) {
    if (kind < coords_ || fields_.size() < first + 4) return;
    if (eyelink_rect(fields_, first, disp_w_, disp_h_)) coords_ = kind;
    else drop("bad_value");
  }
  EyelinkReader(const std::string& path, const SourceOptions& opt, const std::optional<core::View>& own)
      : ReaderBase(path, opt, Format::EyelinkAsc, own.value_or(opt.screen_view())),
        view_(own.value_or(opt.screen_view())),
        own_screen_(own.has_value()) {}

  core::View view_;
  bool own_screen_;  // view_ is the file's own screen (eyelink_screen)
  bool binocular_ = false, mono_right_ = false, blink_[2] = {};
  Coords coords_ = Coords::None;
  double disp_w_ = view_.width(), disp_h_ = view_.height();
  std::uint64_t samples_ = 0;
  double rate_hz_ = 0;  // the SAMPLES line's RATE, 0 when not given
  bool have_prev_ = false;
  double prev_ms_ = 0;  // the last sample's time stamp as written, and its time
  core::TimeNs prev_ns_ = 0;
};

}  // namespace

std::unique_ptr<GazeReader> open_reader(const std::string& path, const SourceOptions& opt) {
  if (!std::filesystem::is_regular_file(path)) throw core::InputError(path + ": no such file");
  const Format f = opt.format.empty() ? detect_format(path) : parse_format(opt.format);
  switch (f) {
    case Format::Fovea: return std::make_unique<FoveaReader>(path, opt);
    case Format::PupilCore: return std::make_unique<PupilCoreReader>(path, opt);
    case Format::Neon: return std::make_unique<NeonReader>(path, opt);
    case Format::TobiiG3: return std::make_unique<TobiiG3Reader>(path, opt);
    case Format::EyelinkAsc: return std::make_unique<EyelinkReader>(path, opt);
    case Format::HidCapture: return std::make_unique<hid::HidCaptureStream>(path, opt);
  }
  throw core::InputError(path + ": unsupported format");
}

// ---- Writer --------------------------------------------------------------------------
FoveaCsvWriter::FoveaCsvWriter(const std::string& path, const std::string& metadata_json, bool per_eye)
    : path_(path), tmp_(path + ".tmp." + std::to_string(::getpid())), per_eye_(per_eye) {
  set_metadata(metadata_json);
  file_ = std::fopen(tmp_.c_str(), "wb");
  if (!file_) throw std::runtime_error(path + ": cannot open for writing");
  std::fputs("t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n", static_cast<std::FILE*>(file_));
}

void FoveaCsvWriter::set_metadata(const std::string& metadata_json) {
  nlohmann::json meta;
  try {
    meta = core::parse_json(metadata_json.empty() ? "{}" : metadata_json);
  } catch (const nlohmann::json::exception& e) {
    throw std::logic_error(std::string("gaze writer metadata: ") + e.what());
  }
  nlohmann::json side = {{"format", "fovea-gaze-csv"}, {"version", 1}};
  side.update(meta);
  meta_ = side.dump(2) + "\n";
}

FoveaCsvWriter::~FoveaCsvWriter() {
  if (file_) {
    std::fclose(static_cast<std::FILE*>(file_));
    std::remove(tmp_.c_str());
  }
}

void FoveaCsvWriter::write(const GazeSample& s) {
  auto row = [&](const char* eye, const EyeGaze& g) {
    const glm::dvec3 d = std::isfinite(g.dir.x + g.dir.y + g.dir.z) ? g.dir : glm::dvec3(0, 0, -1);
    std::fprintf(static_cast<std::FILE*>(file_), "%lld,%s,%.6f,%.6f,%.6f,%.3f,%u\n", static_cast<long long>(s.t_ns),
                 eye, d.x, d.y, d.z, std::isfinite(g.confidence) ? std::clamp(g.confidence, 0.0, 1.0) : 0.0,
                 g.flags & (kTracked | kBlink | kLost) ? g.flags : kLost);
  };
  row("combined", s.combined);
  if (per_eye_) {
    row("left", s.left);
    row("right", s.right);
  }
  ++samples_;
}

void FoveaCsvWriter::finish() {
  std::FILE* f = static_cast<std::FILE*>(file_);
  file_ = nullptr;
  const bool ok = !std::ferror(f);
  if (std::fclose(f) != 0 || !ok) {
    std::remove(tmp_.c_str());
    throw std::runtime_error(path_ + ": write failed");
  }
  core::write_file_atomic(path_ + ".json", meta_);
  std::error_code ec;
  std::filesystem::rename(tmp_, path_, ec);
  if (ec) {
    std::remove(tmp_.c_str());
    throw std::runtime_error(path_ + ": rename failed: " + ec.message());
  }
}

}  // namespace fovea::devices

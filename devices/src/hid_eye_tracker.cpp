#include "fovea/devices/hid_eye_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "fovea/core/error.hpp"

namespace fovea::devices::hid {

namespace {

std::string hex32(std::uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%x", v);
  return b;
}

// Device values are declared up to 32 bits unsigned (e.g. logical max 0xFFFFFFFF): a plain
// cast of such a value to int is undefined, so it saturates instead.
int saturate_int(double v) {
  if (!(v == v)) return 0;
  return static_cast<int>(std::clamp(v, static_cast<double>(std::numeric_limits<int>::min()),
                                     static_cast<double>(std::numeric_limits<int>::max())));
}

int nibble(std::uint32_t unit, int i) {
  const int v = (unit >> (4 * i)) & 0xF;
  return v >= 8 ? v - 16 : v;
}

// SI base units per unit of the HID unit code (HID 1.11 §6.2.2.7): system nibble 1 = SI
// linear (cm, g, s), 3 = English linear (inch, slug, s). Only the dimension we expect.
double unit_scale(std::uint32_t unit, int exponent, Quantity q, double fallback, const std::string& what) {
  const double exp10 = std::pow(10.0, exponent);
  if (unit == 0) return q == Quantity::Count ? 1.0 : fallback * exp10;  // no unit: the page's convention
  const int system = unit & 0xF;
  const int length = nibble(unit, 1), mass = nibble(unit, 2), time = nibble(unit, 3);
  const bool others = (unit >> 16) != 0 || mass != 0;
  auto bad = [&] {
    throw core::InputError("HID eye tracker: " + what + " has unit " + hex32(unit) + " (" +
                           std::to_string(length) + " length, " + std::to_string(time) + " time) which is not a " +
                           (q == Quantity::Length ? "length" : q == Quantity::Time ? "time" : "frequency"));
  };
  if (system != 1 && system != 3) bad();
  switch (q) {
    case Quantity::Length:
      if (length != 1 || time != 0 || others) bad();
      return (system == 1 ? 0.01 : 0.0254) * exp10;
    case Quantity::Time:
      if (time != 1 || length != 0 || others) bad();
      return exp10;
    case Quantity::Frequency:
      if (time != -1 || length != 0 || others) bad();
      return exp10;
    case Quantity::Count: return 1.0;
  }
  return 1.0;
}

}  // namespace

bool Value::in_range(std::int64_t raw) const {
  if (logical_min >= logical_max) return true;  // no usable range declared
  return raw >= logical_min && raw <= logical_max;
}

double Value::to_si(std::int64_t raw) const {
  double phys = static_cast<double>(raw);
  if (!(physical_min == 0 && physical_max == 0) && logical_max != logical_min)
    phys = static_cast<double>(physical_min) + (static_cast<double>(raw) - static_cast<double>(logical_min)) *
                                                   static_cast<double>(physical_max - physical_min) /
                                                   static_cast<double>(logical_max - logical_min);
  return phys * si_per_unit;
}

std::int64_t Value::from_si(double v) const {
  double phys = v / si_per_unit;
  if (!(physical_min == 0 && physical_max == 0) && physical_max != physical_min)
    phys = static_cast<double>(logical_min) + (phys - static_cast<double>(physical_min)) *
                                                  static_cast<double>(logical_max - logical_min) /
                                                  static_cast<double>(physical_max - physical_min);
  if (!std::isfinite(phys)) phys = 0;
  if (logical_min < logical_max) phys = std::clamp(phys, static_cast<double>(logical_min), static_cast<double>(logical_max));
  phys = std::clamp(phys, -9.2e18, 9.2e18);
  return std::llround(phys);
}

std::string Value::describe() const {
  if (!found) return "absent";
  return std::string(report_type_name(type)) + " report " + std::to_string(report_id) + " bits " +
         std::to_string(bit_offset) + "+" + std::to_string(bits) + (is_signed ? " signed" : " unsigned") +
         " logical " + std::to_string(logical_min) + ".." + std::to_string(logical_max) + " unit " +
         hex32(unit) + " exp " + std::to_string(unit_exponent) + (constant ? " (constant flag)" : "");
}

bool read_value(std::span<const std::uint8_t> report, const Value& v, bool has_id, std::int64_t& raw) {
  return read_bits(report.subspan(has_id ? 1 : 0), v.bit_offset, v.bits, v.is_signed, raw);
}
void write_value(std::span<std::uint8_t> report, const Value& v, bool has_id, std::int64_t raw) {
  write_bits(report.subspan(has_id ? 1 : 0), v.bit_offset, v.bits, raw);
}

EyeTrackerLayout locate_eye_tracker(const Descriptor& d) {
  EyeTrackerLayout L;
  auto page_usage = [](std::uint32_t ext) -> int { return (ext >> 16) == kEyeTrackerPage ? int(ext & 0xFFFF) : -1; };
  for (const Field& f : d.fields) {
    if (!(f.flags & kVariable)) continue;  // array fields select usages, they carry no values
    for (std::uint32_t i = 0; i < f.count;) {
      const std::uint32_t ext = f.usage_of(i);
      std::uint32_t n = 1;
      while (i + n < f.count && f.usage_of(i + n) == ext) ++n;
      const int u = page_usage(ext);
      Value v;
      v.found = true;
      v.type = f.type;
      v.report_id = f.report_id;
      v.bit_offset = f.bit_offset + i * f.bit_size;
      v.bits = f.bit_size * n;
      v.is_signed = n == 1 && f.logical_min < 0;
      v.constant = f.flags & kConstant;
      v.logical_min = f.logical_min;
      v.logical_max = f.logical_max;
      if (n > 1) {  // a merged multi-byte value: the per-byte range means nothing
        v.logical_min = v.logical_max = 0;
      }
      v.physical_min = f.physical_min;
      v.physical_max = f.physical_max;
      v.unit = f.unit;
      v.unit_exponent = f.unit_exponent;
      i += n;
      if (u < 0) continue;
      // The innermost page-0x12 physical collection that names what X/Y/Z belong to.
      int owner = -1;
      for (auto it = f.collections.rbegin(); it != f.collections.rend(); ++it) {
        const int c = page_usage(*it);
        if (c >= usage::kGazePoint && c <= usage::kHeadDirectionPoint) {
          owner = c;
          break;
        }
      }
      auto set = [&](Value& slot, Quantity q, double fallback, const char* name) {
        if (slot.found) return;
        if (v.bits > 64) throw core::InputError(std::string("HID eye tracker: ") + name + " is " + std::to_string(v.bits) + " bits wide (at most 64)");
        slot = v;
        slot.si_per_unit = unit_scale(v.unit, v.unit_exponent, q, fallback, name);
      };
      const bool input = f.type == ReportType::Input, feature = f.type == ReportType::Feature;
      switch (u) {
        case usage::kSensorTimestamp:
          if (input) set(L.timestamp, Quantity::Time, 1e-6, "Sensor Timestamp");
          break;
        case usage::kPositionX:
        case usage::kPositionY:
        case usage::kPositionZ: {
          if (!input) break;
          const int axis = u - usage::kPositionX;
          if (owner == usage::kGazePoint && axis < 2) set(axis == 0 ? L.gaze_x : L.gaze_y, Quantity::Length, 1e-6, "Gaze Point");
          else if (owner == usage::kLeftEyePosition) set(L.eye[0][axis], Quantity::Length, 1e-6, "Left Eye Position");
          else if (owner == usage::kRightEyePosition) set(L.eye[1][axis], Quantity::Length, 1e-6, "Right Eye Position");
          else if (owner == usage::kHeadPosition) set(L.head[axis], Quantity::Length, 1e-6, "Head Position");
          break;
        }
        case usage::kTrackerQuality: if (feature) set(L.tracker_quality, Quantity::Count, 1, "Tracker Quality"); break;
        case usage::kMinimumTrackingDistance: if (feature) set(L.min_distance, Quantity::Length, 1e-6, "Minimum Tracking Distance"); break;
        case usage::kOptimumTrackingDistance: if (feature) set(L.optimum_distance, Quantity::Length, 1e-6, "Optimum Tracking Distance"); break;
        case usage::kMaximumTrackingDistance: if (feature) set(L.max_distance, Quantity::Length, 1e-6, "Maximum Tracking Distance"); break;
        case usage::kMaximumScreenPlaneWidth: if (feature) set(L.max_screen_w, Quantity::Length, 1e-6, "Maximum Screen Plane Width"); break;
        case usage::kMaximumScreenPlaneHeight: if (feature) set(L.max_screen_h, Quantity::Length, 1e-6, "Maximum Screen Plane Height"); break;
        case usage::kDisplayManufacturerId: if (feature) set(L.display_manufacturer, Quantity::Count, 1, "Display Manufacturer ID"); break;
        case usage::kDisplayProductId: if (feature) set(L.display_product, Quantity::Count, 1, "Display Product ID"); break;
        case usage::kDisplaySerialNumber: if (feature) set(L.display_serial, Quantity::Count, 1, "Display Serial Number"); break;
        case usage::kDisplayManufacturerDate: if (feature) set(L.display_date, Quantity::Count, 1, "Display Manufacturer Date"); break;
        case usage::kCalibratedScreenWidth: if (feature) set(L.calibrated_w, Quantity::Length, 1e-6, "Calibrated Screen Width"); break;
        case usage::kCalibratedScreenHeight: if (feature) set(L.calibrated_h, Quantity::Length, 1e-6, "Calibrated Screen Height"); break;
        case usage::kSamplingFrequency:
          if (feature) set(L.sampling_frequency, Quantity::Frequency, 1, "Sampling Frequency");
          if (input) set(L.status_input_frequency, Quantity::Frequency, 1, "Sampling Frequency");
          break;
        case usage::kConfigurationStatus:
          if (feature) set(L.configuration_status, Quantity::Count, 1, "Configuration Status");
          if (input) set(L.status_input_config, Quantity::Count, 1, "Configuration Status");
          break;
        case usage::kDeviceModeRequest:
          if (feature) set(L.device_mode, Quantity::Count, 1, "Device Mode Request");
          break;
        default:
          if (u > usage::kHeadDirectionPoint + 3 || u < usage::kTrackingData) ++L.vendor_usages;
          break;
      }
    }
  }
  if (!L.timestamp.found) throw core::InputError("HID eye tracker: no Sensor Timestamp (page 0x12, usage 0x20) in an input report");
  if (!L.gaze_x.found || !L.gaze_y.found)
    throw core::InputError("HID eye tracker: no Gaze Point (0x24) Position X/Y (0x21/0x22) in an input report");
  if (L.gaze_x.report_id != L.timestamp.report_id || L.gaze_y.report_id != L.timestamp.report_id)
    throw core::InputError("HID eye tracker: Sensor Timestamp and Gaze Point are in different input reports");
  L.tracking_report_id = L.timestamp.report_id;
  return L;
}

EyeTrackerCodec::EyeTrackerCodec(std::span<const std::uint8_t> bytes)
    : bytes_(bytes.begin(), bytes.end()), desc_(parse_descriptor(bytes)), layout_(locate_eye_tracker(desc_)) {}

std::vector<std::uint8_t> EyeTrackerCodec::blank(ReportType t, std::uint8_t id) const {
  std::vector<std::uint8_t> r(desc_.report_bytes(t, id), 0);
  if (desc_.uses_report_ids && !r.empty()) r[0] = id;
  return r;
}

bool EyeTrackerCodec::decode_input(std::span<const std::uint8_t> rep, HidGaze& out, DeviceConfig& cfg, std::string& reason) const {
  const bool ids = desc_.uses_report_ids;
  if (rep.empty()) {
    reason = "short_report";
    return false;
  }
  const std::uint8_t id = ids ? rep[0] : 0;
  const std::size_t need = desc_.report_bytes(ReportType::Input, id);
  if (need == 0) {
    reason = "unknown_report_id";
    return false;
  }
  if (rep.size() < need) {
    reason = "short_report";
    return false;
  }
  const EyeTrackerLayout& L = layout_;
  std::int64_t raw = 0;
  if (id != L.tracking_report_id) {
    if (L.status_input_config.found && L.status_input_config.report_id == id && read_value(rep, L.status_input_config, ids, raw))
      cfg.configuration_status = saturate_int(static_cast<double>(raw));
    if (L.status_input_frequency.found && L.status_input_frequency.report_id == id && read_value(rep, L.status_input_frequency, ids, raw))
      cfg.sampling_hz = L.status_input_frequency.to_si(raw);
    reason.clear();
    return false;
  }
  out = HidGaze{};
  read_value(rep, L.timestamp, ids, out.timestamp_raw);
  out.timestamp_s = L.timestamp.to_si(out.timestamp_raw);
  std::int64_t x = 0, y = 0;
  read_value(rep, L.gaze_x, ids, x);
  read_value(rep, L.gaze_y, ids, y);
  out.gaze_valid = L.gaze_x.in_range(x) && L.gaze_y.in_range(y);
  out.gaze_x_m = L.gaze_x.to_si(x);
  out.gaze_y_m = L.gaze_y.to_si(y);
  for (int e = 0; e < 2; ++e) {
    bool ok = L.eye[e][0].found;
    for (int a = 0; a < 3 && ok; ++a) {
      if (!L.eye[e][a].found) continue;
      ok = read_value(rep, L.eye[e][a], ids, raw) && L.eye[e][a].in_range(raw);
      out.eye_pos_m[e][a] = L.eye[e][a].to_si(raw);
    }
    out.eye_valid[e] = ok;
  }
  return true;
}

bool EyeTrackerCodec::decode_feature(std::span<const std::uint8_t> rep, DeviceConfig& cfg) const {
  const bool ids = desc_.uses_report_ids;
  if (rep.empty()) return false;
  const std::uint8_t id = ids ? rep[0] : 0;
  const std::size_t need = desc_.report_bytes(ReportType::Feature, id);
  if (need == 0 || rep.size() < need) return false;
  const EyeTrackerLayout& L = layout_;
  std::int64_t raw = 0;
  auto get = [&](const Value& v, auto&& apply) {
    if (v.found && v.report_id == id && read_value(rep, v, ids, raw)) apply(v.to_si(raw));
  };
  get(L.calibrated_w, [&](double s) { cfg.screen_w_m = s; });
  get(L.calibrated_h, [&](double s) { cfg.screen_h_m = s; });
  get(L.max_screen_w, [&](double s) { if (cfg.screen_w_m <= 0) cfg.screen_w_m = s; });
  get(L.max_screen_h, [&](double s) { if (cfg.screen_h_m <= 0) cfg.screen_h_m = s; });
  get(L.sampling_frequency, [&](double s) { cfg.sampling_hz = s; });
  get(L.configuration_status, [&](double s) { cfg.configuration_status = saturate_int(s); });
  get(L.tracker_quality, [&](double s) { cfg.tracker_quality = saturate_int(s); });
  get(L.min_distance, [&](double s) { cfg.min_distance_m = s; });
  get(L.optimum_distance, [&](double s) { cfg.optimum_distance_m = s; });
  get(L.max_distance, [&](double s) { cfg.max_distance_m = s; });
  return true;
}

std::vector<std::uint8_t> EyeTrackerCodec::startup_feature_ids() const {
  std::vector<std::uint8_t> ids;
  for (const Value* v : {&layout_.tracker_quality, &layout_.max_screen_w, &layout_.calibrated_w, &layout_.calibrated_h,
                         &layout_.configuration_status, &layout_.sampling_frequency})
    if (v->found && std::find(ids.begin(), ids.end(), v->report_id) == ids.end()) ids.push_back(v->report_id);
  return ids;
}

std::vector<std::uint8_t> EyeTrackerCodec::mode_request(std::uint8_t bits) const {
  const Value& v = layout_.device_mode;
  if (!v.found) return {};
  auto r = blank(ReportType::Feature, v.report_id);
  write_value(r, v, desc_.uses_report_ids, bits);
  return r;
}

std::vector<std::uint8_t> EyeTrackerCodec::encode_gaze(const HidGaze& g) const {
  const EyeTrackerLayout& L = layout_;
  const bool ids = desc_.uses_report_ids;
  auto r = blank(ReportType::Input, L.tracking_report_id);
  write_value(r, L.timestamp, ids, g.timestamp_raw);
  // Invalid gaze: a value just outside the logical range (the HID null convention).
  auto null_of = [](const Value& v) { return v.logical_min > std::numeric_limits<std::int32_t>::min() ? v.logical_min - 1 : v.logical_max + 1; };
  write_value(r, L.gaze_x, ids, g.gaze_valid ? L.gaze_x.from_si(g.gaze_x_m) : null_of(L.gaze_x));
  write_value(r, L.gaze_y, ids, g.gaze_valid ? L.gaze_y.from_si(g.gaze_y_m) : null_of(L.gaze_y));
  for (int e = 0; e < 2; ++e)
    for (int a = 0; a < 3; ++a)
      if (L.eye[e][a].found)
        write_value(r, L.eye[e][a], ids, g.eye_valid[e] ? L.eye[e][a].from_si(g.eye_pos_m[e][a]) : null_of(L.eye[e][a]));
  return r;
}

std::vector<std::uint8_t> EyeTrackerCodec::encode_feature(std::uint8_t id, const DeviceConfig& c) const {
  auto r = blank(ReportType::Feature, id);
  if (r.empty()) return r;
  const EyeTrackerLayout& L = layout_;
  const bool ids = desc_.uses_report_ids;
  auto put = [&](const Value& v, double si) {
    if (v.found && v.report_id == id) write_value(r, v, ids, v.from_si(si));
  };
  put(L.tracker_quality, c.tracker_quality);
  put(L.min_distance, c.min_distance_m);
  put(L.optimum_distance, c.optimum_distance_m);
  put(L.max_distance, c.max_distance_m);
  put(L.max_screen_w, c.screen_w_m);
  put(L.max_screen_h, c.screen_h_m);
  put(L.calibrated_w, c.screen_w_m);
  put(L.calibrated_h, c.screen_h_m);
  put(L.sampling_frequency, c.sampling_hz);
  put(L.configuration_status, c.configuration_status);
  return r;
}

std::vector<std::uint8_t> EyeTrackerCodec::encode_status_input(const DeviceConfig& c) const {
  const Value& v = layout_.status_input_config;
  if (!v.found) return {};
  auto r = blank(ReportType::Input, v.report_id);
  write_value(r, v, desc_.uses_report_ids, c.configuration_status);
  if (layout_.status_input_frequency.found && layout_.status_input_frequency.report_id == v.report_id)
    write_value(r, layout_.status_input_frequency, desc_.uses_report_ids, layout_.status_input_frequency.from_si(c.sampling_hz));
  return r;
}

}  // namespace fovea::devices::hid

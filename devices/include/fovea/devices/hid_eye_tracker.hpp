#pragma once
// HID "Eye and Head Trackers" (usage page 0x12, HID Usage Tables 1.2+, final numbering):
// locating the page's usages in any report descriptor, decoding input/feature reports into
// SI values, encoding them (for the device emulator and the start-up handshake).
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "fovea/devices/hid_descriptor.hpp"

namespace fovea::devices::hid {

constexpr std::uint16_t kEyeTrackerPage = 0x12;

namespace usage {  // page 0x12
constexpr std::uint16_t kEyeTracker = 0x01, kHeadTracker = 0x02;
constexpr std::uint16_t kTrackingData = 0x10, kCapabilities = 0x11, kConfiguration = 0x12, kStatus = 0x13, kControl = 0x14;
constexpr std::uint16_t kSensorTimestamp = 0x20, kPositionX = 0x21, kPositionY = 0x22, kPositionZ = 0x23;
constexpr std::uint16_t kGazePoint = 0x24, kLeftEyePosition = 0x25, kRightEyePosition = 0x26, kHeadPosition = 0x27,
                        kHeadDirectionPoint = 0x28;
constexpr std::uint16_t kTrackerQuality = 0x100, kMinimumTrackingDistance = 0x101, kOptimumTrackingDistance = 0x102,
                        kMaximumTrackingDistance = 0x103, kMaximumScreenPlaneWidth = 0x104, kMaximumScreenPlaneHeight = 0x105;
constexpr std::uint16_t kDisplayManufacturerId = 0x200, kDisplayProductId = 0x201, kDisplaySerialNumber = 0x202,
                        kDisplayManufacturerDate = 0x203, kCalibratedScreenWidth = 0x204, kCalibratedScreenHeight = 0x205;
constexpr std::uint16_t kSamplingFrequency = 0x300, kConfigurationStatus = 0x301, kDeviceModeRequest = 0x400;
}  // namespace usage

// Device Mode Request bits (as used by Microsoft's reference driver).
constexpr std::uint8_t kModeGazePoint = 1, kModeEyePosition = 2, kModeHeadPosition = 4;

enum class Quantity { Length, Time, Frequency, Count };

// One located value: where it is and how to scale it. Consecutive values of a field that
// carry the same usage form one wider little-endian value (the reference layout's 64-bit
// timestamp is 8 values of 8 bits).
struct Value {
  bool found = false;
  ReportType type = ReportType::Input;
  std::uint8_t report_id = 0;
  std::uint32_t bit_offset = 0, bits = 0;
  bool is_signed = false, constant = false;
  std::int64_t logical_min = 0, logical_max = 0, physical_min = 0, physical_max = 0;
  std::uint32_t unit = 0;
  int unit_exponent = 0;
  double si_per_unit = 1;  // SI base units (m, s, Hz) per physical unit; set by locate()

  bool in_range(std::int64_t raw) const;  // null values lie outside the logical range
  double to_si(std::int64_t raw) const;
  std::int64_t from_si(double v) const;   // rounded and clamped to the logical range
  std::string describe() const;
};

struct EyeTrackerLayout {
  Value timestamp, gaze_x, gaze_y;
  std::array<std::array<Value, 3>, 2> eye{};  // [left, right][x, y, z]
  std::array<Value, 3> head{};
  Value tracker_quality, min_distance, optimum_distance, max_distance, max_screen_w, max_screen_h;
  Value display_manufacturer, display_product, display_serial, display_date, calibrated_w, calibrated_h;
  Value sampling_frequency, configuration_status;        // feature
  Value status_input_frequency, status_input_config;     // input copy of the Status report
  Value device_mode;
  std::uint8_t tracking_report_id = 0;
  std::uint32_t vendor_usages = 0;  // page-0x12 usages not in the final table (ignored)
};

// Throws core::InputError if the descriptor has no page-0x12 Tracking Data input with a
// Sensor Timestamp and a Gaze Point X/Y, or a located value has an impossible size/unit.
EyeTrackerLayout locate_eye_tracker(const Descriptor& d);

// Device state read from feature reports.
struct DeviceConfig {
  double screen_w_m = 0, screen_h_m = 0;  // Calibrated Screen Width/Height (or max screen plane)
  double sampling_hz = 0;
  int configuration_status = 0;  // 1 Ready, 2 Configuring, 3 Screen Setup Needed, 4 User Calibration Needed
  int tracker_quality = 0;
  double min_distance_m = 0, optimum_distance_m = 0, max_distance_m = 0;
};

struct HidGaze {
  std::int64_t timestamp_raw = 0;      // in the descriptor's units (wraps with its width)
  double timestamp_s = 0;
  bool gaze_valid = false;
  double gaze_x_m = 0, gaze_y_m = 0;   // on the calibrated screen, top-left, y down
  std::array<bool, 2> eye_valid{};
  std::array<glm::dvec3, 2> eye_pos_m{};
};

class EyeTrackerCodec {
 public:
  explicit EyeTrackerCodec(std::span<const std::uint8_t> descriptor_bytes);
  const Descriptor& descriptor() const { return desc_; }
  const EyeTrackerLayout& layout() const { return layout_; }
  const std::vector<std::uint8_t>& descriptor_bytes() const { return bytes_; }

  // An input report as read from the device (report ID first if the descriptor uses IDs).
  // Returns false and a reason ("unknown_report_id", "short_report", ...) for anything that
  // is not a tracking-data report; status input reports update `cfg` and return false with
  // reason "" (not an error).
  bool decode_input(std::span<const std::uint8_t> report, HidGaze& out, DeviceConfig& cfg, std::string& reason) const;
  // A feature report (GET_REPORT response, ID first): updates `cfg`; false if unknown/short.
  bool decode_feature(std::span<const std::uint8_t> report, DeviceConfig& cfg) const;
  // Report IDs of the feature reports worth reading at start-up (capabilities, configuration, status).
  std::vector<std::uint8_t> startup_feature_ids() const;
  // The Control feature report setting Device Mode Request; empty if the device has none.
  std::vector<std::uint8_t> mode_request(std::uint8_t bits) const;

  // Encoding, for the emulated device.
  std::vector<std::uint8_t> encode_gaze(const HidGaze& g) const;
  std::vector<std::uint8_t> encode_feature(std::uint8_t report_id, const DeviceConfig& cfg) const;
  std::vector<std::uint8_t> encode_status_input(const DeviceConfig& cfg) const;  // empty if none

 private:
  std::vector<std::uint8_t> blank(ReportType t, std::uint8_t id) const;
  std::vector<std::uint8_t> bytes_;
  Descriptor desc_;
  EyeTrackerLayout layout_;
};

bool read_value(std::span<const std::uint8_t> report, const Value& v, bool has_id, std::int64_t& raw);
void write_value(std::span<std::uint8_t> report, const Value& v, bool has_id, std::int64_t raw);

}  // namespace fovea::devices::hid

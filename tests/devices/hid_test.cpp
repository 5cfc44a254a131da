#include <algorithm>
#include <random>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <libusb.h>

#include "fovea/core/error.hpp"
#include "fovea/devices/clock_sync.hpp"
#include "fovea/devices/hid_emulator.hpp"
#include "fovea/devices/hid_stream.hpp"
#include "fovea/devices/synthetic.hpp"
#include "test_util.hpp"
#include "transport_errors.hpp"

using namespace fovea::devices;
using namespace fovea::devices::hid;
using fovea::core::InputError;
using fovea::core::TimeNs;

namespace {
std::vector<std::uint8_t> capture_descriptor(const std::string& name) {
  HidCaptureStream c(fovea::devices::test::source_dir() + "/data/gaze/" + name, SourceOptions{});
  return c.codec().descriptor_bytes();
}
std::vector<std::uint8_t> bytes(std::initializer_list<int> v) { return std::vector<std::uint8_t>(v.begin(), v.end()); }
std::string parse_error(const std::vector<std::uint8_t>& d) {
  try {
    EyeTrackerCodec c(d);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
std::unique_ptr<SampleStream> synth(std::uint64_t seed, double seconds) {
  SynthParams p;
  p.seed = seed;
  p.seconds = seconds;
  p.task = SynthTask::Search;
  return std::make_unique<SyntheticStream>(p);
}
// Drains a live stream until it finishes.
std::vector<GazeSample> drain(HidGazeStream& s) {
  std::vector<GazeSample> v;
  GazeSample g;
  for (int idle = 0; idle < 2000;) {
    if (s.next(g)) {
      v.push_back(g);
      idle = 0;
    } else if (s.finished()) {
      while (s.next(g)) v.push_back(g);
      break;
    } else {
      ++idle;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  return v;
}
}  // namespace

TEST(HidDescriptor, MicrosoftReferenceLayout) {
  const EyeTrackerCodec c(capture_descriptor("hid-ms.hidcap"));
  const Descriptor& d = c.descriptor();
  const EyeTrackerLayout& L = c.layout();
  EXPECT_TRUE(d.uses_report_ids);
  EXPECT_EQ(d.report_bytes(ReportType::Input, 0x10), 65u);    // as in the reference dump
  EXPECT_EQ(d.report_bytes(ReportType::Feature, 0x11), 22u);  // the largest feature report
  EXPECT_EQ(L.tracking_report_id, 0x10);
  EXPECT_EQ(L.timestamp.bit_offset, 0u);
  EXPECT_EQ(L.timestamp.bits, 64u);  // 8 values of 8 bits, one usage
  EXPECT_DOUBLE_EQ(L.timestamp.si_per_unit, 1e-6);  // SI time, exponent −6: µs
  EXPECT_TRUE(L.timestamp.constant);                // "Cnst" data items are accepted
  EXPECT_EQ(L.gaze_x.bit_offset, 64u);
  EXPECT_EQ(L.gaze_y.bit_offset, 96u);
  EXPECT_EQ(L.gaze_x.bits, 32u);
  EXPECT_TRUE(L.gaze_x.is_signed);
  EXPECT_NEAR(L.gaze_x.si_per_unit, 1e-6, 1e-18);  // cm, exponent −4: µm
  EXPECT_EQ(L.gaze_x.logical_min, -2000000);
  EXPECT_EQ(L.eye[0][2].bit_offset, 64u + 4 * 32);
  EXPECT_EQ(L.eye[1][0].bit_offset, 64u + 5 * 32);
  EXPECT_EQ(L.head[0].bit_offset, 64u + 8 * 32);
  EXPECT_EQ(L.calibrated_w.report_id, 0x12);
  EXPECT_EQ(L.calibrated_w.bit_offset, 16u + 16 + 32 + 16);
  EXPECT_EQ(L.max_screen_h.bit_offset, 8u + 4 * 32);
  EXPECT_EQ(L.configuration_status.report_id, 0x13);
  EXPECT_TRUE(L.status_input_config.found);
  EXPECT_NEAR(L.sampling_frequency.si_per_unit, 1.0, 1e-12);  // Hz
  EXPECT_EQ(L.device_mode.report_id, 0x14);
  EXPECT_EQ(c.mode_request(kModeGazePoint), bytes({0x14, 0x01}));
}

// A descriptor from outside the project: Microsoft's virtual eye-gaze device in the Driver
// Module Framework (MIT licence), g_VirtualEyeGaze_HidReportDescriptor in
// https://github.com/microsoft/DMF/blob/0dc1b70d2604e6ac4c0cb88d36476a8b2c17e9c5/Dmf/Modules.Library/Dmf_VirtualEyeGaze.c
// The source spells it with macros; each line below is the HID 1.11 §6.2.2.2 short-item
// encoding (prefix byte, little-endian data) of the macro named in its comment, in order.
const std::vector<std::uint8_t> kDmfVirtualEyeGaze = {
    0x05, 0x12,                    // HID_USAGE_PAGE(HID_USAGE_PAGE_EYE_HEAD_TRACKER)
    0x09, 0x01,                    // HID_USAGE(HID_USAGE_EYE_TRACKER)
    0xA1, 0x01,                    // HID_BEGIN_APPLICATION_COLLECTION()
    0x09, 0x10,                    //   HID_USAGE(HID_USAGE_TRACKING_DATA)
    0xA1, 0x02,                    //   HID_BEGIN_LOGICAL_COLLECTION()
    0x85, 0x10,                    //     HID_REPORT_ID(HID_USAGE_TRACKING_DATA)
    0x15, 0x00,                    //     HID_LOGICAL_MINIMUM_BYTE(0x00)
    0x26, 0xFF, 0x00,              //     HID_LOGICAL_MAXIMUM_WORD(0x00FF)
    0x75, 0x08,                    //     HID_REPORT_SIZE_UINT8()
    0x09, 0x20,                    //     HID_USAGE(HID_USAGE_TIMESTAMP)
    0x66, 0x01, 0x10,              //     HID_UNIT_WORD(0x1001)
    0x55, 0x0A,                    //     HID_UNIT_EXPONENT_BYTE(0x0A)
    0x95, 0x08,                    //     HID_REPORT_COUNT(8)
    0x81, 0x02,                    //     HID_INPUT_DYNAMIC_VALUE()
    0x95, 0x01,                    //     HID_REPORT_COUNT(1)
    0x75, 0x20,                    //     HID_REPORT_SIZE_UINT32()
    0x65, 0x11,                    //     HID_UNIT_BYTE(0x11)
    0x55, 0x0C,                    //     HID_UNIT_EXPONENT_BYTE(0x0C)
    0x17, 0x80, 0x7B, 0xE1, 0xFF,  //     HID_LOGICAL_MINIMUM_DWORD(0xFFE17B80)
    0x27, 0x80, 0x84, 0x1E, 0x00,  //     HID_LOGICAL_MAXIMUM_DWORD(0x001E8480)
    0x09, 0x24,                    //     HID_USAGE(HID_USAGE_GAZE_LOCATION)
    0xA1, 0x00,                    //     HID_BEGIN_PHYSICAL_COLLECTION()
    0x95, 0x02,                    //       HID_REPORT_COUNT(2)
    0x09, 0x21, 0x09, 0x22,        //       HID_USAGE(HID_USAGE_POSITION_X), HID_USAGE(HID_USAGE_POSITION_Y)
    0x81, 0x03,                    //       HID_INPUT_STATIC_VALUE()
    0xC0,                          //     HID_END_COLLECTION_EX()
    0x09, 0x25,                    //     HID_USAGE(HID_USAGE_LEFT_EYE_POSITION)
    0xA1, 0x00,                    //     HID_BEGIN_PHYSICAL_COLLECTION()
    0x95, 0x03,                    //       HID_REPORT_COUNT(3)
    0x09, 0x21, 0x09, 0x22, 0x09, 0x23,  // HID_USAGE(HID_USAGE_POSITION_X/_Y/_Z)
    0x81, 0x03,                    //       HID_INPUT_STATIC_VALUE()
    0xC0,                          //     HID_END_COLLECTION_EX()
    0x09, 0x26,                    //     HID_USAGE(HID_USAGE_RIGHT_EYE_POSITION)
    0xA1, 0x00,                    //     HID_BEGIN_PHYSICAL_COLLECTION()
    0x95, 0x03,                    //       HID_REPORT_COUNT(3)
    0x09, 0x21, 0x09, 0x22, 0x09, 0x23,  // HID_USAGE(HID_USAGE_POSITION_X/_Y/_Z)
    0x81, 0x03,                    //       HID_INPUT_STATIC_VALUE()
    0xC0,                          //     HID_END_COLLECTION_EX()
    0x09, 0x27,                    //     HID_USAGE(HID_USAGE_HEAD_POSITION)
    0xA1, 0x00,                    //     HID_BEGIN_PHYSICAL_COLLECTION()
    0x95, 0x03,                    //       HID_REPORT_COUNT(3)
    0x09, 0x21, 0x09, 0x22, 0x09, 0x23,  // HID_USAGE(HID_USAGE_POSITION_X/_Y/_Z)
    0x81, 0x03,                    //       HID_INPUT_STATIC_VALUE()
    0xC0,                          //     HID_END_COLLECTION_EX()
    0x09, 0x28,                    //     HID_USAGE(HID_USAGE_HEAD_DIRECTION)
    0xA1, 0x00,                    //     HID_BEGIN_PHYSICAL_COLLECTION()
    0x95, 0x03,                    //       HID_REPORT_COUNT(3)
    0x09, 0x29, 0x09, 0x2A, 0x09, 0x2B,  // HID_USAGE(HID_USAGE_ROTATION_ABOUT_X/_Y/_Z_AXIS)
    0x81, 0x03,                    //       HID_INPUT_STATIC_VALUE()
    0xC0,                          //     HID_END_COLLECTION_EX()
    0xC0,                          //   HID_END_COLLECTION_EX()
    0x09, 0x11,                    //   HID_USAGE(HID_USAGE_CAPABILITIES)
    0xA1, 0x02,                    //   HID_BEGIN_LOGICAL_COLLECTION()
    0x85, 0x11,                    //     HID_REPORT_ID(HID_USAGE_CAPABILITIES)
    0x75, 0x08,                    //     HID_REPORT_SIZE_UINT8()
    0x95, 0x01,                    //     HID_REPORT_COUNT(1)
    0x0A, 0x00, 0x01,              //     HID_USAGE_WORD(HID_USAGE_TRACKER_QUALITY)
    0x15, 0x00,                    //     HID_LOGICAL_MINIMUM_BYTE(0x00)
    0x25, 0x01,                    //     HID_LOGICAL_MAXIMUM_BYTE(0x01)
    0x65, 0x00,                    //     HID_UNIT_BYTE(0x00)
    0x55, 0x00,                    //     HID_UNIT_EXPONENT_BYTE(0x00)
    0xB1, 0x03,                    //     HID_FEATURE_STATIC_VALUE()
    0xA1, 0x00,                    //     HID_BEGIN_PHYSICAL_COLLECTION()
    0x95, 0x05,                    //       HID_REPORT_COUNT(5)
    0x75, 0x20,                    //       HID_REPORT_SIZE_UINT32()
    0x17, 0x80, 0x7B, 0xE1, 0xFF,  //       HID_LOGICAL_MINIMUM_DWORD(0xFFE17B80)
    0x27, 0x80, 0x84, 0x1E, 0x00,  //       HID_LOGICAL_MAXIMUM_DWORD(0x001E8480)
    0x65, 0x11,                    //       HID_UNIT_BYTE(0x11)
    0x55, 0x0C,                    //       HID_UNIT_EXPONENT_BYTE(0x0C)
    0x0A, 0x01, 0x01,              //       HID_USAGE_WORD(HID_USAGE_MINIMUM_TRACKING_DISTANCE)
    0x0A, 0x02, 0x01,              //       HID_USAGE_WORD(HID_USAGE_OPTIMUM_TRACKING_DISTANCE)
    0x0A, 0x03, 0x01,              //       HID_USAGE_WORD(HID_USAGE_MAXIMUM_TRACKING_DISTANCE)
    0x0A, 0x04, 0x01,              //       HID_USAGE_WORD(HID_USAGE_MAXIMUM_SCREEN_PLANE_WIDTH)
    0x0A, 0x05, 0x01,              //       HID_USAGE_WORD(HID_USAGE_MAXIMUM_SCREEN_PLANE_HEIGHT)
    0xB1, 0x03,                    //       HID_FEATURE_STATIC_VALUE()
    0xC0,                          //     HID_END_COLLECTION_EX()
    0xC0,                          //   HID_END_COLLECTION_EX()
    0x09, 0x12,                    //   HID_USAGE(HID_USAGE_CONFIGURATION)
    0xA1, 0x02,                    //   HID_BEGIN_LOGICAL_COLLECTION()
    0x85, 0x12,                    //     HID_REPORT_ID(HID_USAGE_CONFIGURATION)
    0x75, 0x08,                    //     HID_REPORT_SIZE_UINT8()
    0x15, 0x00,                    //     HID_LOGICAL_MINIMUM_BYTE(0x00)
    0x26, 0xFF, 0x00,              //     HID_LOGICAL_MAXIMUM_WORD(0x00FF)
    0x95, 0x01,                    //     HID_REPORT_COUNT(1)
    0x75, 0x10,                    //     HID_REPORT_SIZE_UINT16()
    0x27, 0xFF, 0xFF, 0x00, 0x00,  //     HID_LOGICAL_MAXIMUM_DWORD(0x0000FFFF)
    0x65, 0x00,                    //     HID_UNIT_BYTE(0x00)
    0x55, 0x00,                    //     HID_UNIT_EXPONENT_BYTE(0x00)
    0x0A, 0x00, 0x02,              //     HID_USAGE_WORD(HID_USAGE_DISPLAY_MANUFACTURER_ID)
    0xB1, 0x03,                    //     HID_FEATURE_STATIC_VALUE()
    0x0A, 0x01, 0x02,              //     HID_USAGE_WORD(HID_USAGE_DISPLAY_PRODUCT_ID)
    0xB1, 0x03,                    //     HID_FEATURE_STATIC_VALUE()
    0x75, 0x20,                    //     HID_REPORT_SIZE_UINT32()
    0x27, 0xFF, 0xFF, 0xFF, 0x7F,  //     HID_LOGICAL_MAXIMUM_DWORD(0x7FFFFFFF)
    0x0A, 0x02, 0x02,              //     HID_USAGE_WORD(HID_USAGE_DISPLAY_SERIAL_NUMBER)
    0xB1, 0x03,                    //     HID_FEATURE_STATIC_VALUE()
    0x75, 0x10,                    //     HID_REPORT_SIZE_UINT16()
    0x15, 0x00,                    //     HID_LOGICAL_MINIMUM_BYTE(0x00)
    0x27, 0xFF, 0xFF, 0x00, 0x00,  //     HID_LOGICAL_MAXIMUM_DWORD(0x0000FFFF)
    0x0A, 0x03, 0x02,              //     HID_USAGE_WORD(HID_USAGE_DISPLAY_MANUFACTURER_DATE)
    0xB1, 0x03,                    //     HID_FEATURE_STATIC_VALUE()
    0xA1, 0x00,                    //     HID_BEGIN_PHYSICAL_COLLECTION()
    0x65, 0x11,                    //       HID_UNIT_BYTE(0x11)
    0x55, 0x0C,                    //       HID_UNIT_EXPONENT_BYTE(0x0C)
    0x27, 0xFF, 0xFF, 0xFF, 0x7F,  //       HID_LOGICAL_MAXIMUM_DWORD(0x7FFFFFFF)
    0x75, 0x20,                    //       HID_REPORT_SIZE_UINT32()
    0x0A, 0x04, 0x02,              //       HID_USAGE_WORD(HID_USAGE_CALIBRATED_SCREEN_WIDTH)
    0xB1, 0x03,                    //       HID_FEATURE_STATIC_VALUE()
    0x0A, 0x05, 0x02,              //       HID_USAGE_WORD(HID_USAGE_CALIBRATED_SCREEN_HEIGHT)
    0xB1, 0x03,                    //       HID_FEATURE_STATIC_VALUE()
    0xC0,                          //     HID_END_COLLECTION_EX()
    0xC0,                          //   HID_END_COLLECTION_EX()
    0x09, 0x13,                    //   HID_USAGE(HID_USAGE_TRACKER_STATUS)
    0xA1, 0x02,                    //   HID_BEGIN_LOGICAL_COLLECTION()
    0x85, 0x13,                    //     HID_REPORT_ID(HID_USAGE_TRACKER_STATUS)
    0x75, 0x08,                    //     HID_REPORT_SIZE_UINT8()
    0x65, 0x00,                    //     HID_UNIT_BYTE(0x00)
    0x55, 0x00,                    //     HID_UNIT_EXPONENT_BYTE(0x00)
    0x25, 0x04,                    //     HID_LOGICAL_MAXIMUM_BYTE(0x04)
    0x0A, 0x01, 0x03,              //     HID_USAGE_WORD(HID_USAGE_CONFIGURATION_STATUS)
    0xB1, 0x02,                    //     HID_FEATURE_DYNAMIC_VALUE()
    0x75, 0x10,                    //     HID_REPORT_SIZE_UINT16()
    0x27, 0xFF, 0xFF, 0x00, 0x00,  //     HID_LOGICAL_MAXIMUM_DWORD(0x0000FFFF)
    0x66, 0x01, 0xF0,              //     HID_UNIT_WORD(0xF001)
    0x55, 0x00,                    //     HID_UNIT_EXPONENT_BYTE(0x00)
    0x0A, 0x00, 0x03,              //     HID_USAGE_WORD(HID_USAGE_SAMPLING_FREQUENCY)
    0xB1, 0x02,                    //     HID_FEATURE_DYNAMIC_VALUE()
    0xC0,                          //   HID_END_COLLECTION_EX()
    0x09, 0x13,                    //   HID_USAGE(HID_USAGE_TRACKER_STATUS)
    0xA1, 0x02,                    //   HID_BEGIN_LOGICAL_COLLECTION()
    0x85, 0x13,                    //     HID_REPORT_ID(HID_USAGE_TRACKER_STATUS)
    0x75, 0x08,                    //     HID_REPORT_SIZE_UINT8()
    0x65, 0x00,                    //     HID_UNIT_BYTE(0x00)
    0x55, 0x00,                    //     HID_UNIT_EXPONENT_BYTE(0x00)
    0x25, 0x04,                    //     HID_LOGICAL_MAXIMUM_BYTE(0x04)
    0x0A, 0x01, 0x03,              //     HID_USAGE_WORD(HID_USAGE_CONFIGURATION_STATUS)
    0x81, 0x02,                    //     HID_INPUT_DYNAMIC_VALUE()
    0x75, 0x10,                    //     HID_REPORT_SIZE_UINT16()
    0x27, 0xFF, 0xFF, 0x00, 0x00,  //     HID_LOGICAL_MAXIMUM_DWORD(0x0000FFFF)
    0x66, 0x01, 0xF0,              //     HID_UNIT_WORD(0xF001)
    0x55, 0x00,                    //     HID_UNIT_EXPONENT_BYTE(0x00)
    0x0A, 0x00, 0x03,              //     HID_USAGE_WORD(HID_USAGE_SAMPLING_FREQUENCY)
    0x81, 0x02,                    //     HID_INPUT_DYNAMIC_VALUE()
    0xC0,                          //   HID_END_COLLECTION_EX()
    0x09, 0x14,                    //   HID_USAGE(HID_USAGE_TRACKER_CONTROL)
    0xA1, 0x02,                    //   HID_BEGIN_LOGICAL_COLLECTION()
    0x85, 0x14,                    //     HID_REPORT_ID(HID_USAGE_TRACKER_CONTROL)
    0x75, 0x08,                    //     HID_REPORT_SIZE_UINT8()
    0x25, 0x07,                    //     HID_LOGICAL_MAXIMUM_BYTE(0x07)
    0x65, 0x00,                    //     HID_UNIT_BYTE(0x00)
    0x55, 0x00,                    //     HID_UNIT_EXPONENT_BYTE(0x00)
    0x0A, 0x00, 0x04,              //     HID_USAGE_WORD(HID_USAGE_MODE_REQUEST)
    0xB1, 0x02,                    //     HID_FEATURE_DYNAMIC_VALUE()
    0xC0,                          //   HID_END_COLLECTION_EX()
    0xC0,                          // HID_END_COLLECTION_EX()
};

TEST(HidDescriptor, PublishedMicrosoftVirtualEyeGazeDescriptor) {
  const Descriptor d = parse_descriptor(kDmfVirtualEyeGaze);
  EXPECT_TRUE(d.uses_report_ids);
  EXPECT_EQ(d.long_items, 0u);
  // The packed report structs of the same driver: GAZE_REPORT is the ID byte and GAZE_DATA
  // (Dmf_EyeGazeIoctl_Public.h: 8-byte timestamp, 2-D gaze point, four 3-D points, 64 bytes),
  // CONFIGURATION_REPORT the ID and 18 bytes, TRACKER_STATUS_REPORT {ReportId,
  // ConfigurationStatus, SamplingFrequency}, TRACKER_CONTROL_REPORT {ReportId, ModeRequest}.
  EXPECT_EQ(d.report_bytes(ReportType::Input, 0x10), 65u);
  EXPECT_EQ(d.report_bytes(ReportType::Feature, 0x11), 1u + 1 + 5 * 4);
  EXPECT_EQ(d.report_bytes(ReportType::Feature, 0x12), 1u + 2 + 2 + 4 + 2 + 4 + 4);
  EXPECT_EQ(d.report_bytes(ReportType::Feature, 0x13), 4u);
  EXPECT_EQ(d.report_bytes(ReportType::Input, 0x13), 4u);
  EXPECT_EQ(d.report_bytes(ReportType::Feature, 0x14), 2u);
  EXPECT_EQ(d.report_ids(ReportType::Input), bytes({0x10, 0x13}));
  EXPECT_EQ(d.report_ids(ReportType::Feature), bytes({0x11, 0x12, 0x13, 0x14}));

  // The head-direction field: three 32-bit rotations inside Eye Tracker > Tracking Data >
  // Head Direction Point, constant (Cnst,Var,Abs) as declared.
  const auto head_dir = std::find_if(d.fields.begin(), d.fields.end(), [](const Field& f) {
    return f.type == ReportType::Input && f.usage_of(0) == 0x120029u;
  });
  ASSERT_NE(head_dir, d.fields.end());
  EXPECT_EQ(head_dir->report_id, 0x10);
  EXPECT_EQ(head_dir->bit_offset, 64u + 11 * 32);  // after gaze (2), both eyes (6), head position (3)
  EXPECT_EQ(head_dir->count, 3u);
  EXPECT_EQ(head_dir->bit_size, 32u);
  EXPECT_EQ(head_dir->usage_of(2), 0x12002Bu);
  EXPECT_EQ(head_dir->flags, std::uint32_t(kConstant | kVariable));
  EXPECT_EQ(head_dir->collections, (std::vector<std::uint32_t>{0x120001, 0x120010, 0x120028}));
  EXPECT_EQ(head_dir->logical_min, -2000000);
  EXPECT_EQ(head_dir->logical_max, 2000000);
  EXPECT_EQ(head_dir->unit, 0x11u);
  EXPECT_EQ(head_dir->unit_exponent, -4);

  const EyeTrackerCodec c(kDmfVirtualEyeGaze);
  const EyeTrackerLayout& L = c.layout();
  EXPECT_EQ(L.tracking_report_id, 0x10);
  EXPECT_EQ(L.timestamp.bit_offset, 0u);
  EXPECT_EQ(L.timestamp.bits, 64u);
  EXPECT_FALSE(L.timestamp.constant);  // HID_INPUT_DYNAMIC_VALUE here
  EXPECT_DOUBLE_EQ(L.timestamp.si_per_unit, 1e-6);
  EXPECT_EQ(L.gaze_x.bit_offset, 64u);
  EXPECT_EQ(L.gaze_y.bit_offset, 96u);
  EXPECT_NEAR(L.gaze_x.si_per_unit, 1e-6, 1e-18);
  EXPECT_EQ(L.eye[0][0].bit_offset, 128u);
  EXPECT_EQ(L.eye[1][2].bit_offset, 128u + 5 * 32);
  EXPECT_EQ(L.head[0].bit_offset, 64u + 8 * 32);
  EXPECT_EQ(L.calibrated_w.report_id, 0x12);
  EXPECT_EQ(L.calibrated_w.bit_offset, 16u + 16 + 32 + 16);
  EXPECT_EQ(L.calibrated_h.bit_offset, 16u + 16 + 32 + 16 + 32);
  EXPECT_EQ(L.configuration_status.report_id, 0x13);
  EXPECT_EQ(L.sampling_frequency.bit_offset, 8u);
  EXPECT_NEAR(L.sampling_frequency.si_per_unit, 1.0, 1e-12);  // SI, time^-1: Hz
  EXPECT_TRUE(L.status_input_config.found);
  EXPECT_EQ(c.mode_request(kModeGazePoint), bytes({0x14, 0x01}));  // MODE_REQUEST_ENABLE_GAZE_POINT

  // Reports with the defaults the driver sets in DMF_VirtualEyeGaze_Open: tracker quality
  // 1 (fine gaze), tracking distances 50000/65000/90000 µm, status 3 (screen setup
  // needed) at 100 Hz.
  DeviceConfig cfg;
  std::vector<std::uint8_t> caps = {0x11, 0x01};
  for (const std::uint32_t um : {50000u, 65000u, 90000u, 0u, 0u})
    for (int b = 0; b < 4; ++b) caps.push_back(std::uint8_t(um >> (8 * b)));
  ASSERT_TRUE(c.decode_feature(caps, cfg));
  EXPECT_EQ(cfg.tracker_quality, 1);
  EXPECT_NEAR(cfg.min_distance_m, 0.05, 1e-12);
  EXPECT_NEAR(cfg.optimum_distance_m, 0.065, 1e-12);
  EXPECT_NEAR(cfg.max_distance_m, 0.09, 1e-12);
  ASSERT_TRUE(c.decode_feature(bytes({0x13, 0x03, 0x64, 0x00}), cfg));
  EXPECT_EQ(cfg.configuration_status, 3);
  EXPECT_DOUBLE_EQ(cfg.sampling_hz, 100.0);
  // A calibrated 527040 x 296460 µm screen, then a gaze report: 1.5 s, (-1000, 250000) µm.
  std::vector<std::uint8_t> conf(19, 0);
  conf[0] = 0x12;
  for (int b = 0; b < 4; ++b) {
    conf[11 + b] = std::uint8_t(527040u >> (8 * b));
    conf[15 + b] = std::uint8_t(296460u >> (8 * b));
  }
  ASSERT_TRUE(c.decode_feature(conf, cfg));
  EXPECT_NEAR(cfg.screen_w_m, 0.52704, 1e-12);
  EXPECT_NEAR(cfg.screen_h_m, 0.29646, 1e-12);
  std::vector<std::uint8_t> gaze(65, 0);
  gaze[0] = 0x10;
  for (int b = 0; b < 8; ++b) gaze[1 + b] = std::uint8_t(std::uint64_t(1500000) >> (8 * b));
  for (int b = 0; b < 4; ++b) {
    gaze[9 + b] = std::uint8_t(std::uint32_t(-1000) >> (8 * b));
    gaze[13 + b] = std::uint8_t(250000u >> (8 * b));
  }
  HidGaze g;
  std::string reason;
  ASSERT_TRUE(c.decode_input(gaze, g, cfg, reason)) << reason;
  EXPECT_DOUBLE_EQ(g.timestamp_s, 1.5);
  EXPECT_TRUE(g.gaze_valid);
  EXPECT_NEAR(g.gaze_x_m, -0.001, 1e-12);
  EXPECT_NEAR(g.gaze_y_m, 0.25, 1e-12);
}

TEST(HidDescriptor, CompactInterleavedLayout) {
  const EyeTrackerCodec c(capture_descriptor("hid-compact.hidcap"));
  const Descriptor& d = c.descriptor();
  const EyeTrackerLayout& L = c.layout();
  EXPECT_EQ(L.tracking_report_id, 0x21);
  EXPECT_EQ(d.report_bytes(ReportType::Input, 0x21), 17u);
  EXPECT_EQ(L.gaze_y.bit_offset, 8u);  // Y before X, after a vendor byte
  EXPECT_EQ(L.gaze_x.bit_offset, 24u);
  EXPECT_EQ(L.gaze_x.bits, 16u);
  EXPECT_FALSE(L.gaze_x.is_signed);
  EXPECT_NEAR(L.gaze_x.si_per_unit, 1e-4, 1e-16);       // cm, exponent −2: 0.1 mm
  EXPECT_EQ(L.timestamp.bit_offset, 48u);                // after padding + vendor nibble
  EXPECT_EQ(L.timestamp.bits, 32u);                      // 2 × 16 bits, extended usage
  EXPECT_NEAR(L.timestamp.si_per_unit, 1e-5, 1e-17);     // 10 µs ticks
  EXPECT_EQ(L.eye[0][2].bit_offset, 80u + 32);           // usage range X..Z
  EXPECT_NEAR(L.eye[0][0].si_per_unit, 1e-3, 1e-15);     // mm
  EXPECT_FALSE(L.eye[1][0].found);
  EXPECT_EQ(L.calibrated_h.bit_offset, 0u);
  EXPECT_EQ(L.calibrated_w.bit_offset, 16u);
  EXPECT_EQ(L.device_mode.report_id, 0x24);
  EXPECT_EQ(L.vendor_usages, 0u);  // vendor page items are not page-0x12 usages
  // The gaze point has the null-state flag: its null value decodes as lost.
  HidGaze g;
  g.gaze_valid = false;
  DeviceConfig cfg;
  cfg.screen_w_m = cfg.screen_h_m = 0.5;
  HidGaze back;
  std::string reason;
  ASSERT_TRUE(c.decode_input(c.encode_gaze(g), back, cfg, reason));
  EXPECT_FALSE(back.gaze_valid);
}

TEST(HidDescriptor, MalformedDescriptorsFailClearly) {
  // A minimal valid eye tracker to mutate.
  const auto ok = reference_descriptor("ms");
  EXPECT_EQ(parse_error(ok), "");
  auto unclosed = ok;
  unclosed.pop_back();  // the last End Collection
  EXPECT_NE(parse_error(unclosed).find("not closed"), std::string::npos) << parse_error(unclosed);
  EXPECT_NE(parse_error(bytes({0x05, 0x12, 0x09, 0x01, 0xA1, 0x01, 0x27, 0xFF})).find("ends first"), std::string::npos);
  EXPECT_NE(parse_error(bytes({0x05, 0x12, 0xFE, 0x10, 0x00, 0xAA})).find("long item"), std::string::npos);
  EXPECT_NE(parse_error(bytes({0x05, 0x12, 0x09, 0x01, 0xA1, 0x01, 0x76, 0x00, 0x10, 0x95, 0x01, 0x81, 0x02, 0xC0})).find("absurd Report Size"),
            std::string::npos);
  EXPECT_NE(parse_error(bytes({0x75, 0x08, 0x97, 0x00, 0x00, 0x01, 0x00, 0x81, 0x02})).find("absurd Report Count"), std::string::npos);
  EXPECT_NE(parse_error(bytes({0xC0})).find("End Collection"), std::string::npos);
  EXPECT_NE(parse_error(bytes({0xB4})).find("Pop without Push"), std::string::npos);
  EXPECT_NE(parse_error(bytes({0x85, 0x00})).find("Report ID must be"), std::string::npos);
  EXPECT_NE(parse_error(bytes({0x75, 0x08, 0x95, 0x01, 0x81, 0x02, 0x85, 0x01, 0x81, 0x02})).find("Report ID after"), std::string::npos);
  EXPECT_NE(parse_error(bytes({})).find("no input"), std::string::npos);
  // A keyboard-like descriptor (page 0x07): parses, but is no eye tracker.
  EXPECT_NE(parse_error(bytes({0x05, 0x07, 0x09, 0x06, 0xA1, 0x01, 0x19, 0xE0, 0x29, 0xE7, 0x15, 0x00, 0x25, 0x01, 0x75,
                               0x01, 0x95, 0x08, 0x81, 0x02, 0xC0}))
                .find("Sensor Timestamp"),
            std::string::npos);
  // A Gaze Point with a time unit is rejected with the unit named.
  auto bad_unit = ok;
  for (std::size_t i = 0; i + 1 < bad_unit.size(); ++i)
    if (bad_unit[i] == 0x65 && bad_unit[i + 1] == 0x11) {  // first "Unit (cm)"
      bad_unit[i + 1] = 0x01;
      bad_unit.insert(bad_unit.begin() + static_cast<long>(i) + 2, 0x10);  // -> 0x1001 (seconds)
      bad_unit[i] = 0x66;
      break;
    }
  EXPECT_NE(parse_error(bad_unit).find("not a length"), std::string::npos) << parse_error(bad_unit);
  // A long item and unknown page-0x12 usages are skipped, not fatal.
  auto extra = bytes({0xFE, 0x02, 0x00, 0xAA, 0xBB});
  extra.insert(extra.end(), ok.begin(), ok.end() - 1);
  for (int b : {0x85, 0x30, 0x0A, 0x50, 0x01, 0x75, 0x08, 0x95, 0x01, 0x81, 0x02, 0xC0}) extra.push_back(static_cast<std::uint8_t>(b));
  ASSERT_EQ(parse_error(extra), "");
  const EyeTrackerCodec c(extra);
  EXPECT_EQ(c.descriptor().long_items, 1u);
  EXPECT_EQ(c.layout().vendor_usages, 1u);
}

TEST(HidDescriptor, RandomBytesNeverCrash) {
  std::mt19937 rng(99);
  const auto ok = reference_descriptor("compact");
  int parsed = 0;
  for (int i = 0; i < 20000; ++i) {
    std::vector<std::uint8_t> d;
    if (i % 2) {  // mutations of a valid descriptor
      d = ok;
      for (int k = 0; k < 3; ++k) d[rng() % d.size()] = static_cast<std::uint8_t>(rng());
      d.resize(rng() % (d.size() + 1));
    } else {
      d.resize(rng() % 64);
      for (auto& b : d) b = static_cast<std::uint8_t>(rng());
    }
    try {
      EyeTrackerCodec c(d);
      ++parsed;
      DeviceConfig cfg;
      cfg.screen_w_m = cfg.screen_h_m = 1;
      HidGaze g;
      std::string reason;
      std::vector<std::uint8_t> rep(rng() % 40);
      for (auto& b : rep) b = static_cast<std::uint8_t>(rng());
      c.decode_input(rep, g, cfg, reason);
      c.decode_feature(rep, cfg);
    } catch (const InputError&) {
    }
  }
  EXPECT_GT(parsed, 0);
}

TEST(HidCapture, ShippedCapturesReplayTheGazeThatBuiltThem) {
  // data/gaze/hid-*.hidcap were recorded with
  //   fovea gaze record --source "hid-emulated:LAYOUT?seed=7&task=search&seconds=2" --seconds 2 --raw FILE out.csv
  for (const char* layout : {"ms", "compact"}) {
    SourceOptions o;
    HidCaptureStream cap(fovea::devices::test::source_dir() + "/data/gaze/hid-" + layout + ".hidcap", o);
    auto ref = synth(7, 2);
    GazeSample a, b;
    int n = 0;
    double worst = 0;
    while (ref->next(a)) {
      ASSERT_TRUE(cap.next(b)) << layout << " sample " << n;
      EXPECT_NEAR(static_cast<double>(b.t_ns), static_cast<double>(a.t_ns), 10'000) << layout;
      const auto px = o.screen_view().dir_to_pixel(a.combined.dir);
      const bool on_screen = a.tracked() && px && o.screen_view().contains_pixel(*px);
      EXPECT_EQ(b.tracked(), on_screen) << layout << " sample " << n;
      if (on_screen) worst = std::max(worst, fovea::core::angle_deg(a.combined.dir, b.combined.dir));
      ++n;
    }
    EXPECT_FALSE(cap.next(b));
    EXPECT_EQ(n, 240);
    EXPECT_LT(worst, std::string(layout) == "ms" ? 1e-3 : 0.05) << layout;  // µm vs 0.1 mm quantisation
    EXPECT_TRUE(cap.stats().dropped.empty());
    EXPECT_NEAR(cap.config().screen_w_m, 0.5, 1e-3);
  }
}

TEST(HidCapture, LiveStreamWritesACaptureThatReplaysIdentically) {
  const std::string path = fovea::devices::test::scratch_dir() + "/live.hidcap";
  SourceOptions o;
  std::vector<GazeSample> live;
  {
    HidGazeStream s(std::make_unique<EmulatedTransport>(synth(3, 1), "compact", o.screen_view()), o, path);
    live = drain(s);
    s.stop();
    EXPECT_NEAR(s.config().sampling_hz, 120, 1e-9);
  }
  ASSERT_EQ(live.size(), 120u);
  HidCaptureStream cap(path, o);
  GazeSample g;
  for (const GazeSample& s : live) {
    ASSERT_TRUE(cap.next(g));
    EXPECT_EQ(g.device_time_ns, s.device_time_ns);
    EXPECT_EQ(g.host_time_ns, s.host_time_ns);
    EXPECT_EQ(g.combined.dir, s.combined.dir);
  }
  // Garbage in a capture: counted, not fatal.
  const std::string bad = fovea::devices::test::write_text(
      "bad.hidcap", "fovea-hid-capture 1\ndescriptor " + to_hex(reference_descriptor("ms")) +
                        "\nget_feature 0 12 00 00 00 00 00 00 00 00 00 00 20 a1 07 00 90 d0 03 00\n"
                        "input 5 10 01 02\ninput x 10\ninput 6 zz\nbogus line\ninput 7 99 00\n");
  HidCaptureStream b(bad, o);
  EXPECT_FALSE(b.next(g));
  EXPECT_EQ(b.stats().dropped.at("short_report"), 1u);
  EXPECT_EQ(b.stats().dropped.at("bad_line"), 3u);
  EXPECT_EQ(b.stats().dropped.at("unknown_report_id"), 1u);
  EXPECT_THROW(HidCaptureStream(fovea::devices::test::write_text("nodesc.hidcap", "fovea-hid-capture 1\ninput 1 10\n"), o), InputError);
  EXPECT_THROW(HidCaptureStream(fovea::devices::test::write_text("nomagic.hidcap", "descriptor 05 12\n"), o), InputError);
}

TEST(HidTransport, FaultsAreSurvivedAndReported) {
  SourceOptions o;
  Faults f;
  f.garbage_every = 7;
  f.short_every = 11;
  f.stall_every = 13;
  HidGazeStream s(std::make_unique<EmulatedTransport>(synth(4, 3), "ms", o.screen_view(), f), o);
  const auto v = drain(s);
  const StreamStats st = s.stats();
  EXPECT_GT(v.size(), 250u);  // most of the 360 samples get through
  EXPECT_GT(st.transport_errors, 20u);
  EXPECT_GT(st.dropped.at("short_report"), 10u);
  EXPECT_FALSE(st.disconnected);
  for (std::size_t i = 1; i < v.size(); ++i) ASSERT_GT(v[i].t_ns, v[i - 1].t_ns);
  for (const GazeSample& g : v) ASSERT_NEAR(glm::length(g.combined.dir), 1.0, 1e-9);

  Faults unplug;
  unplug.unplug_after = 50;
  HidGazeStream u(std::make_unique<EmulatedTransport>(synth(4, 3), "compact", o.screen_view(), unplug), o);
  const auto w = drain(u);
  EXPECT_TRUE(u.finished());
  EXPECT_TRUE(u.stats().disconnected);
  EXPECT_EQ(w.size(), 50u);

  Faults stall;
  stall.feature_stall = true;  // no configuration can be read: the screen size is unknown
  try {
    HidGazeStream x(std::make_unique<EmulatedTransport>(synth(4, 1), "ms", o.screen_view(), stall), o);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("calibrated screen size"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("GET_REPORT"), std::string::npos) << e.what();
  }
}

TEST(HidTransport, GazeStreamIsOffUntilTheHostEnablesIt) {
  SourceOptions o;
  EmulatedTransport t(synth(1, 1), "ms", o.screen_view());
  std::vector<std::uint8_t> buf(256);
  EXPECT_EQ(t.read_input(buf, 0).size, 0u);  // Device Mode Request not yet written
  EXPECT_THROW(t.set_feature(bytes({0x14, 0x09})), TransportError);  // outside the logical range 0..7
  t.set_feature(bytes({0x14, 0x01}));
  EXPECT_EQ(t.read_input(buf, 0).size, 4u);   // status input report first
  EXPECT_EQ(t.read_input(buf, 0).size, 65u);  // then tracking data
}

TEST(HidTransport, LibraryErrorMappingAndMissingDevices) {
  EXPECT_TRUE(detail::libusb_failure(LIBUSB_ERROR_NO_DEVICE, "x").disconnected());
  EXPECT_FALSE(detail::libusb_failure(LIBUSB_ERROR_PIPE, "x").disconnected());
  EXPECT_FALSE(detail::libusb_failure(LIBUSB_ERROR_OVERFLOW, "x").disconnected());
  EXPECT_NE(std::string(detail::libusb_failure(LIBUSB_ERROR_PIPE, "in").what()).find("LIBUSB_ERROR_PIPE"), std::string::npos);
  EXPECT_TRUE(detail::hidapi_failure("/dev/hidraw9", "read", false).disconnected());
  EXPECT_FALSE(detail::hidapi_failure("/dev/hidraw9", "read", true).disconnected());
  std::uint16_t v = 0, p = 0;
  EXPECT_TRUE(detail::parse_vid_pid("2104:0313", v, p));
  EXPECT_EQ(v, 0x2104);
  EXPECT_EQ(p, 0x0313);
  EXPECT_FALSE(detail::parse_vid_pid("2104", v, p));
  EXPECT_FALSE(detail::parse_vid_pid("12345:1", v, p));
  // No such device on this machine: clean InputErrors, no crash (both transports compiled in).
  EXPECT_THROW(open_hidapi("dead:beef"), InputError);
  EXPECT_THROW(open_libusb("dead:beef"), InputError);
  EXPECT_THROW(open_libusb("/dev/hidraw0"), InputError);
  (void)enumerate_hidapi();
  (void)enumerate_libusb();
  EXPECT_THROW(open_gaze_source("hid:dead:beef", SourceOptions{}), InputError);
}

TEST(ClockSync, OffsetAndDriftUnderJitter) {
  ClockSync c;
  std::mt19937_64 rng(5);
  std::exponential_distribution<double> delay(1.0 / 2e6);  // mean 2 ms
  const double drift = 200e-6;
  const TimeNs offset = 7'000'000'000;
  double worst = 0;
  for (int i = 0; i < 120 * 60; ++i) {
    const TimeNs dev = TimeNs(i) * 8'333'333;
    const TimeNs truth = dev + offset + std::llround(static_cast<double>(dev) * drift) + 500'000;  // + minimum delay
    c.add(dev, truth + std::llround(delay(rng)));
    if (i > 120 * 3) worst = std::max(worst, std::abs(static_cast<double>(c.to_host(dev) - truth)));
  }
  EXPECT_LT(worst, 300'000.0);  // 0.3 ms over a minute, with 2 ms mean jitter
  EXPECT_NEAR(c.drift_ppm(), 200, 20);
}

// The HID report-descriptor parser alone, and the bit-field reader over its fields.
#include <algorithm>

#include "../harness.hpp"
#include "fovea/devices/hid_descriptor.hpp"

FOVEA_FUZZ_TARGET(hid_descriptor) {
  const auto d = fovea::devices::hid::parse_descriptor(data);
  for (const auto& f : d.fields) {
    std::int64_t v = 0;
    for (std::uint32_t i = 0; i < f.count && i < 64; ++i)
      (void)fovea::devices::hid::read_bits(data, f.bit_offset + i * f.bit_size, std::min<std::uint32_t>(f.bit_size, 64),
                                           f.logical_min < 0, v);
    (void)f.usage_of(f.count);
  }
  for (const auto t : {fovea::devices::hid::ReportType::Input, fovea::devices::hid::ReportType::Feature})
    for (const auto id : d.report_ids(t)) (void)d.report_bytes(t, id);
}

#pragma once
// HID report-descriptor parser (Device Class Definition for HID 1.11, §6.2.2): short and
// long items, global state with push/pop, local usages (also usage ranges and extended
// 32-bit usages), report IDs, report sizes/counts, logical/physical ranges, unit and unit
// exponent, collections. Produces the fields of every report with their bit offsets.
// Malformed descriptors raise core::InputError naming the byte offset.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace fovea::devices::hid {

enum class ReportType : std::uint8_t { Input = 1, Output = 2, Feature = 3 };
const char* report_type_name(ReportType t);

// Main-item data bits (HID 1.11 §6.2.2.5).
enum MainFlag : std::uint32_t { kConstant = 1u << 0, kVariable = 1u << 1, kRelative = 1u << 2, kNullState = 1u << 6 };

struct Field {
  ReportType type = ReportType::Input;
  std::uint8_t report_id = 0;     // 0: the descriptor uses no report IDs
  std::uint32_t bit_offset = 0;   // from the start of the report data (after the ID byte)
  std::uint32_t bit_size = 0;     // of one value (Report Size)
  std::uint32_t count = 0;        // values (Report Count)
  std::uint32_t flags = 0;        // MainFlag bits
  std::int64_t logical_min = 0, logical_max = 0;
  std::int64_t physical_min = 0, physical_max = 0;
  std::uint32_t unit = 0;
  int unit_exponent = 0;
  // Extended usage (page << 16 | id) of each value; a shorter list repeats its last entry.
  std::vector<std::uint32_t> usages;
  // Extended usages of the enclosing collections, outermost first.
  std::vector<std::uint32_t> collections;

  std::uint32_t usage_of(std::uint32_t i) const;  // 0 if none
};

struct Descriptor {
  std::vector<Field> fields;
  bool uses_report_ids = false;
  std::uint32_t long_items = 0;  // skipped (no long item tags are defined)
  // Size in bytes of a report as on the wire, including the report ID byte if IDs are used.
  std::size_t report_bytes(ReportType t, std::uint8_t id) const;
  std::vector<std::uint8_t> report_ids(ReportType t) const;
};

Descriptor parse_descriptor(std::span<const std::uint8_t> bytes);

// Raw little-endian bit extraction/insertion within report data (after the ID byte).
// `bits` up to 64; `is_signed` sign-extends. Out-of-range reads return false.
bool read_bits(std::span<const std::uint8_t> data, std::uint32_t bit_offset, std::uint32_t bits, bool is_signed, std::int64_t& out);
void write_bits(std::span<std::uint8_t> data, std::uint32_t bit_offset, std::uint32_t bits, std::int64_t value);

// Hex helpers for captures and messages: "05 12 09 01" <-> bytes.
std::string to_hex(std::span<const std::uint8_t> bytes);
bool from_hex(std::string_view text, std::vector<std::uint8_t>& out);

}  // namespace fovea::devices::hid

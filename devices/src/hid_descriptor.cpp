#include "fovea/devices/hid_descriptor.hpp"

#include <algorithm>
#include <map>

#include "fovea/core/error.hpp"

namespace fovea::devices::hid {

namespace {
constexpr std::uint32_t kMaxReportSize = 256;      // bits per value (Linux's limit too)
constexpr std::uint32_t kMaxReportCount = 4096;
constexpr std::size_t kMaxReportBytes = 16384;     // HID_MAX_BUFFER_SIZE
constexpr int kMaxDepth = 32;

struct Global {
  std::uint16_t usage_page = 0;
  std::int64_t logical_min = 0, logical_max = 0, physical_min = 0, physical_max = 0;
  std::uint32_t unit = 0;
  int unit_exponent = 0;
  std::uint32_t report_size = 0, report_count = 0;
  std::uint8_t report_id = 0;
};

struct Local {
  std::vector<std::pair<std::uint32_t, bool>> usages;  // value, extended (4-byte item)
  std::uint32_t usage_min = 0, usage_max = 0;
  bool have_min = false, have_max = false, min_ext = false;
  void clear() { *this = Local{}; }
};

[[noreturn]] void bad(std::size_t at, const std::string& what) {
  throw core::InputError("HID report descriptor, byte " + std::to_string(at) + ": " + what);
}

std::uint32_t unsigned_value(const std::uint8_t* p, int n) {
  std::uint32_t v = 0;
  for (int i = 0; i < n; ++i) v |= std::uint32_t(p[i]) << (8 * i);
  return v;
}
std::int64_t signed_value(const std::uint8_t* p, int n) {
  const std::uint32_t u = unsigned_value(p, n);
  if (n == 0) return 0;
  if (n == 1) return static_cast<std::int8_t>(u);
  if (n == 2) return static_cast<std::int16_t>(u);
  return static_cast<std::int32_t>(u);
}
}  // namespace

const char* report_type_name(ReportType t) {
  switch (t) {
    case ReportType::Input: return "input";
    case ReportType::Output: return "output";
    case ReportType::Feature: return "feature";
  }
  return "?";
}

std::uint32_t Field::usage_of(std::uint32_t i) const {
  if (usages.empty()) return 0;
  return usages[std::min<std::size_t>(i, usages.size() - 1)];
}

std::size_t Descriptor::report_bytes(ReportType t, std::uint8_t id) const {
  std::uint32_t bits = 0;
  for (const Field& f : fields)
    if (f.type == t && f.report_id == id) bits = std::max(bits, f.bit_offset + f.bit_size * f.count);
  if (bits == 0) return 0;
  return (bits + 7) / 8 + (uses_report_ids ? 1 : 0);
}

std::vector<std::uint8_t> Descriptor::report_ids(ReportType t) const {
  std::vector<std::uint8_t> ids;
  for (const Field& f : fields)
    if (f.type == t && std::find(ids.begin(), ids.end(), f.report_id) == ids.end()) ids.push_back(f.report_id);
  return ids;
}

Descriptor parse_descriptor(std::span<const std::uint8_t> b) {
  Descriptor d;
  Global g;
  std::vector<Global> stack;
  Local local;
  std::vector<std::uint32_t> collections;
  std::map<std::pair<int, int>, std::uint32_t> offsets;  // (type, id) -> bits used
  bool seen_main_without_id = false;
  std::size_t i = 0;
  while (i < b.size()) {
    const std::size_t at = i;
    const std::uint8_t prefix = b[i++];
    if (prefix == 0xFE) {  // long item: bDataSize, bLongItemTag, data
      if (i + 2 > b.size()) bad(at, "truncated long item header");
      const std::size_t n = b[i];
      i += 2;
      if (i + n > b.size()) bad(at, "long item data runs past the end (" + std::to_string(n) + " bytes)");
      i += n;
      ++d.long_items;
      continue;
    }
    const int size = (prefix & 3) == 3 ? 4 : (prefix & 3);
    const int type = (prefix >> 2) & 3, tag = prefix >> 4;
    if (i + size > b.size()) bad(at, "item 0x" + to_hex({&prefix, 1}) + " needs " + std::to_string(size) + " data bytes, the descriptor ends first");
    const std::uint8_t* data = b.data() + i;
    i += size;
    const std::uint32_t u = unsigned_value(data, size);
    const std::int64_t s = signed_value(data, size);
    if (type == 0) {  // main
      if (tag == 0x8 || tag == 0x9 || tag == 0xB) {
        const ReportType rt = tag == 0x8 ? ReportType::Input : tag == 0x9 ? ReportType::Output : ReportType::Feature;
        if (g.report_size == 0 && g.report_count != 0) bad(at, "main item with Report Count but no Report Size");
        if (g.report_size > kMaxReportSize) bad(at, "absurd Report Size " + std::to_string(g.report_size));
        if (g.report_count > kMaxReportCount) bad(at, "absurd Report Count " + std::to_string(g.report_count));
        if (g.report_id == 0) seen_main_without_id = true;
        if (d.uses_report_ids && seen_main_without_id) bad(at, "main items both with and without a Report ID");
        Field f;
        f.type = rt;
        f.report_id = g.report_id;
        f.bit_size = g.report_size;
        f.count = g.report_count;
        f.flags = u;
        f.logical_min = g.logical_min;
        f.logical_max = g.logical_max;
        // A non-negative minimum with a "negative" maximum is an unsigned maximum.
        if (f.logical_min >= 0 && f.logical_max < f.logical_min) f.logical_max &= 0xFFFFFFFFll;
        f.physical_min = g.physical_min;
        f.physical_max = g.physical_max;
        f.unit = g.unit;
        f.unit_exponent = g.unit_exponent;
        f.collections = collections;
        auto ext = [&](std::uint32_t v, bool is_ext) { return is_ext ? v : (std::uint32_t(g.usage_page) << 16 | (v & 0xFFFF)); };
        for (const auto& [v, e] : local.usages) f.usages.push_back(ext(v, e));
        if (local.have_min && local.have_max) {
          const std::uint32_t lo = ext(local.usage_min, local.min_ext), hi = ext(local.usage_max, local.min_ext);
          if (hi < lo) bad(at, "Usage Maximum below Usage Minimum");
          for (std::uint64_t x = lo; x <= hi && f.usages.size() < std::max<std::uint32_t>(f.count, 1); ++x)
            f.usages.push_back(static_cast<std::uint32_t>(x));
        }
        std::uint32_t& off = offsets[{static_cast<int>(rt), g.report_id}];
        f.bit_offset = off;
        off += f.bit_size * f.count;
        if (off / 8 + 1 > kMaxReportBytes) bad(at, "report " + std::to_string(g.report_id) + " grows beyond " + std::to_string(kMaxReportBytes) + " bytes");
        if (f.count > 0 && f.bit_size > 0) d.fields.push_back(std::move(f));
        local.clear();
      } else if (tag == 0xA) {  // collection
        if (collections.size() >= kMaxDepth) bad(at, "collections nested too deeply");
        std::uint32_t usage = 0;
        if (!local.usages.empty()) {
          const auto& [v, e] = local.usages.front();
          usage = e ? v : (std::uint32_t(g.usage_page) << 16 | (v & 0xFFFF));
        }
        collections.push_back(usage);
        local.clear();
      } else if (tag == 0xC) {
        if (collections.empty()) bad(at, "End Collection without an open collection");
        collections.pop_back();
        local.clear();
      } else {
        bad(at, "unknown main item tag 0x" + to_hex({reinterpret_cast<const std::uint8_t*>(&prefix), 1}));
      }
    } else if (type == 1) {  // global
      switch (tag) {
        case 0x0: g.usage_page = static_cast<std::uint16_t>(u); break;
        case 0x1: g.logical_min = s; break;
        case 0x2: g.logical_max = s; break;
        case 0x3: g.physical_min = s; break;
        case 0x4: g.physical_max = s; break;
        case 0x5: g.unit_exponent = (size == 1 && u <= 0xF) ? ((u & 0x8) ? int(u) - 16 : int(u)) : int(s); break;
        case 0x6: g.unit = u; break;
        case 0x7: g.report_size = u; break;
        case 0x8:
          if (u == 0 || u > 255) bad(at, "Report ID must be 1..255, got " + std::to_string(u));
          if (seen_main_without_id) bad(at, "Report ID after main items without one");
          g.report_id = static_cast<std::uint8_t>(u);
          d.uses_report_ids = true;
          break;
        case 0x9: g.report_count = u; break;
        case 0xA:
          if (stack.size() >= 16) bad(at, "Push stack overflow");
          stack.push_back(g);
          break;
        case 0xB:
          if (stack.empty()) bad(at, "Pop without Push");
          g = stack.back();
          stack.pop_back();
          break;
        default: bad(at, "unknown global item tag " + std::to_string(tag));
      }
    } else if (type == 2) {  // local
      switch (tag) {
        case 0x0: local.usages.emplace_back(u, size == 4); break;
        case 0x1: local.usage_min = u; local.have_min = true; local.min_ext = size == 4; break;
        case 0x2: local.usage_max = u; local.have_max = true; break;
        default: break;  // designators, strings, delimiters: not needed
      }
    } else {
      bad(at, "reserved item type");
    }
  }
  if (!collections.empty()) bad(b.size(), std::to_string(collections.size()) + " collection(s) not closed");
  if (d.fields.empty()) bad(b.size(), "no input, output or feature items");
  return d;
}

bool read_bits(std::span<const std::uint8_t> data, std::uint32_t off, std::uint32_t bits, bool is_signed, std::int64_t& out) {
  if (bits == 0 || bits > 64 || std::uint64_t(off) + bits > std::uint64_t(data.size()) * 8) return false;
  std::uint64_t v = 0;
  for (std::uint32_t k = 0; k < bits; ++k) {
    const std::uint32_t p = off + k;
    v |= std::uint64_t((data[p / 8] >> (p % 8)) & 1u) << k;
  }
  if (is_signed && bits < 64 && (v >> (bits - 1)) & 1u) v |= ~std::uint64_t(0) << bits;
  out = static_cast<std::int64_t>(v);
  return true;
}

void write_bits(std::span<std::uint8_t> data, std::uint32_t off, std::uint32_t bits, std::int64_t value) {
  const std::uint64_t v = static_cast<std::uint64_t>(value);
  for (std::uint32_t k = 0; k < bits && k < 64; ++k) {
    const std::uint32_t p = off + k;
    if (p / 8 >= data.size()) return;
    const std::uint8_t m = std::uint8_t(1u << (p % 8));
    data[p / 8] = ((v >> k) & 1u) ? (data[p / 8] | m) : (data[p / 8] & ~m);
  }
}

std::string to_hex(std::span<const std::uint8_t> bytes) {
  static const char* h = "0123456789abcdef";
  std::string s;
  s.reserve(bytes.size() * 3);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (i) s += ' ';
    s += h[bytes[i] >> 4];
    s += h[bytes[i] & 15];
  }
  return s;
}

bool from_hex(std::string_view t, std::vector<std::uint8_t>& out) {
  out.clear();
  int hi = -1;
  for (char c : t) {
    int v;
    if (c >= '0' && c <= '9') v = c - '0';
    else if (c >= 'a' && c <= 'f') v = c - 'a' + 10;
    else if (c >= 'A' && c <= 'F') v = c - 'A' + 10;
    else if (c == ' ' || c == '\t') {
      if (hi >= 0) return false;  // odd digit count inside a byte
      continue;
    } else return false;
    if (hi < 0) hi = v;
    else {
      out.push_back(static_cast<std::uint8_t>(hi << 4 | v));
      hi = -1;
    }
  }
  return hi < 0;
}

}  // namespace fovea::devices::hid

#pragma once
// Streaming line reader over plain or gzip files (zlib reads both), bounded memory:
// one fixed read buffer plus the current line, never more than kMaxLine bytes.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace fovea::devices::detail {

struct Line {
  std::string_view text;      // without '\n' / "\r\n"; a leading UTF-8 BOM is removed
  std::uint64_t number = 0;   // 1-based
  bool unterminated = false;  // the file ended without a newline after this line
  bool overlong = false;      // longer than kMaxLine: text is empty, the rest was skipped
};

class LineReader {
 public:
  static constexpr std::size_t kChunk = 64 * 1024;
  static constexpr std::size_t kMaxLine = 1 << 20;

  explicit LineReader(const std::string& path);  // throws core::InputError
  ~LineReader();
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  bool next(Line& out);
  void rewind();
  const std::string& path() const { return path_; }
  // Bytes held by the reader (buffer capacity), the figure behind the memory bound.
  std::size_t peak_bytes() const { return peak_; }
  // After the last line: the gzip stream ended before its trailer (a cut file). The lines
  // read are what the file holds; the caller decides how to report it.
  bool truncated() const { return truncated_; }

 private:
  bool fill();  // appends one chunk; false at end of file
  std::string path_;
  void* gz_ = nullptr;
  std::vector<char> buf_;
  std::size_t begin_ = 0, end_ = 0;
  std::uint64_t number_ = 0;
  bool eof_ = false, truncated_ = false;
  std::size_t peak_ = 0;
};

}  // namespace fovea::devices::detail

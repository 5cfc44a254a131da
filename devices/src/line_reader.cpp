#include "line_reader.hpp"

#include <zlib.h>

#include <cstring>

#include "fovea/core/error.hpp"

namespace fovea::devices::detail {

LineReader::LineReader(const std::string& path) : path_(path) {
  gz_ = gzopen(path.c_str(), "rb");
  if (!gz_) throw core::InputError(path + ": cannot open for reading");
  gzbuffer(static_cast<gzFile>(gz_), kChunk);
  buf_.resize(2 * kChunk);
}

LineReader::~LineReader() {
  if (gz_) gzclose(static_cast<gzFile>(gz_));
}

void LineReader::rewind() {
  if (gzrewind(static_cast<gzFile>(gz_)) != 0) throw core::InputError(path_ + ": cannot rewind");
  begin_ = end_ = 0;
  number_ = 0;
  eof_ = truncated_ = false;
}

bool LineReader::fill() {
  if (eof_) return false;
  if (begin_ > 0) {  // compact: keep only the unread tail
    std::memmove(buf_.data(), buf_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  if (buf_.size() - end_ < kChunk) {  // grow by exactly one chunk (no doubling): the bound stays tight
    buf_.reserve(end_ + kChunk);
    buf_.resize(end_ + kChunk);
  }
  peak_ = std::max(peak_, buf_.capacity());
  const int n = gzread(static_cast<gzFile>(gz_), buf_.data() + end_, static_cast<unsigned>(kChunk));
  if (n < 0) {
    int err = 0;
    throw core::InputError(path_ + ": read error (" + gzerror(static_cast<gzFile>(gz_), &err) + ")");
  }
  if (n == 0) {
    int err = Z_OK;
    gzerror(static_cast<gzFile>(gz_), &err);
    truncated_ = err == Z_BUF_ERROR;  // zlib: "unexpected end of file" inside a gzip member
    eof_ = true;
    return false;
  }
  end_ += static_cast<std::size_t>(n);
  return true;
}

bool LineReader::next(Line& out) {
  out = Line{};
  std::size_t scan = begin_;
  bool overlong = false;
  for (;;) {
    const void* nl = std::memchr(buf_.data() + scan, '\n', end_ - scan);
    if (nl) {
      const std::size_t pos = static_cast<const char*>(nl) - buf_.data();
      out.number = ++number_;
      if (overlong) {
        out.overlong = true;
      } else {
        std::size_t len = pos - begin_;
        if (len > 0 && buf_[begin_ + len - 1] == '\r') --len;
        out.text = std::string_view(buf_.data() + begin_, len);
      }
      begin_ = pos + 1;
      break;
    }
    if (end_ - begin_ > kMaxLine) {  // drop what we have of an overlong line, keep scanning
      overlong = true;
      begin_ = end_;
    }
    scan = end_;
    const std::size_t before = begin_;
    if (!fill()) {
      if (end_ == begin_ && !overlong) return false;
      out.number = ++number_;
      out.unterminated = true;
      if (overlong) {
        out.overlong = true;
      } else {
        std::size_t len = end_ - begin_;
        if (len > 0 && buf_[begin_ + len - 1] == '\r') --len;
        out.text = std::string_view(buf_.data() + begin_, len);
      }
      begin_ = end_;
      break;
    }
    scan = scan - before + begin_;  // fill() may have compacted the buffer
  }
  if (out.number == 1 && out.text.size() >= 3 && std::memcmp(out.text.data(), "\xEF\xBB\xBF", 3) == 0)
    out.text.remove_prefix(3);
  return true;
}

}  // namespace fovea::devices::detail

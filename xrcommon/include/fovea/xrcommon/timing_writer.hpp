#pragma once
// The one writer of timing records (timing_record.hpp), one JSON object per line.
#include <string>

#include "fovea/xrcommon/timing_record.hpp"

namespace fovea::xrcommon {

class TimingWriter {
 public:
  // Stream: lines appear in the file as they are written (a live session's log, readable
  // while it runs and after a crash). Append: as Stream, after what the file already holds
  // (O_APPEND: each line lands whole at the end, also with other writers of the file).
  // Atomic: written under PATH.tmp and renamed onto PATH by close(), so PATH is either absent
  // or complete (a tool's output).
  enum class Mode { Stream, Append, Atomic };

  TimingWriter() = default;
  ~TimingWriter();  // closes; an Atomic file not closed is removed (incomplete)
  TimingWriter(const TimingWriter&) = delete;
  TimingWriter& operator=(const TimingWriter&) = delete;
  TimingWriter(TimingWriter&& o) noexcept;
  TimingWriter& operator=(TimingWriter&& o) noexcept;

  // Creates the file (truncating it, except in Append mode). Throws std::runtime_error naming the path and the reason
  // when it cannot.
  void open(const std::string& path, Mode mode = Mode::Stream);
  bool is_open() const { return fd_ >= 0; }
  // One record, one write(2) of the whole line: a reader never sees half a record. On a
  // write error the file is closed, error() says why and later writes are ignored; returns
  // false then.
  bool write(const TimingRecord& r);
  // Atomic: renames into place (throws std::runtime_error on failure). Stream: closes.
  void close();
  const std::string& path() const { return path_; }
  const std::string& error() const { return error_; }

 private:
  void release() noexcept;
  int fd_ = -1;
  Mode mode_ = Mode::Stream;
  std::string path_, error_;
};

}  // namespace fovea::xrcommon

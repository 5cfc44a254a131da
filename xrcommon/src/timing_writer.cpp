#include "fovea/xrcommon/timing_writer.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace fovea::xrcommon {

namespace {
std::string file_name(const std::string& path, TimingWriter::Mode m) {
  return m == TimingWriter::Mode::Atomic ? path + ".tmp" : path;
}
}  // namespace

TimingWriter::~TimingWriter() { release(); }

TimingWriter::TimingWriter(TimingWriter&& o) noexcept
    : fd_(o.fd_), mode_(o.mode_), path_(std::move(o.path_)), error_(std::move(o.error_)) {
  o.fd_ = -1;
}

TimingWriter& TimingWriter::operator=(TimingWriter&& o) noexcept {
  if (this != &o) {
    release();
    fd_ = o.fd_;
    mode_ = o.mode_;
    path_ = std::move(o.path_);
    error_ = std::move(o.error_);
    o.fd_ = -1;
  }
  return *this;
}

void TimingWriter::release() noexcept {
  if (fd_ < 0) return;
  ::close(fd_);
  fd_ = -1;
  if (mode_ == Mode::Atomic) ::unlink(file_name(path_, mode_).c_str());
}

void TimingWriter::open(const std::string& path, Mode mode) {
  release();
  path_ = path;
  mode_ = mode;
  error_.clear();
  const std::string name = file_name(path, mode);
  fd_ = ::open(name.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | (mode == Mode::Append ? O_APPEND : O_TRUNC), 0644);
  if (fd_ < 0) {
    error_ = "timing records \"" + name + "\": cannot create: " + std::strerror(errno);
    throw std::runtime_error(error_);
  }
}

bool TimingWriter::write(const TimingRecord& r) {
  if (fd_ < 0) return false;
  const std::string line = to_json_line(r);
  std::size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      error_ = "timing records \"" + file_name(path_, mode_) + "\": write failed at frame " + std::to_string(r.frame) +
               ": " + (n < 0 ? std::strerror(errno) : "nothing written") + "; no further records";
      release();
      return false;
    }
    done += std::size_t(n);
  }
  return true;
}

void TimingWriter::close() {
  if (fd_ < 0) return;
  const bool synced = mode_ != Mode::Atomic || ::fsync(fd_) == 0;
  const int err = synced ? 0 : errno;
  ::close(fd_);
  fd_ = -1;
  if (mode_ != Mode::Atomic) return;
  const std::string tmp = file_name(path_, mode_);
  if (!synced || std::rename(tmp.c_str(), path_.c_str()) != 0) {
    error_ = "timing records \"" + path_ + "\": cannot complete: " + std::strerror(synced ? errno : err);
    ::unlink(tmp.c_str());
    throw std::runtime_error(error_);
  }
}

}  // namespace fovea::xrcommon

#include "harness.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <unistd.h>

#include "fovea/core/error.hpp"

namespace fovea::fuzz {

namespace {

struct Scratch {
  std::filesystem::path dir;
  Scratch() {
    const char* tmp = std::getenv("TMPDIR");
    std::string tmpl = std::string(tmp && *tmp ? tmp : "/tmp") + "/fovea-fuzz-XXXXXX";
    if (!::mkdtemp(tmpl.data())) throw std::runtime_error("fuzz: cannot create a scratch directory in " + tmpl);
    dir = tmpl;
  }
  ~Scratch() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};

Scratch& scratch() {
  static Scratch s;
  return s;
}

}  // namespace

std::string scratch_dir() { return scratch().dir.string(); }

std::string scratch_file(const std::string& name, std::string_view bytes) {
  const auto path = scratch().dir / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("fuzz: cannot write " + path.string());
  return path.string();
}

std::string_view as_text(std::span<const std::uint8_t> data) {
  return {reinterpret_cast<const char*>(data.data()), data.size()};
}

std::pair<std::string_view, std::string_view> split(std::string_view text, std::string_view marker) {
  const auto at = text.find(marker);
  if (at == std::string_view::npos) return {text, {}};
  return {text.substr(0, at), text.substr(at + marker.size())};
}

void run_guarded(Target fn, std::span<const std::uint8_t> data) {
  try {
    fn(data);
  } catch (const core::InputError&) {
    // The documented rejection: a message naming the input, exit 2 through the CLI.
  }
}

}  // namespace fovea::fuzz

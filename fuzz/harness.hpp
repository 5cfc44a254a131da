#pragma once
// One harness per parser that takes outside input. Each file defines its entry point with
// FOVEA_FUZZ_TARGET(name): under libFuzzer (FOVEA_LIBFUZZER) it becomes
// LLVMFuzzerTestOneInput of its own executable; otherwise it registers in the table the
// plain-test driver (replay_main.cpp) uses to replay corpus and regression files through
// the same code. A harness lets core::InputError pass (the documented rejection) and
// nothing else: any other exception, crash, sanitizer report or hang is a finding.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>

namespace fovea::fuzz {

using Target = void (*)(std::span<const std::uint8_t>);
bool register_target(const char* name, Target fn);
void run_guarded(Target fn, std::span<const std::uint8_t> data);

// Writes `bytes` to `name` inside this process's scratch directory (created on first use
// under $TMPDIR, removed at exit) and returns the path.
std::string scratch_file(const std::string& name, std::string_view bytes);
std::string scratch_dir();

std::string_view as_text(std::span<const std::uint8_t> data);
// The input cut at the first `marker` (e.g. a CSV and its sidecar): {before, after}; the
// second part is empty when the marker is absent.
std::pair<std::string_view, std::string_view> split(std::string_view text, std::string_view marker);

}  // namespace fovea::fuzz

#ifdef FOVEA_LIBFUZZER
#define FOVEA_FUZZ_TARGET(name)                                                            \
  static void fuzz_##name(std::span<const std::uint8_t>);                                  \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {      \
    fovea::fuzz::run_guarded(&fuzz_##name, {data, size});                                  \
    return 0;                                                                              \
  }                                                                                        \
  static void fuzz_##name(std::span<const std::uint8_t> data)
#else
#define FOVEA_FUZZ_TARGET(name)                                                            \
  static void fuzz_##name(std::span<const std::uint8_t>);                                  \
  [[maybe_unused]] static const bool registered_##name =                                   \
      fovea::fuzz::register_target(#name, &fuzz_##name);                                   \
  static void fuzz_##name(std::span<const std::uint8_t> data)
#endif

// Replays files through the harnesses' entry points as a plain program (no libFuzzer):
//   fovea_fuzz_replay TARGET PATH...   (files, or directories walked recursively)
// CTest runs it over every target's seed corpus and regression inputs in each build
// configuration, so a fixed finding stays fixed under ASan/UBSan and in Release.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "harness.hpp"

namespace fovea::fuzz {
namespace {
std::map<std::string, Target>& targets() {
  static std::map<std::string, Target> t;
  return t;
}
}  // namespace

bool register_target(const char* name, Target fn) {
  targets()[name] = fn;
  return true;
}

}  // namespace fovea::fuzz

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  const auto& all = fovea::fuzz::targets();
  if (argc < 2 || !all.count(argv[1])) {
    std::fprintf(stderr, "usage: %s TARGET PATH...\ntargets:", argv[0]);
    for (const auto& [name, fn] : all) std::fprintf(stderr, " %s", name.c_str());
    std::fprintf(stderr, "\n");
    return 2;
  }
  const auto fn = all.at(argv[1]);
  std::vector<fs::path> files;
  for (int i = 2; i < argc; ++i) {
    if (fs::is_directory(argv[i])) {
      for (const auto& e : fs::recursive_directory_iterator(argv[i]))
        if (e.is_regular_file()) files.push_back(e.path());
    } else if (fs::is_regular_file(argv[i])) {
      files.push_back(argv[i]);
    } else if (fs::exists(argv[i])) {
      std::fprintf(stderr, "%s: not a file or directory\n", argv[i]);
      return 2;
    }
  }
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::fprintf(stderr, "%s\n", f.c_str());  // the last name printed is the culprit of a crash
    fovea::fuzz::run_guarded(fn, bytes);
  }
  std::printf("%s: %zu inputs replayed\n", argv[1], files.size());
  return 0;
}

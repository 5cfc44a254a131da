// fovea: foveated path tracing for VR, from the command line.
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <new>
#include <set>

#include "command.hpp"
#include "fovea/core/error.hpp"

namespace fovea::tools {

std::map<std::string, Command>& commands() {
  static std::map<std::string, Command> m;
  return m;
}

Args::Args(const std::vector<std::string>& argv, const std::vector<std::string>& valued,
           const std::vector<std::string>& flags, int max_positional) {
  const std::set<std::string> v(valued.begin(), valued.end()), f(flags.begin(), flags.end());
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a.size() > 2 && a.rfind("--", 0) == 0) {
      std::string key = a.substr(2), value;
      const auto eq = key.find('=');
      const bool inline_value = eq != std::string::npos;
      if (inline_value) {
        value = key.substr(eq + 1);
        key = key.substr(0, eq);
      }
      if (v.count(key)) {
        if (!inline_value) {
          if (i + 1 >= argv.size()) throw core::InputError("option --" + key + " needs a value");
          value = argv[++i];
        }
        values_[key] = value;
      } else if (f.count(key) && !inline_value) {
        values_[key] = "1";
      } else {
        throw core::InputError("unknown option " + a + " (see --help)");
      }
    } else {
      if (static_cast<int>(positional_.size()) >= max_positional)
        throw core::InputError("unexpected argument \"" + a + "\" (see --help)");
      positional_.push_back(a);
    }
  }
}

std::string Args::str(const std::string& key, const std::string& fallback) const {
  auto it = values_.find(key);
  return it == values_.end() ? fallback : it->second;
}

std::optional<std::string> Args::opt(const std::string& key) const {
  auto it = values_.find(key);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

double Args::num(const std::string& key, double fallback) const {
  auto it = values_.find(key);
  if (it == values_.end()) return fallback;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(it->second.c_str(), &end);
  if (it->second.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    throw core::InputError("option --" + key + ": expected a finite number, got \"" + it->second + "\"");
  return v;
}

long Args::integer(const std::string& key, long fallback) const {
  auto it = values_.find(key);
  if (it == values_.end()) return fallback;
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(it->second.c_str(), &end, 10);
  if (it->second.empty() || *end != '\0' || errno == ERANGE)
    throw core::InputError("option --" + key + ": expected an integer, got \"" + it->second + "\"");
  return v;
}

bool stdout_is_tty() { return ::isatty(1) == 1; }
bool stderr_is_tty() { return ::isatty(2) == 1; }

namespace {
void usage(std::ostream& os) {
  os << "usage: fovea <command> [options]   (fovea <command> --help for its options)\n\ncommands:\n";
  for (const auto& [name, c] : commands()) os << "  " << name << std::string(12 - std::min<size_t>(name.size(), 11), ' ') << c.summary << "\n";
}
}  // namespace

}  // namespace fovea::tools

namespace {

// The Vulkan driver, as ./x chooses it (docs/building.md, "The Vulkan driver"): one the
// user selected wins; else FOVEA_VK_DRIVER=system is the system's lavapipe, =loader the
// loader's own search, and the default the Mesa 25 lavapipe ./x installs into the source
// tree, where it is (without it the loader's search, which prefers a GPU).
void select_vulkan_driver() {
  const char* env = std::getenv("FOVEA_VK_DRIVER");
  const std::string choice = env && *env ? env : "embedded";
  if (choice != "embedded" && choice != "system" && choice != "loader")
    throw fovea::core::InputError("FOVEA_VK_DRIVER: expected embedded, system or loader, got \"" + choice + "\"");
  if (std::getenv("VK_ICD_FILENAMES") || std::getenv("VK_DRIVER_FILES")) return;
  if (choice == "system") setenv("VK_ICD_FILENAMES", FOVEA_SYSTEM_VK_ICD, 1);
  if (choice == "embedded" && std::filesystem::exists(FOVEA_EMBEDDED_VK_ICD))
    setenv("VK_ICD_FILENAMES", FOVEA_EMBEDDED_VK_ICD, 1);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace fovea::tools;
  if (argc < 2) {
    usage(std::cerr);
    return 2;
  }
  const std::string name = argv[1];
  if (name == "--help" || name == "-h" || name == "help") {
    usage(std::cout);
    return 0;
  }
  auto it = commands().find(name);
  if (it == commands().end()) {
    std::cerr << "fovea: unknown command \"" << name << "\"\n";
    usage(std::cerr);
    return 2;
  }
  try {
    select_vulkan_driver();
    return it->second.run(std::vector<std::string>(argv + 2, argv + argc));
  } catch (const fovea::core::InputError& e) {
    std::cerr << "fovea " << name << ": " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    // Sizes come from the input (rasters, scenes, recordings) and are bounded where they are
    // read; what still does not fit this machine is the input's size, not a fault.
    std::cerr << "fovea " << name << ": out of host memory: the input needs more memory than this machine has "
              << "(std::bad_alloc); a smaller display raster, scene or recording fits\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "fovea " << name << ": error: " << e.what() << "\n";
    return 1;
  }
}

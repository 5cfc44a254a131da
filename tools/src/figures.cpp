#include "figures.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string_view>
#include <vector>

extern char** environ;

namespace fovea::plots {
std::span<const std::uint8_t> find(std::string_view name);  // the embedded tools/plots/*.py
}

namespace fovea::tools {
namespace {

std::string script(const std::string& name) {
  const auto b = plots::find(name);
  return {reinterpret_cast<const char*>(b.data()), b.size()};
}

// Loads the shared module from argv[1] as `fovea_plot`, then runs the family script in
// argv[2] as __main__ with argv[3:] as its arguments: the scripts run from the binary, as
// they run from tools/plots/ (`python3 tools/plots/charts.py DATA`).
constexpr const char* kBoot =
    "import sys, types\n"
    "m = types.ModuleType('fovea_plot')\n"
    "exec(compile(sys.argv[1], 'fovea_plot.py', 'exec'), m.__dict__)\n"
    "sys.modules['fovea_plot'] = m\n"
    "src, name = sys.argv[2], sys.argv[3]\n"
    "sys.argv = [name] + sys.argv[4:]\n"
    "exec(compile(src, name, 'exec'), {'__name__': '__main__'})\n";

constexpr int kNoMatplotlib = 3;  // fovea_plot.py's exit status when matplotlib is missing

}  // namespace

std::string python_interpreter() {
  if (const char* p = std::getenv("FOVEA_PYTHON"); p && *p) return p;
  // The system's Python, which python3-matplotlib installs for, before one that PATH may
  // put first (a pyenv or virtualenv without matplotlib).
  if (access("/usr/bin/python3", X_OK) == 0) return "/usr/bin/python3";
  return "python3";
}

bool draw_figures(const std::string& family, const std::string& data_path, std::ostream& log) {
  const std::string name = family + ".py";
  const std::string python = python_interpreter();
  const std::string common = script("fovea_plot.py"), body = script(name);
  std::string why;
  if (body.empty()) {
    why = "no embedded script " + name;
  } else {
    std::vector<std::string> args = {python, "-c", kBoot, common, body, name, data_path};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    // The script's stdout goes to stderr: a command's stdout is its JSON.
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, STDERR_FILENO, STDOUT_FILENO);
    pid_t pid = 0;
    const int err = posix_spawnp(&pid, python.c_str(), &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    int status = 0;
    if (err != 0) {
      why = python + " cannot be run (" + std::strerror(err) + ")";
    } else {
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return true;
      if (WIFEXITED(status) && WEXITSTATUS(status) == 127) why = python + " cannot be run (not found)";
      else if (WIFEXITED(status) && WEXITSTATUS(status) == kNoMatplotlib) why = "matplotlib is missing for " + python;
      else if (WIFEXITED(status)) why = "it exited with status " + std::to_string(WEXITSTATUS(status));
      else why = "it was killed by signal " + std::to_string(WTERMSIG(status));
    }
  }
  log << "warning: figures not drawn by tools/plots/" << name << ": " << why << ".\n"
      << "note: the data is in " << data_path << "; with python3-matplotlib installed (FOVEA_PYTHON names another\n"
      << "  interpreter) draw the figures with: fovea plot " << data_path << "\n";
  return false;
}

}  // namespace fovea::tools

#include "xr_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace fovea::test {

ProcessResult run_process(const std::vector<std::string>& argv, const std::map<std::string, std::string>& env,
                          int timeout_s) {
  ProcessResult res;
  int in_pipe[2], out_pipe[2];
  if (pipe(in_pipe) != 0 || pipe(out_pipe) != 0) throw std::runtime_error("pipe failed");
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    dup2(in_pipe[0], 0);
    dup2(out_pipe[1], 1);
    dup2(out_pipe[1], 2);
    close(in_pipe[0]);
    close(in_pipe[1]);
    close(out_pipe[0]);
    close(out_pipe[1]);
    for (const auto& [k, v] : env) {
      if (v.empty())
        unsetenv(k.c_str());
      else
        setenv(k.c_str(), v.c_str(), 1);
    }
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  close(in_pipe[0]);
  close(out_pipe[1]);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(timeout_s);
  char buf[4096];
  for (;;) {
    pollfd p{out_pipe[0], POLLIN, 0};
    const int ms = int(std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count());
    if (ms <= 0) {
      res.timed_out = true;
      kill(pid, SIGKILL);
      break;
    }
    if (poll(&p, 1, ms) > 0) {
      const ssize_t n = read(out_pipe[0], buf, sizeof buf);
      if (n <= 0) break;  // the child (and any grandchild holding the pipe) is gone
      res.output.append(buf, size_t(n));
    }
  }
  close(out_pipe[0]);
  close(in_pipe[1]);
  int status = 0;
  waitpid(pid, &status, 0);
  res.exit_code = (!res.timed_out && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
  return res;
}

TempDir::TempDir(const std::string& tag) {
  std::string tmpl = (std::filesystem::temp_directory_path() / ("fovea_" + tag + "_XXXXXX")).string();
  if (!mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
  path_ = tmpl;
}

TempDir::~TempDir() {
  std::error_code ec;
  if (!keep_) std::filesystem::remove_all(path_, ec);
}

std::map<std::string, std::string> runtime_env(const std::string& out, int exit_after_frames, int png_every) {
  std::map<std::string, std::string> env{
      {"XR_RUNTIME_JSON", FOVEA_RUNTIME_MANIFEST},
      {"FOVEA_EXIT_AFTER_FRAMES", std::to_string(exit_after_frames)},
      {"FOVEA_RUNTIME_OUT", out},
      {"FOVEA_RUNTIME_PNG_EVERY", std::to_string(png_every)},
      {"FOVEA_DISPLAY", "small"},
      // Lockstep pacing: these runs are compared with each other frame by frame, so the
      // content must be a function of the frame index (realtime pacing is tested in-process).
      {"FOVEA_RUNTIME_PACING", "lockstep"},
      {"XR_ENABLE_API_LAYERS", ""},
      {"LD_PRELOAD", FOVEA_TEST_PRELOAD},
  };
  if (!std::getenv("VK_ICD_FILENAMES")) env["VK_ICD_FILENAMES"] = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json";
  return env;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace fovea::test

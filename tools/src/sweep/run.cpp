#include "sweep/run.hpp"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <thread>

#include "fovea/core/error.hpp"
#include "fovea/core/image.hpp"

namespace fovea::sweep {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

struct Task {
  std::string id;
  bool is_job = false;
  std::vector<std::vector<std::string>> commands;
  std::string out;  // relative to the results directory
  json record;      // what task.json / failed/<id>.json describe the task with
  std::vector<std::string> needs;
};

struct Running {
  std::size_t task = 0;
  std::size_t command = 0;
  pid_t pid = -1;
  fs::path tmp;
  Clock::time_point start;
};

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "host";
  return buf;
}

std::string fmt_duration(double s) {
  char buf[32];
  const long t = std::lround(std::max(0.0, s));
  if (t >= 3600) std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, t / 60 % 60);
  else std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  return buf;
}

std::string tail_of(const fs::path& file, std::size_t max_bytes) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return {};
  in.seekg(0, std::ios::end);
  const auto size = static_cast<std::size_t>(in.tellg());
  const std::size_t n = std::min(size, max_bytes);
  std::string s(n, '\0');
  in.seekg(static_cast<std::streamoff>(size - n));
  in.read(s.data(), static_cast<std::streamsize>(n));
  return s;
}

// Removes what killed runs left of this task: every temporary directory of a job (a job
// belongs to one shard, so nobody else writes it), and for shared inputs, which several
// shards may compute at once, only those of dead processes on this host.
void remove_stale(const fs::path& dir, const Task& t, const std::string& host) {
  const fs::path final_dir = dir / t.out;
  const std::string prefix = final_dir.filename().string() + ".tmp.";
  std::error_code ec;
  if (!fs::is_directory(final_dir.parent_path(), ec)) return;
  for (const auto& e : fs::directory_iterator(final_dir.parent_path(), ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    bool stale = t.is_job;
    const std::string rest = name.substr(prefix.size());  // <host>.<pid>
    const auto dot = rest.rfind('.');
    if (!stale && dot != std::string::npos && rest.substr(0, dot) == host) {
      const pid_t pid = pid_t(std::atol(rest.c_str() + dot + 1));
      stale = pid > 0 && ::kill(pid, 0) != 0 && errno == ESRCH;
    }
    if (stale) fs::remove_all(e.path(), ec);
  }
}

class Pool {
 public:
  Pool(std::vector<Task> tasks, const RunOptions& o) : tasks_(std::move(tasks)), o_(o), dir_(fs::absolute(o.dir)) {}

  RunSummary run() {
    RunSummary sum;
    host_ = host_name();
    for (const auto& t : tasks_) sum.jobs += t.is_job;
    std::vector<std::size_t> pending;
    for (std::size_t i = 0; i < tasks_.size(); ++i) {
      if (fs::exists(dir_ / tasks_[i].out)) {
        done_.insert(tasks_[i].id);
        if (tasks_[i].is_job) ++sum.skipped;
        ++finished_before_;
      } else {
        pending.push_back(i);
      }
    }
    total_ = tasks_.size();
    struct sigaction sa {}, old_int{}, old_term{};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    g_stop = 0;
    ::sigaction(SIGINT, &sa, &old_int);
    ::sigaction(SIGTERM, &sa, &old_term);
    start_ = Clock::now();
    auto last_bar = Clock::now() - std::chrono::seconds(1);
    while ((!pending.empty() || !running_.empty()) && !g_stop) {
      // Start what is ready, in plan order (shared inputs come first).
      for (auto it = pending.begin(); it != pending.end() && int(running_.size()) < o_.jobs;) {
        const Task& t = tasks_[*it];
        std::string missing;
        bool wait = false;
        for (const auto& n : t.needs) {
          if (failed_.count(n)) missing = n;
          else if (!done_.count(n)) wait = true;
        }
        if (!missing.empty()) {
          record_failure(*it, -1, "shared input " + missing + " failed", 0);
          sum.failed += t.is_job;
          it = pending.erase(it);
        } else if (wait) {
          ++it;
        } else {
          start_task(*it);
          it = pending.erase(it);
        }
      }
      // Shared inputs come first in plan order, so a blocked task with nothing running is a bug.
      if (running_.empty() && !pending.empty() && !g_stop)
        throw std::runtime_error("sweep run: tasks wait on shared inputs that are not in the plan");
      int status = 0;
      const pid_t pid = ::waitpid(-1, &status, WNOHANG);
      if (pid > 0) {
        finish_command(pid, status, sum);
        continue;
      }
      if (o_.progress && Clock::now() - last_bar > std::chrono::milliseconds(250)) {
        draw_bar();
        last_bar = Clock::now();
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    if (g_stop) {
      sum.interrupted = true;
      for (auto& r : running_) ::kill(-r.pid, SIGTERM);
      for (auto& r : running_) {
        int st = 0;
        ::waitpid(r.pid, &st, 0);
        std::error_code ec;
        fs::remove_all(r.tmp, ec);
      }
      running_.clear();
    }
    if (o_.progress) {
      draw_bar();
      std::fprintf(stderr, "\n");
    }
    ::sigaction(SIGINT, &old_int, nullptr);
    ::sigaction(SIGTERM, &old_term, nullptr);
    return sum;
  }

 private:
  void start_task(std::size_t i) {
    const Task& t = tasks_[i];
    remove_stale(dir_, t, host_);
    Running r;
    r.task = i;
    r.tmp = dir_ / (t.out + ".tmp." + host_ + "." + std::to_string(::getpid()));
    fs::remove_all(r.tmp);
    fs::create_directories(r.tmp);
    r.start = Clock::now();
    r.pid = spawn(t, 0, r.tmp);
    running_.push_back(r);
  }

  // argv[0] "fovea" is this program; arguments naming the task's output (out or out/...)
  // are redirected into the temporary directory, those naming a shared input it needs
  // (shared/<id> or below) into the results directory.
  pid_t spawn(const Task& t, std::size_t command, const fs::path& tmp) {
    std::vector<std::string> args = t.commands[command];
    const std::string& out = t.out;
    const auto under = [](const std::string& a, const std::string& dir) { return a == dir || a.rfind(dir + "/", 0) == 0; };
    if (!args.empty() && args[0] == "fovea") args[0] = o_.fovea_exe;
    for (std::size_t k = 1; k < args.size(); ++k) {
      if (under(args[k], out)) args[k] = tmp.string() + args[k].substr(out.size());
      for (const std::string& id : t.needs)
        if (under(args[k], "shared/" + id)) args[k] = (dir_ / args[k]).string();
    }
    std::vector<char*> cargv;
    for (auto& a : args) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    const std::string out_file = (tmp / "stdout.txt").string(), err_file = (tmp / "stderr.txt").string();
    const pid_t parent = ::getpid();
    const pid_t pid = ::fork();
    if (pid < 0) throw std::runtime_error(std::string("sweep run: fork failed: ") + std::strerror(errno));
    if (pid == 0) {
      // A killed pool takes its renders with it: nothing finishes behind its back.
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent) ::_exit(127);
      ::setpgid(0, 0);  // its own group, so stopping the task reaches everything it started
      ::signal(SIGINT, SIG_DFL);
      ::signal(SIGTERM, SIG_DFL);
      const int fo = ::open(out_file.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      const int fe = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      if (fo >= 0) ::dup2(fo, 1);
      if (fe >= 0) ::dup2(fe, 2);
      ::execvp(cargv[0], cargv.data());
      std::fprintf(stderr, "cannot execute %s: %s\n", cargv[0], std::strerror(errno));
      ::_exit(127);
    }
    ::setpgid(pid, pid);  // also here: no window in which a stop misses the group
    return pid;
  }

  void finish_command(pid_t pid, int status, RunSummary& sum) {
    const auto it = std::find_if(running_.begin(), running_.end(), [&](const Running& r) { return r.pid == pid; });
    if (it == running_.end()) return;
    Running r = *it;
    const Task& t = tasks_[r.task];
    const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
    if (ok && r.command + 1 < t.commands.size()) {
      it->command = r.command + 1;
      it->pid = spawn(t, it->command, r.tmp);
      return;
    }
    running_.erase(it);
    const double seconds = std::chrono::duration<double>(Clock::now() - r.start).count();
    ++finished_now_;
    std::error_code ec;
    if (!ok) {
      const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      record_failure(r.task, code, tail_of(r.tmp / "stderr.txt", 2000), seconds);
      fs::remove_all(r.tmp, ec);
      sum.failed += t.is_job;
      return;
    }
    json rec = t.record;
    rec["exit_code"] = 0;
    rec["seconds"] = seconds;
    rec["host"] = host_;
    core::write_file_atomic((r.tmp / "task.json").string(), rec.dump(2) + "\n");
    const fs::path final_dir = dir_ / t.out;
    if (::rename(r.tmp.c_str(), final_dir.c_str()) != 0) {
      // Another shard finished the same shared input first: keep its copy.
      if (!t.is_job && fs::exists(final_dir)) fs::remove_all(r.tmp, ec);
      else throw std::runtime_error("sweep run: cannot rename " + r.tmp.string() + ": " + std::strerror(errno));
    }
    fs::remove(dir_ / "failed" / (t.id + ".json"), ec);
    done_.insert(t.id);
    sum.ran += t.is_job;
  }

  void record_failure(std::size_t i, int code, const std::string& tail, double seconds) {
    const Task& t = tasks_[i];
    failed_.insert(t.id);
    json rec = t.record;
    rec["exit_code"] = code;
    rec["stderr_tail"] = tail;
    rec["seconds"] = seconds;
    rec["host"] = host_;
    fs::create_directories(dir_ / "failed");
    core::write_file_atomic((dir_ / "failed" / (t.id + ".json")).string(), rec.dump(2) + "\n");
    if (!o_.progress) return;
    std::fprintf(stderr, "\rfailed: %s %s (exit %d)\n", t.is_job ? "job" : "shared input", t.id.c_str(), code);
  }

  void draw_bar() {
    const std::size_t finished = finished_before_ + finished_now_;
    const int width = 30, fill = int(double(width) * double(finished) / double(std::max<std::size_t>(total_, 1)));
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    const std::size_t left = total_ - finished;
    const std::string eta = finished_now_ ? fmt_duration(elapsed / double(finished_now_) * double(left)) : "?";
    std::fprintf(stderr, "\r[%s%s] %zu/%zu tasks, %zu failed, %zu running, %s elapsed, ETA %s   ",
                 std::string(std::size_t(fill), '#').c_str(), std::string(std::size_t(width - fill), ' ').c_str(), finished,
                 total_, failed_.size(), running_.size(), fmt_duration(elapsed).c_str(), eta.c_str());
    std::fflush(stderr);
  }

  std::vector<Task> tasks_;
  RunOptions o_;
  fs::path dir_;
  std::string host_;
  std::vector<Running> running_;
  std::set<std::string> done_, failed_;
  std::size_t total_ = 0, finished_before_ = 0, finished_now_ = 0;
  Clock::time_point start_;
};

}  // namespace

int default_pool_size() {
  cpu_set_t set;
  CPU_ZERO(&set);
  int cpus = ::sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : 0;
  if (cpus < 1) cpus = int(std::max(1u, std::thread::hardware_concurrency()));
  int lp = cpus;
  if (const char* v = std::getenv("LP_NUM_THREADS")) {
    const int n = std::atoi(v);
    if (n > 0) lp = n;
  }
  return std::max(1, cpus / lp);
}

RunSummary run_plan(const Plan& plan, const RunOptions& o) {
  if (o.jobs < 1) throw core::InputError("--jobs must be >= 1");
  std::vector<Task> tasks;
  std::vector<Task> jobs;
  std::set<std::string> needed;
  for (std::size_t i : shard_jobs(plan.jobs.size(), o.shard_index, o.shard_count)) {
    const Job& j = plan.jobs[i];
    Task t;
    t.id = j.id;
    t.is_job = true;
    t.commands = {j.argv};
    t.out = j.out;
    t.needs = j.shared;
    t.record = {{"type", "job"}, {"id", j.id}, {"settings", j.settings}, {"argv", j.argv}};
    needed.insert(j.shared.begin(), j.shared.end());
    jobs.push_back(std::move(t));
  }
  for (const auto& s : plan.shared)
    if (needed.count(s.id))
      tasks.push_back(Task{s.id, false, s.commands, s.out, {{"type", "shared"}, {"id", s.id}, {"settings", s.settings}}, {}});
  tasks.insert(tasks.end(), jobs.begin(), jobs.end());
  fs::create_directories(fs::path(o.dir) / "jobs");
  if (!plan.shared.empty()) fs::create_directories(fs::path(o.dir) / "shared");
  return Pool(std::move(tasks), o).run();
}

}  // namespace fovea::sweep

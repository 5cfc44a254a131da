// fovea sweep run: a killed pool resumes with only the unfinished jobs, shards cover every
// job exactly once, failures are recorded with exit code and stderr. The jobs are small
// shell commands standing in for renders (the runner only runs argv).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "cli.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/json.hpp"
#include "sweep/plan.hpp"

namespace fovea::sweep {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A job that logs its start to `log`, sleeps, then writes a render-like report into its --out.
Job shell_job(int n, const std::string& log, double sleep_s, int exit_code = 0) {
  Job j;
  j.settings = {{"n", n}};
  j.id = settings_id(j.settings);
  j.out = "jobs/" + j.id;
  std::ostringstream script;
  script << "echo " << j.id << " >> '" << log << "'; sleep " << sleep_s << "; mkdir -p \"$2\"; ";
  if (exit_code) script << "echo boom-" << n << " >&2; exit " << exit_code;
  else script << "echo '{\"frames\": 1, \"gpu_ms\": {\"total\": " << n << "}, \"summary\": {}}' > \"$2/report.json\"";
  j.argv = {"/bin/sh", "-c", script.str(), "job", "--out", j.out};
  return j;
}

std::string write_plan(const std::string& dir, const std::vector<Job>& jobs) {
  Plan p;
  p.header = {{"type", "sweep"}, {"version", 1}, {"source", "test"}, {"report", json::object()}};
  p.jobs = jobs;
  const std::string path = dir + "/plan.jsonl";
  core::write_file_atomic(path, plan_to_jsonl(p));
  return path;
}

std::multiset<std::string> lines(const std::string& path) {
  std::multiset<std::string> out;
  std::ifstream in(path);
  for (std::string l; std::getline(in, l);)
    if (!l.empty()) out.insert(l);
  return out;
}

std::set<std::string> finished(const std::string& dir) {
  std::set<std::string> out;
  if (!fs::exists(dir + "/jobs")) return out;
  for (const auto& e : fs::directory_iterator(dir + "/jobs"))
    if (e.path().filename().string().find(".tmp.") == std::string::npos) out.insert(e.path().filename().string());
  return out;
}

TEST(SweepRun, KilledRunResumesWithOnlyTheUnfinishedJobs) {
  const std::string dir = test::temp_dir("sweep-resume"), log = dir + "/started.log";
  std::vector<Job> jobs;
  std::set<std::string> all;
  for (int n = 0; n < 8; ++n) {
    jobs.push_back(shell_job(n, log, 0.4));
    all.insert(jobs.back().id);
  }
  const std::string plan = write_plan(dir, jobs);

  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::freopen("/dev/null", "w", stdout);
    ::execl(FOVEA_EXE, FOVEA_EXE, "sweep", "run", plan.c_str(), "--jobs", "2", "--dir", dir.c_str(), "--quiet", nullptr);
    ::_exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (finished(dir).size() < 3 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ::kill(pid, SIGKILL);  // no chance to clean up: the worst case
  int st = 0;
  ::waitpid(pid, &st, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(800));  // longer than a job: orphans would finish now
  const std::set<std::string> before = finished(dir);
  ASSERT_GE(before.size(), 3u);
  ASSERT_LT(before.size(), all.size()) << "the run finished before it was killed";
  const auto started_first = lines(log);
  EXPECT_GE(started_first.size(), before.size());  // usually more: the jobs in flight when it died
  fs::rename(log, dir + "/first.log");

  const auto r = test::run_fovea("sweep run " + plan + " --jobs 2 --dir " + dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const json s = fovea::core::parse_json(r.out);
  EXPECT_EQ(s["skipped"], before.size());
  EXPECT_EQ(s["ran"], all.size() - before.size());
  // Exactly the unfinished jobs ran, each once; the in-flight ones were redone.
  std::multiset<std::string> expected;
  for (const auto& id : all)
    if (!before.count(id)) expected.insert(id);
  EXPECT_EQ(lines(log), expected);
  EXPECT_EQ(finished(dir), all);
  for (const auto& e : fs::directory_iterator(dir + "/jobs")) {
    EXPECT_EQ(e.path().filename().string().find(".tmp."), std::string::npos) << "left over: " << e.path();
    EXPECT_TRUE(fs::exists(e.path() / "report.json"));
    EXPECT_TRUE(fs::exists(e.path() / "task.json"));
  }
  // A third run has nothing to do.
  const auto again = test::run_fovea("sweep run " + plan + " --dir " + dir);
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(fovea::core::parse_json(again.out)["ran"], 0);
  fs::remove_all(dir);
}

TEST(SweepRun, ShardsRunEveryJobExactlyOnce) {
  const std::string dir = test::temp_dir("sweep-shard"), log = dir + "/started.log";
  std::vector<Job> jobs;
  std::multiset<std::string> all;
  for (int n = 0; n < 11; ++n) {
    jobs.push_back(shell_job(n, log, 0));
    all.insert(jobs.back().id);
  }
  const std::string plan = write_plan(dir, jobs);
  std::size_t total = 0;
  for (int i = 0; i < 3; ++i) {
    const std::string shard = std::to_string(i) + "/3";
    test::CliResult r;
    if (i == 1) {  // the Slurm array task's way of naming its shard
      ::setenv("SLURM_ARRAY_TASK_ID", "1", 1);
      ::setenv("SLURM_ARRAY_TASK_COUNT", "3", 1);
      r = test::run_fovea("sweep run " + plan + " --dir " + dir);
      ::unsetenv("SLURM_ARRAY_TASK_ID");
      ::unsetenv("SLURM_ARRAY_TASK_COUNT");
    } else {
      r = test::run_fovea("sweep run " + plan + " --shard " + shard + " --dir " + dir);
    }
    ASSERT_EQ(r.status, 0) << r.err;
    const json s = fovea::core::parse_json(r.out);
    EXPECT_EQ(s["shard"], shard);
    total += s["ran"].get<std::size_t>();
  }
  EXPECT_EQ(total, all.size());
  EXPECT_EQ(lines(log), all);
  EXPECT_EQ(test::run_fovea("sweep run " + plan + " --shard 3/3 --dir " + dir).status, 2);
  fs::remove_all(dir);
}

TEST(SweepRun, FailedJobsAreRecordedAndRetried) {
  const std::string dir = test::temp_dir("sweep-fail"), log = dir + "/started.log";
  const std::vector<Job> jobs = {shell_job(0, log, 0), shell_job(1, log, 0, 3), shell_job(2, log, 0)};
  const std::string plan = write_plan(dir, jobs);
  auto r = test::run_fovea("sweep run " + plan + " --jobs 2 --dir " + dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(fovea::core::parse_json(r.out)["failed"], 1);
  std::ifstream in(dir + "/failed/" + jobs[1].id + ".json");
  ASSERT_TRUE(in);
  const json f = fovea::core::parse_json(in);
  EXPECT_EQ(f["exit_code"], 3);
  EXPECT_NE(f["stderr_tail"].get<std::string>().find("boom-1"), std::string::npos);
  EXPECT_EQ(f["settings"]["n"], 1);
  EXPECT_FALSE(fs::exists(dir + "/" + jobs[1].out));
  // The next run skips the two good jobs and tries the failed one again.
  r = test::run_fovea("sweep run " + plan + " --dir " + dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(fovea::core::parse_json(r.out)["skipped"], 2);
  EXPECT_EQ(lines(log).count(jobs[1].id), 2u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace fovea::sweep

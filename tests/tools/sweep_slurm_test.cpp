// fovea sweep slurm: the generated scripts, and an end-to-end run on a real one-node Slurm
// (Debian's munged, slurmctld and slurmd started here, all state in a temporary directory)
// whose report must equal a local `fovea sweep run` of the same plan, timings excepted.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/json.hpp"
#include "sweep/slurm.hpp"

namespace fovea::sweep {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

TEST(SweepSlurm, ScriptsDescribeTheArrayAndTheMerge) {
  const std::string dir = test::temp_dir("sweep-slurm");
  SlurmOptions o;
  o.plan = dir + "/plan.jsonl";
  o.results_dir = dir;
  o.out_dir = dir + "/slurm";
  o.fovea_exe = "/opt/fovea";
  o.workdir = dir;
  o.shards = 4;
  o.cpus_per_task = 2;
  o.gpus = "1";
  o.partition = "gpu";
  o.time = "01:00:00";
  o.mem = "4G";
  const SlurmScripts s = write_slurm_scripts(o);
  const std::string array = test::read_text(s.array_script), merge = test::read_text(s.merge_script), submit = test::read_text(s.submit_script);
  for (const char* line : {"#SBATCH --array=0-3\n", "#SBATCH --cpus-per-task=2\n", "#SBATCH --gpus=1\n",
                           "#SBATCH --partition=gpu\n", "#SBATCH --time=01:00:00\n", "#SBATCH --mem=4G\n", "array_%A_%a.out"})
    EXPECT_NE(array.find(line), std::string::npos) << line << "\n" << array;
  EXPECT_NE(array.find("'/opt/fovea' sweep run '" + o.plan + "' --dir '" + dir + "'"), std::string::npos) << array;
  EXPECT_EQ(merge.find("--array"), std::string::npos);
  EXPECT_NE(merge.find("sweep report '" + o.plan + "'"), std::string::npos) << merge;
  EXPECT_NE(submit.find("--dependency=afterok:${id%%;*}"), std::string::npos) << submit;
  EXPECT_EQ(parse_parsable("1234\n"), "1234");
  EXPECT_EQ(parse_parsable("77;cluster\n"), "77");
  EXPECT_THROW(parse_parsable("Submitted batch job 5"), core::InputError);
  o.partition = "a\n#SBATCH --x";
  EXPECT_THROW(write_slurm_scripts(o), core::InputError);
  o.partition = "";
  o.shards = 0;
  EXPECT_THROW(write_slurm_scripts(o), core::InputError);
  fs::remove_all(dir);
}

#ifndef FOVEA_SANITIZED_BUILD
// The end-to-end run, Release only: under the sanitizers it adds the daemons' start-up and
// scheduling (20 s) to what SweepRun.* checks there of the same `fovea sweep run --shard`
// processes, shards named as an array task names them included.

// Metrics and bands of every job in a report's results.json, timings removed.
json numbers_without_timings(const fs::path& results) {
  json j = fovea::core::parse_json(test::read_text(results));
  json out = json::object();
  for (auto& row : j["jobs"]) {
    json m = json::object();
    for (auto it = row["metrics"].begin(); it != row["metrics"].end(); ++it)
      if (it.key().find("_ms") == std::string::npos && it.key().find("seconds") == std::string::npos) m[it.key()] = *it;
    out[row["id"].get<std::string>()] = {{"status", row["status"]}, {"metrics", m}, {"bands", row["bands"]}};
  }
  return out;
}

int free_port() {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  int port = 0;
  if (::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 && ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &len) == 0)
    port = ntohs(a.sin_port);
  ::close(s);
  return port;
}

std::string host_short() {
  char buf[256] = {};
  ::gethostname(buf, sizeof buf - 1);
  std::string h = buf;
  return h.substr(0, h.find('.'));
}

int sh(const std::string& cmd) {
  const int r = std::system(cmd.c_str());
  return WIFEXITED(r) ? WEXITSTATUS(r) : -1;
}

std::string sh_out(const std::string& cmd) {
  std::string out;
  if (FILE* p = ::popen(cmd.c_str(), "r")) {
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    ::pclose(p);
  }
  return out;
}

// munged, slurmctld and slurmd of one node, everything under `dir`; stopped by their pid
// files when this goes out of scope, whatever the test's outcome.
class OneNodeSlurm {
 public:
  explicit OneNodeSlurm(std::string dir) : dir_(std::move(dir)) {}
  ~OneNodeSlurm() { stop(); }

  // Empty on success, otherwise why the cluster could not start.
  std::string start() {
    if (::geteuid() != 0) return "not root: slurmd and munged need root for this one-node setup";
    for (const char* bin : {"/usr/sbin/munged", "/usr/sbin/slurmctld", "/usr/sbin/slurmd", "/usr/bin/sbatch", "/usr/bin/squeue"})
      if (!fs::exists(bin)) return std::string(bin) + " is missing (Debian packages munge, slurmctld, slurmd, slurm-client)";
    fs::create_directories(dir_ + "/state");
    fs::create_directories(dir_ + "/spool");
    {
      std::random_device rd;
      std::string key(1024, '\0');
      for (auto& c : key) c = char(rd() & 0xff);
      std::ofstream(dir_ + "/munge.key", std::ios::binary) << key;
      ::chmod((dir_ + "/munge.key").c_str(), 0400);
    }
    if (sh("/usr/sbin/munged --key-file=" + dir_ + "/munge.key --socket=" + dir_ + "/munge.sock --pid-file=" + dir_ +
           "/munged.pid --log-file=" + dir_ + "/munged.log --seed-file=" + dir_ + "/munge.seed --force") != 0)
      return "munged did not start: " + test::read_text(dir_ + "/munged.log");
    const std::string host = host_short();
    const int ctld_port = free_port(), d_port = free_port();
    std::ostringstream conf;
    conf << "ClusterName=fovea\nSlurmctldHost=" << host << "\nAuthType=auth/munge\nAuthInfo=socket=" << dir_
         << "/munge.sock\nCredType=cred/munge\nSlurmUser=root\nSlurmdUser=root\nStateSaveLocation=" << dir_
         << "/state\nSlurmdSpoolDir=" << dir_ << "/spool\nSlurmctldPidFile=" << dir_ << "/slurmctld.pid\nSlurmdPidFile="
         << dir_ << "/slurmd.pid\nSlurmctldLogFile=" << dir_ << "/slurmctld.log\nSlurmdLogFile=" << dir_
         << "/slurmd.log\nSlurmctldPort=" << ctld_port << "\nSlurmdPort=" << d_port
         << "\nProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\nReturnToService=2\nSelectType=select/cons_tres\n"
            "SelectTypeParameters=CR_Core\nMpiDefault=none\nNodeName="
         << host << " CPUs=" << std::thread::hardware_concurrency() << " State=UNKNOWN\nPartitionName=debug Nodes=" << host
         << " Default=YES MaxTime=INFINITE State=UP\n";
    std::ofstream(dir_ + "/slurm.conf") << conf.str();
    ::setenv("SLURM_CONF", (dir_ + "/slurm.conf").c_str(), 1);
    if (sh("/usr/sbin/slurmctld") != 0) return "slurmctld did not start: " + test::read_text(dir_ + "/slurmctld.log");
    if (sh("/usr/sbin/slurmd") != 0) return "slurmd did not start: " + test::read_text(dir_ + "/slurmd.log");
    for (int i = 0; i < 60; ++i) {  // ~5 s is usual
      if (sh_out("sinfo -h -o %t 2>/dev/null").find("idle") != std::string::npos) return "";
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
    return "the node did not become idle within 30 s: " + test::read_text(dir_ + "/slurmctld.log");
  }

  // All three told at once: each takes 1-2 s to exit, one after the other 5 s.
  void stop() {
    std::vector<pid_t> pids;
    for (const char* d : {"slurmd", "slurmctld", "munged"}) {
      const pid_t pid = pid_t(std::atol(test::read_text(dir_ + "/" + d + ".pid").c_str()));
      fs::remove(dir_ + "/" + d + ".pid");
      if (pid > 0 && ::kill(pid, SIGTERM) == 0) pids.push_back(pid);
    }
    const auto alive = [&] { return std::ranges::any_of(pids, [](pid_t p) { return ::kill(p, 0) == 0; }); };
    for (int i = 0; i < 50 && alive(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    for (const pid_t p : pids)
      if (::kill(p, 0) == 0) ::kill(p, SIGKILL);
    ::unsetenv("SLURM_CONF");
  }

 private:
  std::string dir_;
};

TEST(SweepSlurm, EndToEndOnARealOneNodeSlurmMatchesALocalRun) {
  const std::string dir = test::temp_dir("sweep-slurm-e2e");
  OneNodeSlurm cluster(dir + "/cluster");
  if (const std::string why = cluster.start(); !why.empty()) {
    cluster.stop();
    fs::remove_all(dir);
    GTEST_SKIP() << "Slurm could not start: " << why;
  }
  // Two tiny renders sharing one reference, as two array tasks.
  core::write_file_atomic(dir + "/sweep.json", R"({"scenes": "cornell", "displays": "tiny", "frames": 2, "gaze": "synthetic:3",
      "distribution": ["visual-polar", "cartesian"], "reference": 4})");
  fs::create_directories(dir + "/slurm-run");
  fs::create_directories(dir + "/local-run");
  for (const char* d : {"slurm-run", "local-run"}) {
    const auto p = test::run_fovea("sweep plan " + dir + "/sweep.json --out " + dir + "/" + d + "/plan.jsonl");
    ASSERT_EQ(p.status, 0) << p.err;
  }
  const auto sub = test::run_fovea("sweep slurm " + dir + "/slurm-run/plan.jsonl --shards 2 --cpus-per-task 1 --time 10 --submit");
  ASSERT_EQ(sub.status, 0) << sub.err;
  const json ids = fovea::core::parse_json(sub.out);
  const std::string array = ids["array_job"], merge = ids["merge_job"];

  // Meanwhile the same plan locally.
  const auto local = test::run_fovea("sweep run " + dir + "/local-run/plan.jsonl --jobs 1");
  ASSERT_EQ(local.status, 0) << local.err;
  ASSERT_EQ(test::run_fovea("sweep report " + dir + "/local-run/plan.jsonl --out " + dir + "/local-run/report").status, 0);

  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(10);
  std::string state;
  while (std::chrono::steady_clock::now() < deadline) {
    state = sh_out("scontrol -o show job " + merge + " 2>&1");
    if (state.find("JobState=COMPLETED") != std::string::npos || state.find("JobState=FAILED") != std::string::npos ||
        state.find("JobState=CANCELLED") != std::string::npos || state.find("DependencyNeverSatisfied") != std::string::npos)
      break;
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  ASSERT_NE(state.find("JobState=COMPLETED"), std::string::npos)
      << state << "\narray: " << sh_out("scontrol -o show job " + array + " 2>&1") << "\nlogs: "
      << sh_out("cat " + dir + "/slurm-run/slurm/logs/* 2>&1");
  // Both array tasks ran a shard; the merge wrote the report.
  const json a0 = fovea::core::parse_json(test::read_text(dir + "/slurm-run/slurm/logs/array_" + array + "_0.out"));
  const json a1 = fovea::core::parse_json(test::read_text(dir + "/slurm-run/slurm/logs/array_" + array + "_1.out"));
  EXPECT_EQ(a0["shard"], "0/2");
  EXPECT_EQ(a1["shard"], "1/2");
  EXPECT_EQ(a0["ran"].get<int>() + a1["ran"].get<int>(), 2);
  const json slurm_numbers = numbers_without_timings(dir + "/slurm-run/slurm/report/results.json");
  const json local_numbers = numbers_without_timings(dir + "/local-run/report/results.json");
  ASSERT_EQ(slurm_numbers.size(), 2u);
  for (const auto& [id, row] : slurm_numbers.items()) {
    EXPECT_EQ(row["status"], "done") << id;
    EXPECT_TRUE(row["metrics"].contains("fovea_psnr")) << id;
  }
  EXPECT_EQ(slurm_numbers, local_numbers);
  cluster.stop();
  fs::remove_all(dir);
}
#endif

}  // namespace
}  // namespace fovea::sweep

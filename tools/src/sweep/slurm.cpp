#include "sweep/slurm.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "fovea/core/error.hpp"
#include "fovea/core/image.hpp"

namespace fovea::sweep {
namespace {

namespace fs = std::filesystem;

// Single-quoted for the shell: ' becomes '\''.
std::string quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Values that end up on #SBATCH lines: one line, no shell or directive syntax.
void check_value(const std::string& option, const std::string& v) {
  for (char c : v)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || std::strchr(":_.,=/+-", c)))
      throw core::InputError("--" + option + ": unexpected character '" + std::string(1, c) + "' in \"" + v + "\"");
}

struct Captured {
  int status = -1;
  std::string out, err;
};

// fork/exec with stdout and stderr read through pipes (sbatch's output is small).
Captured capture(std::vector<std::string> argv) {
  int po[2], pe[2];
  if (::pipe(po) != 0 || ::pipe(pe) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  std::vector<char*> cargv;
  for (auto& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    ::dup2(po[1], 1);
    ::dup2(pe[1], 2);
    ::close(po[0]), ::close(pe[0]), ::close(po[1]), ::close(pe[1]);
    ::execvp(cargv[0], cargv.data());
    std::fprintf(stderr, "cannot execute %s: %s\n", cargv[0], std::strerror(errno));
    ::_exit(127);
  }
  ::close(po[1]), ::close(pe[1]);
  Captured c;
  char buf[4096];
  // stderr is drained after stdout; both stay far below the pipe buffer for sbatch.
  for (ssize_t n; (n = ::read(po[0], buf, sizeof buf)) > 0;) c.out.append(buf, std::size_t(n));
  for (ssize_t n; (n = ::read(pe[0], buf, sizeof buf)) > 0;) c.err.append(buf, std::size_t(n));
  ::close(po[0]), ::close(pe[0]);
  int st = 0;
  ::waitpid(pid, &st, 0);
  c.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return c;
}

std::string sbatch_submit(std::vector<std::string> argv) {
  const Captured c = capture(argv);
  if (c.status != 0) throw std::runtime_error("sbatch failed (exit " + std::to_string(c.status) + "): " + c.err);
  return parse_parsable(c.out);
}

}  // namespace

SlurmScripts write_slurm_scripts(const SlurmOptions& o) {
  if (o.shards < 1 || o.shards > 100000) throw core::InputError("--shards must be in 1..100000");
  if (o.cpus_per_task < 0 || o.cpus_per_task > 4096) throw core::InputError("--cpus-per-task must be in 1..4096");
  check_value("partition", o.partition), check_value("mem", o.mem), check_value("time", o.time),
      check_value("gpus", o.gpus);
  const fs::path out(o.out_dir);
  fs::create_directories(out / "logs");
  std::string common;
  if (!o.partition.empty()) common += "#SBATCH --partition=" + o.partition + "\n";
  if (!o.time.empty()) common += "#SBATCH --time=" + o.time + "\n";
  if (!o.mem.empty()) common += "#SBATCH --mem=" + o.mem + "\n";
  // #SBATCH lines cannot be quoted: paths with spaces would break them.
  for (const auto& p : {o.out_dir, o.workdir})
    if (p.find_first_of(" \t\n'\"") != std::string::npos)
      throw core::InputError("\"" + p + "\": Slurm directives cannot hold paths with spaces or quotes");
  common += "#SBATCH --chdir=" + o.workdir + "\n";

  std::string array = "#!/bin/bash\n# One array task per shard of the plan (fovea sweep slurm).\n";
  array += "#SBATCH --job-name=fovea-sweep\n";
  array += "#SBATCH --array=0-" + std::to_string(o.shards - 1) + "\n";
  array += "#SBATCH --output=" + (out / "logs" / "array_%A_%a.out").string() + "\n";
  array += "#SBATCH --error=" + (out / "logs" / "array_%A_%a.err").string() + "\n";
  if (o.cpus_per_task > 0) array += "#SBATCH --cpus-per-task=" + std::to_string(o.cpus_per_task) + "\n";
  if (!o.gpus.empty()) array += "#SBATCH --gpus=" + o.gpus + "\n";
  array += common;
  array += "set -eu\n";
  array += "# lavapipe renders with the task's CPUs unless told otherwise.\n";
  array += "export LP_NUM_THREADS=\"${LP_NUM_THREADS:-${SLURM_CPUS_PER_TASK:-1}}\"\n";
  array += "# The shard comes from SLURM_ARRAY_TASK_ID / SLURM_ARRAY_TASK_COUNT.\n";
  array += "exec " + quote(o.fovea_exe) + " sweep run " + quote(o.plan) + " --dir " + quote(o.results_dir) + "\n";

  std::string merge = "#!/bin/bash\n# Merges the array's results once every task succeeded (fovea sweep slurm).\n";
  merge += "#SBATCH --job-name=fovea-sweep-merge\n";
  merge += "#SBATCH --output=" + (out / "logs" / "merge_%j.out").string() + "\n";
  merge += "#SBATCH --error=" + (out / "logs" / "merge_%j.err").string() + "\n";
  merge += common;
  merge += "set -eu\n";
  merge += "exec " + quote(o.fovea_exe) + " sweep report " + quote(o.plan) + " --dir " + quote(o.results_dir) + " --out " +
           quote((out / "report").string()) + "\n";

  SlurmScripts s{(out / "sweep-array.sbatch").string(), (out / "sweep-merge.sbatch").string(),
                 (out / "submit.sh").string()};
  std::string submit = "#!/bin/sh\n# Submits the array, then the merge once all array tasks succeeded.\nset -eu\n";
  submit += "id=$(sbatch --parsable " + quote(s.array_script) + ")\n";
  submit += "merge=$(sbatch --parsable --dependency=afterok:${id%%;*} " + quote(s.merge_script) + ")\n";
  submit += "echo \"{\\\"array_job\\\": \\\"${id%%;*}\\\", \\\"merge_job\\\": \\\"${merge%%;*}\\\"}\"\n";
  core::write_file_atomic(s.array_script, array);
  core::write_file_atomic(s.merge_script, merge);
  core::write_file_atomic(s.submit_script, submit);
  fs::permissions(s.submit_script, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
  return s;
}

std::string parse_parsable(const std::string& text) {
  std::string id = text.substr(0, text.find_first_of(";\n"));
  if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw core::InputError("sbatch --parsable printed \"" + text + "\", not a job id");
  return id;
}

SubmittedJobs submit_slurm(const SlurmScripts& s) {
  SubmittedJobs j;
  j.array_id = sbatch_submit({"sbatch", "--parsable", s.array_script});
  j.merge_id = sbatch_submit({"sbatch", "--parsable", "--dependency=afterok:" + j.array_id, s.merge_script});
  return j;
}

}  // namespace fovea::sweep

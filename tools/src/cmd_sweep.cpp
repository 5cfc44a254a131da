// fovea sweep plan|run|slurm|report: speed/accuracy sweeps of `fovea render`, run by a
// local process pool or as Slurm job arrays, merged into CSV/JSON and Pareto plots.
#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/output_path.hpp"
#include "fovea/core/image.hpp"
#include "sweep/plan.hpp"
#include "sweep/report.hpp"
#include "sweep/run.hpp"
#include "sweep/slurm.hpp"

namespace fovea::tools::cmd_sweep {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kHelp = R"(usage: fovea sweep plan FILE --out PLAN
       fovea sweep run PLAN [--dir DIR] [--jobs N] [--shard I/N] [--quiet]
       fovea sweep slurm PLAN --shards N [--out DIR] [--dir DIR] [--partition P]
                         [--cpus-per-task C] [--mem M] [--time T] [--gpus G] [--submit]
       fovea sweep report PLAN --out DIR [--dir DIR] [--markdown PAGE [--command TEXT]]

plan    expands a sweep file (JSON: "scenes", "displays", "gaze", "frames", any `fovea render`
        option as a value, a list or {"from", "to", "step"}, and "report"; "command":
        "latency" makes the jobs `fovea latency` runs, keys its options; or a list of
        such objects, their union) into PLAN, one JSON
        line per job: id (FNV-1a 64 of its canonical settings), the command's argv, the
        shared inputs (references computed once per scene, display and spp).
run     runs the plan's jobs with a pool of N processes [CPUs / LP_NUM_THREADS]; finished jobs
        (DIR/jobs/<id>) are skipped, failed ones recorded in DIR/failed/<id>.json and retried
        next time. --shard I/N (or SLURM_ARRAY_TASK_ID / SLURM_ARRAY_TASK_COUNT) runs the jobs
        whose plan index is I modulo N. Progress bar with ETA on a terminal. Prints a JSON
        summary; exit 1 if a job failed, 130 if interrupted.
slurm   writes DIR/sweep-array.sbatch (one array task per shard), DIR/sweep-merge.sbatch
        (`fovea sweep report` into DIR/report) and DIR/submit.sh; --submit submits both, the
        merge with --dependency=afterok on the array, and prints the job ids. [DIR: slurm/
        next to the plan]
report  merges the results into DIR/results.csv and results.json and writes the figures'
        data to DIR/figures.json, drawn by matplotlib as PNG and SVG (docs/figures.md;
        redraw: fovea plot DIR/figures.json): quality against time per frame with the
        Pareto front per distribution and each point's budget, quality against budget,
        per-band curves (per scene when the scene varies), latency against quality
        (latency jobs: gaze-to-photon against foveal error and fovea quality).
        --markdown PAGE also writes a Markdown page: every job at equal samples, the
        best quality at equal time, per-band PSNR, the plots (linked relative to PAGE) and
        the front's cost against the cartesian job for a 90 Hz frame; --command is the
        regeneration command its header quotes.

DIR (--dir) is the results directory [the plan's directory]. docs/sweep.md has the formats.
Exit status: 0 on success, 2 on invalid arguments or input files, 1 on other errors.
)";

std::string self_exe() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot find this program's path (/proc/self/exe)");
  return p.string();
}

// The options `fovea <name> --help` lists: the keys a sweep file may vary for its jobs.
std::vector<sweep::RenderOption> help_options(const std::string& name) {
  const auto it = commands().find(name);
  if (it == commands().end()) throw std::runtime_error("this fovea has no " + name + " command");
  std::ostringstream help;
  std::streambuf* old = std::cout.rdbuf(help.rdbuf());
  try {
    it->second.run({"--help"});
  } catch (...) {
    std::cout.rdbuf(old);
    throw;
  }
  std::cout.rdbuf(old);
  return sweep::parse_help_options(help.str());
}

// The commands a sweep file may run ("command" key) and their options.
sweep::CommandOptions command_options() {
  sweep::CommandOptions o;
  for (const char* name : {"render", "latency"}) o[name] = help_options(name);
  return o;
}

std::string plan_arg(const Args& a, const char* sub) {
  if (a.positional().size() != 1) throw core::InputError(std::string("sweep ") + sub + " needs PLAN (see --help)");
  return a.positional()[0];
}

std::string results_dir(const Args& a, const std::string& plan) {
  return a.str("dir", fs::absolute(plan).parent_path().string());
}

int cmd_plan(const std::vector<std::string>& argv) {
  const Args a(argv, {"out"}, {}, 1);
  if (a.positional().size() != 1 || !a.has("out")) throw core::InputError("sweep plan needs FILE and --out PLAN (see --help)");
  const sweep::Plan plan = sweep::load_sweep_file(a.positional()[0], command_options());
  const std::string out = a.str("out", "");
  core::prepare_output_file(out, "--out");
  core::write_file_atomic(out, sweep::plan_to_jsonl(plan));
  std::cout << json{{"plan", out}, {"jobs", plan.jobs.size()}, {"shared", plan.shared.size()}}.dump() << "\n";
  return 0;
}

int cmd_run(const std::vector<std::string>& argv) {
  const Args a(argv, {"dir", "jobs", "shard"}, {"quiet"}, 1);
  const std::string path = plan_arg(a, "run");
  const sweep::Plan plan = sweep::read_plan(path);
  sweep::RunOptions o;
  o.dir = results_dir(a, path);
  o.fovea_exe = self_exe();
  o.jobs = int(a.integer("jobs", sweep::default_pool_size()));
  if (o.jobs < 1 || o.jobs > 1024) throw core::InputError("--jobs must be in 1..1024");
  if (auto s = a.opt("shard")) {
    std::tie(o.shard_index, o.shard_count) = sweep::parse_shard(*s);
  } else if (const char* id = std::getenv("SLURM_ARRAY_TASK_ID")) {
    const char* count = std::getenv("SLURM_ARRAY_TASK_COUNT");
    if (!count) throw core::InputError("SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not");
    std::tie(o.shard_index, o.shard_count) =
        sweep::parse_shard(std::string(id) + "/" + count);
  }
  o.progress = !a.has("quiet") && stderr_is_tty();
  const sweep::RunSummary s = sweep::run_plan(plan, o);
  std::cout << json{{"shard", std::to_string(o.shard_index) + "/" + std::to_string(o.shard_count)},
                    {"jobs", s.jobs},
                    {"skipped", s.skipped},
                    {"ran", s.ran},
                    {"failed", s.failed},
                    {"interrupted", s.interrupted},
                    {"dir", o.dir}}
                   .dump()
            << "\n";
  if (s.failed) std::cerr << "fovea sweep run: " << s.failed << " job(s) failed; see " << o.dir << "/failed/\n";
  return s.interrupted ? 130 : s.failed ? 1 : 0;
}

int cmd_slurm(const std::vector<std::string>& argv) {
  const Args a(argv, {"shards", "partition", "cpus-per-task", "mem", "time", "gpus", "out", "dir"}, {"submit"}, 1);
  const std::string path = plan_arg(a, "slurm");
  if (!a.has("shards")) throw core::InputError("sweep slurm needs --shards N (see --help)");
  const sweep::Plan plan = sweep::read_plan(path);  // refuse a broken plan before the cluster does
  sweep::SlurmOptions o;
  o.plan = fs::absolute(path).string();
  o.results_dir = fs::absolute(results_dir(a, path)).string();
  o.out_dir = fs::absolute(a.str("out", (fs::path(o.plan).parent_path() / "slurm").string())).string();
  o.fovea_exe = self_exe();
  o.workdir = fs::current_path().string();
  o.shards = int(a.integer("shards", 1));
  o.cpus_per_task = int(a.integer("cpus-per-task", 0));
  if (a.has("cpus-per-task") && o.cpus_per_task < 1) throw core::InputError("--cpus-per-task must be in 1..4096");
  o.partition = a.str("partition", ""), o.mem = a.str("mem", ""), o.time = a.str("time", ""), o.gpus = a.str("gpus", "");
  const sweep::SlurmScripts s = sweep::write_slurm_scripts(o);
  json j = {{"jobs", plan.jobs.size()}, {"shards", o.shards}, {"array_script", s.array_script},
            {"merge_script", s.merge_script}, {"submit_script", s.submit_script}, {"report", o.out_dir + "/report"}};
  if (a.has("submit")) {
    const sweep::SubmittedJobs ids = sweep::submit_slurm(s);
    j["array_job"] = ids.array_id;
    j["merge_job"] = ids.merge_id;
  }
  std::cout << j.dump() << "\n";
  return 0;
}

int cmd_report(const std::vector<std::string>& argv) {
  const Args a(argv, {"out", "dir", "markdown", "command"}, {}, 1);
  const std::string path = plan_arg(a, "report");
  if (!a.has("out")) throw core::InputError("sweep report needs --out DIR (see --help)");
  const sweep::Plan plan = sweep::read_plan(path);
  std::string command = "fovea sweep report " + path + " --out " + a.str("out", "");
  if (a.has("markdown")) command += " --markdown " + a.str("markdown", "");
  const sweep::ReportSummary s = sweep::write_report(
      plan, {results_dir(a, path), a.str("out", ""), a.str("markdown", ""), a.str("command", command)});
  std::cout << json{{"done", s.done}, {"failed", s.failed}, {"missing", s.missing}, {"files", s.files}}.dump() << "\n";
  return 0;
}

int run(std::vector<std::string> argv) {
  if (argv.empty()) {
    std::cerr << kHelp;
    return 2;
  }
  if (argv[0] == "--help" || argv[0] == "-h") {
    std::cout << kHelp;
    return 0;
  }
  const std::string sub = argv[0];
  argv.erase(argv.begin());
  for (const auto& x : argv)
    if (x == "--help" || x == "-h") {
      std::cout << kHelp;
      return 0;
    }
  if (sub == "plan") return cmd_plan(argv);
  if (sub == "run") return cmd_run(argv);
  if (sub == "slurm") return cmd_slurm(argv);
  if (sub == "report") return cmd_report(argv);
  throw core::InputError("unknown sweep subcommand \"" + sub + "\" (plan, run, slurm, report)");
}

}  // namespace

FOVEA_COMMAND(sweep_command, "sweep", "speed/accuracy sweeps: plan, run (local pool or shard), slurm, report", run);

}  // namespace fovea::tools::cmd_sweep

#pragma once
// Sweep plans: a sweep file (JSON) expanded into one job per combination of settings,
// each a `fovea render` command with a stable id, plus the shared inputs (converged
// references) that several jobs use. Format and hash: docs/sweep.md.
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace fovea::sweep {

// One option of `fovea render`, as its --help lists it.
struct RenderOption {
  std::string name;    // without the leading dashes
  bool valued = true;  // false: a flag
};
// The options listed in a command's --help text ("  --name VALUE  ..." / "  --flag  ...").
std::vector<RenderOption> parse_help_options(const std::string& help);

// A shared input: computed once, before the jobs that list its id, into shared/<id>/.
struct SharedInput {
  std::string id;
  nlohmann::json settings;                        // canonical: what the id hashes
  std::vector<std::vector<std::string>> commands;  // run in order; argv[0] "fovea" = this program
  std::string out;                                 // shared/<id>, relative to the results directory
};

struct Job {
  std::string id;
  nlohmann::json settings;        // option -> value (canonical, sorted keys); "command" unless render
  std::vector<std::string> argv;  // the exact command; its --out value is out
  std::string out;                // jobs/<id>, relative to the results directory
  std::vector<std::string> shared;
};

struct Plan {
  nlohmann::json header;  // {"type": "sweep", "source", "report", "jobs", "shared"}
  std::vector<SharedInput> shared;
  std::vector<Job> jobs;
  const SharedInput* find_shared(const std::string& id) const;
};

// FNV-1a, 64 bit (offset basis 0xcbf29ce484222325, prime 0x100000001b3).
std::uint64_t fnv1a64(std::string_view bytes);
// 16 lowercase hex digits of fnv1a64 over the compact JSON dump of `settings` (keys sorted).
std::string settings_id(const nlohmann::json& settings);

// The commands a sweep runs ("render", "latency") and the options each allows as keys.
using CommandOptions = std::map<std::string, std::vector<RenderOption>>;

// Expands a parsed sweep file. `source` names it in error messages; `options` are the options
// allowed as keys for each command (a part's "command" key picks one; "render" when absent).
// Throws core::InputError naming the key and the source.
Plan expand_sweep(const nlohmann::json& sweep, const std::string& source, const CommandOptions& options);
// `render_options` only: a sweep of `fovea render` jobs.
Plan expand_sweep(const nlohmann::json& sweep, const std::string& source, const std::vector<RenderOption>& render_options);
Plan load_sweep_file(const std::string& path, const CommandOptions& options);

// The command a job runs: its settings' "command" ("render" when absent).
std::string job_command(const nlohmann::json& settings);

std::string plan_to_jsonl(const Plan& plan);
// Reads a plan written by plan_to_jsonl; errors name the file and line.
Plan read_plan(const std::string& path);

// Shard `index` of `count` holds the jobs whose plan index i has i % count == index:
// every job in exactly one shard, sizes differing by at most one.
std::vector<std::size_t> shard_jobs(std::size_t job_count, int index, int count);
// "I/N" -> {I, N} with 0 <= I < N; InputError otherwise.
std::pair<int, int> parse_shard(const std::string& text);

}  // namespace fovea::sweep

#pragma once
// Runs a plan (or one shard of it) with a local pool of processes. Each task writes into
// <dir>/<out>.tmp.<host>.<pid> and is renamed to <dir>/<out> when all its commands exit 0,
// so a finished task is exactly one whose directory exists: a second run skips it, and a
// killed run loses only the tasks in flight. Layout: docs/sweep.md.
#include <cstddef>
#include <string>

#include "sweep/plan.hpp"

namespace fovea::sweep {

struct RunOptions {
  std::string dir;        // results directory (jobs/, shared/, failed/)
  std::string fovea_exe;  // replaces argv[0] == "fovea"
  int jobs = 1;           // processes at a time
  int shard_index = 0, shard_count = 1;
  bool progress = false;  // progress bar with ETA on stderr
};

struct RunSummary {
  std::size_t jobs = 0;     // jobs in this shard
  std::size_t skipped = 0;  // already finished before this run
  std::size_t ran = 0;      // finished by this run
  std::size_t failed = 0;   // recorded in failed/<id>.json
  bool interrupted = false;
};

RunSummary run_plan(const Plan& plan, const RunOptions& options);

// Pool size from the machine: the CPUs this process may use divided by the threads each
// lavapipe render uses (LP_NUM_THREADS, lavapipe's default being all CPUs), at least 1.
int default_pool_size();

}  // namespace fovea::sweep

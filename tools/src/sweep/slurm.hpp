#pragma once
// Slurm as the distributed engine: an sbatch job-array script (one array task per shard of
// the plan, each running `fovea sweep run` with SLURM_ARRAY_TASK_ID/COUNT) and a merge
// script (`fovea sweep report`) submitted with --dependency=afterok on the array.
#include <string>

namespace fovea::sweep {

struct SlurmOptions {
  std::string plan;         // absolute paths from here on
  std::string results_dir;  // shared directory the array tasks write into
  std::string out_dir;      // scripts, logs/ and report/
  std::string fovea_exe;
  std::string workdir;      // working directory of the tasks (relative scene/gaze paths)
  int shards = 1;
  int cpus_per_task = 0;    // 0: not requested
  std::string partition, mem, time, gpus;  // empty: not requested
};

struct SlurmScripts {
  std::string array_script, merge_script, submit_script;  // paths written
};

// Validates the options (InputError naming the option) and writes the three scripts.
SlurmScripts write_slurm_scripts(const SlurmOptions& options);

// The job id in `sbatch --parsable` output ("123" or "123;cluster"); InputError otherwise.
std::string parse_parsable(const std::string& sbatch_stdout);

struct SubmittedJobs {
  std::string array_id, merge_id;
};
// Submits the array, then the merge with --dependency=afterok:<array id>. `sbatch` is looked
// up on PATH; failures throw std::runtime_error with sbatch's message.
SubmittedJobs submit_slurm(const SlurmScripts& scripts);

}  // namespace fovea::sweep

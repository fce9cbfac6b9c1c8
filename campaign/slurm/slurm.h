#pragma once
/// @file
/// @brief Campaigns as Slurm job arrays: `capsim campaign submit` (register the campaign exactly as
/// `campaign run` does, write an sbatch script over the cases not done yet, submit it, record the job),
/// `capsim campaign collect` (ingest the result files of the case folders exactly once) and the Slurm part
/// of `campaign status`. Array tasks never open the database: each case folder receives result.json (the
/// worker's JSON line, written via a temporary file + rename) and slurm_exit.json (exit code, host, wall
/// time, job); only the manager side (collect) writes SQLite.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "campaign/scheduler/campaign_runner.h"
#include "campaign/store/sqlite_db.h"

namespace capsim::campaign {

/// @brief Names of the files an array task writes into a case folder.
inline constexpr const char* kResultFile = "result.json";
inline constexpr const char* kSlurmExitFile = "slurm_exit.json";

/// @brief Everything the sbatch script depends on (a pure function of this, for tests).
struct SbatchSettings {
  std::string job_name = "capsim";      ///< --job-name (sanitised)
  std::string campaign_name;            ///< for the header comment
  std::string db_path;                  ///< for the header comment (tasks never open it)
  std::string worker;                   ///< absolute path of the worker (`capsim`)
  std::string runs_dir;                 ///< absolute folder of the case folders
  std::string log_dir;                  ///< absolute folder for %A_%a.out
  std::vector<std::string> case_ids;    ///< in task order: task i owns [i*M, (i+1)*M)
  int cases_per_task = 1;               ///< M
  int array_limit = 0;                  ///< %K (0: none)
  int threads = 1;                      ///< --cpus-per-task and --threads
  std::string partition;                ///< --partition ("" none)
  std::string time_limit;               ///< --time ("" none)
  int signal_lead_s = 60;               ///< --signal=B:TERM@lead
};

/// @brief Number of array tasks for @p n_cases with @p per_task cases each.
int array_size(int n_cases, int per_task);

/// @brief The sbatch script. Each task runs its cases one after the other (`capsim run ... --json`, with
/// --resume when the folder holds a checkpoint, skipping folders that already have a result), forwards
/// SIGTERM/SIGINT to the running worker (which checkpoints and exits 3) and starts no further case.
std::string make_sbatch_script(const SbatchSettings& s);

/// @brief Validates a Slurm time limit (MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS).
bool valid_slurm_time(const std::string& t);

/// @brief Options of `capsim campaign submit`.
struct SubmitOptions {
  RunOptions run;            ///< campaign_file, db_path, runs_dir, threads_per_job, retry_failed, worker, dry_run
  int array_limit = 0;       ///< --array-limit (0: none)
  std::string partition;     ///< --partition
  std::string time_limit;    ///< --time
  int cases_per_task = 1;    ///< --cases-per-task
  int signal_lead_s = 60;    ///< seconds before the time limit at which Slurm sends SIGTERM
};

/// @brief `capsim campaign submit`; returns the exit code. @throws BadInput.
int submit_campaign(const SubmitOptions& opt);

/// @brief Options of `capsim campaign collect`.
struct CollectOptions {
  std::string db_path;   ///< database
  std::string campaign;  ///< only this campaign ("" all)
  bool quiet = false;    ///< no summary on stdout
};

/// @brief `capsim campaign collect`; returns the exit code. @throws BadInput.
int collect_campaign(const CollectOptions& opt);

/// @brief The live array tasks of some jobs, as squeue reports them.
struct QueueState {
  bool available = false;  ///< squeue ran and answered
  std::string error;       ///< why not
  /// job id -> (task index -> state, e.g. PENDING / RUNNING / COMPLETING); only live tasks are listed.
  std::map<std::string, std::map<int, std::string>> tasks;
  /// job id -> pending tasks squeue shows folded ("12_[3-7]"): their count.
  std::map<std::string, int> folded_pending;
  /// @brief Whether task @p task of @p job is still queued/running (false if unknown job or ended).
  bool live(const std::string& job, int task) const;
  /// @brief Whether any task of @p job is live.
  bool live(const std::string& job) const;
};

/// @brief Runs `squeue` for the given jobs (every job id listed by the caller). Unavailable when squeue
/// is missing or fails; never throws.
QueueState query_queue(const std::vector<std::string>& job_ids);

/// @brief States of ended array tasks from `sacct` (job id -> state -> count), nullopt when sacct is
/// missing or accounting is disabled.
std::optional<std::map<std::string, std::map<std::string, int>>> query_sacct(const std::vector<std::string>& job_ids);

/// @brief Appends the Slurm jobs of a campaign (recorded by submit, not yet fully collected) to
/// `campaign status`: live tasks from squeue, ended ones from sacct, degrading gracefully without Slurm.
void print_slurm_status(Db& db, std::int64_t campaign_id);

/// @brief Before a local `campaign run` uses a database that has Slurm jobs: ingests what ended array
/// tasks left (as collect does) and refuses (BadInput) while cases of the campaign are in live or
/// unknown-state array tasks, so a case never runs twice at once. No-op without Slurm tables/jobs.
void check_no_live_slurm_tasks(Store& store, std::int64_t campaign_id);

/// @brief Full path of an executable found in $PATH ("" if none).
std::string find_program(const std::string& name);

}  // namespace capsim::campaign

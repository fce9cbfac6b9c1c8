#pragma once
/// @file
/// @brief The Slurm tables of the campaign database (schema version 2: slurm_jobs, slurm_tasks) and the case
/// updates of `campaign collect`, as typed functions: slurm/ decides, this file holds the SQL. Callers of
/// the writing functions hold a transaction (collect is one pass in one transaction).

#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "campaign/grid/case_params.h"
#include "campaign/store/sqlite_db.h"

namespace capsim::campaign {

/// @brief A case not finished yet (queued or failed), with its folder.
struct UnfinishedCase {
  std::string case_id;   ///< identity
  CaseParams params;     ///< all case keys
  std::string out_dir;   ///< case folder ("" if never prepared)
};

/// @brief An array task's case that collect has not resolved yet.
struct SubmittedTask {
  std::string job_id;    ///< Slurm job
  int task_index = 0;    ///< SLURM_ARRAY_TASK_ID
  std::string case_id;   ///< the case
  std::string status;    ///< the case's status in `cases`
  std::string out_dir;   ///< its folder
};

/// @brief A submitted job of a campaign not fully collected.
struct OpenSlurmJob {
  std::string job_id, submitted_at;           ///< id, submission time
  std::int64_t n_tasks = 0, n_cases = 0;      ///< array size, cases
  std::int64_t open_cases = 0;                ///< cases not collected yet
};

/// @brief A job sbatch accepted, as `campaign submit` records it.
struct SlurmJobRecord {
  std::string job_id;                         ///< sbatch --parsable
  std::int64_t campaign_id = 0;               ///< its campaign
  std::string script_path;                    ///< the submitted script
  int n_tasks = 0, cases_per_task = 1;        ///< array size, M
  int array_limit = 0;                        ///< %K, 0 none
  std::string partition, time_limit;          ///< "" none
  int threads = 1;                            ///< per task
  std::vector<std::string> case_ids;          ///< in task order
  std::vector<bool> resumed;                  ///< per case: a checkpoint existed at submission
};

/// @brief Job ids with cases not collected yet (none for a database without Slurm tables).
std::vector<std::string> open_job_ids(Db& db);
/// @brief Campaigns that hold case @p case_id.
std::set<std::int64_t> campaigns_of_case(Db& db, const std::string& case_id);
/// @brief Queued or failed cases (of campaign @p campaign_id only, if given).
std::vector<UnfinishedCase> unfinished_cases(Db& db, std::optional<std::int64_t> campaign_id);
/// @brief Cases of array tasks not resolved yet (of campaign @p campaign_id only, if given), by job and position.
/// Empty for a database without Slurm tables.
std::vector<SubmittedTask> submitted_tasks(Db& db, std::optional<std::int64_t> campaign_id = std::nullopt);

/// @brief An attempt that ran outside this manager (an array task or a hand run), recorded when collected.
void add_collected_attempt(Db& db, const std::string& case_id, const std::optional<std::string>& host, bool resumed,
                           const std::string& outcome, std::optional<int> exit_code, const std::string& error);
/// @brief Marks a case finished from a collected result file (its results row is inserted by the caller):
/// status done/unstable, wall time from the task's exit record else the result, one more attempt.
void mark_collected_result(Db& db, const std::string& case_id, const std::string& status,
                           std::optional<double> task_wall_s, std::optional<double> result_wall_s,
                           const std::optional<std::string>& host, const std::optional<std::string>& code_version,
                           const std::string& error, const std::string& h5_path);
/// @brief A case whose array task ended without a valid result: queued (resumable if @p resumable) or failed.
void mark_collected_failure(Db& db, const std::string& case_id, const std::string& status, bool resumable,
                            const std::string& error, std::optional<int> exit_code,
                            const std::optional<std::string>& host, bool attempted);
/// @brief Resolves the open task of @p case_id: of job @p job_id, or (job_id "") of any job, as @p state.
void resolve_task(Db& db, const std::string& job_id, const std::string& case_id, const std::string& state,
                  std::optional<int> exit_code, const std::optional<std::string>& host, std::optional<double> wall_s);
/// @brief Marks the jobs whose every task is resolved as collected.
void close_collected_jobs(Db& db);
/// @brief Open array-task cases of a campaign: their count and the job ids (comma-separated).
std::pair<std::int64_t, std::string> open_tasks_of_campaign(Db& db, std::int64_t campaign_id);
/// @brief Records a submitted job and its tasks (one transaction).
void record_slurm_job(Db& db, const SlurmJobRecord& job);
/// @brief The submitted jobs of a campaign not fully collected, by submission time (none without Slurm tables).
std::vector<OpenSlurmJob> open_slurm_jobs(Db& db, std::int64_t campaign_id);

}  // namespace capsim::campaign

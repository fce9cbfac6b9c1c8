#pragma once
/// @file
/// @brief The campaign database: schema creation and version check, campaigns, cases, results,
/// attempts and transitions. Only the campaign manager opens it for writing.

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "campaign/grid/campaign_spec.h"
#include "campaign/grid/case_params.h"
#include "campaign/store/sqlite_db.h"

namespace capsim::campaign {

/// @brief One row of `cases`, as the scheduler needs it.
struct CaseRow {
  std::string case_id;       ///< identity
  CaseParams params;         ///< all case keys
  std::string status;        ///< queued | running | done | unstable | failed
  bool resumable = false;    ///< a checkpoint exists: start with --resume
  int attempts = 0;          ///< starts so far
  double est_cost = 1;       ///< relative cost estimate
  std::string out_dir;       ///< case folder
  std::string host;          ///< host of the last start
  std::int64_t worker_pid = 0;  ///< pid of the last start (0 unknown)
  std::string error;         ///< last error text
};

/// @brief The outcome of one worker as the manager saw it.
struct WorkerOutcome {
  int exit_code = -1;        ///< exit status, or -1 when killed by a signal
  int signal = 0;            ///< terminating signal, 0 if exited
  double wall_s = 0;         ///< measured by the manager
  std::string last_line;     ///< last line of the worker's stdout
  std::string stderr_tail;   ///< last lines of its stderr
};

/// @brief Critical capillary numbers of one (law, a/b, C, level) group.
struct Transition {
  std::string law;                     ///< membrane law
  double aspect_ratio = 0;             ///< a/b
  double skalak_C = -1;                ///< -1 for neo-hookean
  int mesh_level = 0;                  ///< mesh level
  double d12_threshold = 0.05;         ///< criterion used
  int n_samples = 0;                   ///< finished samples used
  std::optional<double> ca_star_low, ca_star_high;    ///< sampled Ca with min_D12 < threshold
  std::optional<double> ca_star_below, ca_star_above; ///< nearest samples outside the interval
  std::optional<double> ca_min_d12;    ///< sampled Ca of the smallest min_D12
  std::optional<double> ca_h;          ///< interpolated zero of max_tau_min
  std::optional<double> ca_h_low, ca_h_high;          ///< its bracket
  std::string ca_h_low_case, ca_h_high_case;          ///< bracket case ids
  std::string method = "grid";         ///< grid | adaptive
  std::string note;                    ///< e.g. "CaH above sampled range"
};

/// @brief The campaign database.
class Store {
 public:
  /// @brief Opens for writing, creating the file and schema if needed (one transaction, before any
  /// worker). A database of an older schema version this build can migrate (1 -> 2: adds the Slurm
  /// tables) is migrated in one transaction; a newer or unknown version is refused.
  /// @throws BadInput for a corrupt/foreign file or a version it cannot read (nothing written).
  static std::unique_ptr<Store> open_for_write(const std::string& path);
  /// @brief Opens an existing database read-only (queries, status, dry runs). An older version that
  /// is a subset of the current one (1) is read as is. @throws BadInput.
  static std::unique_ptr<Store> open_readonly(const std::string& path);
  /// @brief The schema version this build creates (parsed from the embedded DDL).
  static int expected_schema_version();
  /// @brief The oldest schema version this build reads and migrates (the embedded DDL is additive and
  /// idempotent from this version on: CREATE ... IF NOT EXISTS only).
  static constexpr int kOldestMigratableVersion = 1;

  /// @brief The connection.
  Db& db() { return *db_; }

  /// @brief Inserts or updates a campaign by name; returns its id.
  std::int64_t upsert_campaign(const CampaignSpec& spec);
  /// @brief Id of the campaign named @p name.
  std::optional<std::int64_t> find_campaign(const std::string& name);
  /// @brief Name of the most recently updated campaign (for queries without --campaign).
  std::optional<std::string> latest_campaign();
  /// @brief Adds cases (new rows queued) and links them to the campaign; returns how many were new rows.
  int add_cases(std::int64_t campaign_id, const std::vector<CaseParams>& cases, const std::string& origin,
                const std::string& runs_dir);
  /// @brief Cases of a campaign.
  std::vector<CaseRow> campaign_cases(std::int64_t campaign_id);
  /// @brief Every case with status running (orphans after a manager crash).
  std::vector<CaseRow> running_cases();

  /// @brief Marks a case running and opens an attempt row; returns the attempt id.
  std::int64_t mark_running(const std::string& case_id, const std::string& host, std::int64_t pid, bool resumed);
  /// @brief Records a worker's end: result (done/unstable), interrupted (queued, resumable) or failed.
  /// Returns the new case status.
  std::string record_outcome(const std::string& case_id, std::int64_t attempt_id, const WorkerOutcome& out,
                             const std::string& h5_path, const CaseParams& params);
  /// @brief A running case whose manager died: ingest @p result_line if it is a complete result, else
  /// requeue (resumable when a checkpoint exists). Returns the new status.
  std::string recover_orphan(const std::string& case_id, const std::string& result_line, bool resumable,
                             const std::string& h5_path, const CaseParams& params);
  /// @brief Requeues the failed cases of a campaign (--retry-failed); returns how many.
  int requeue_failed(std::int64_t campaign_id);
  /// @brief Replaces the transitions of a campaign.
  void save_transitions(std::int64_t campaign_id, const std::vector<Transition>& rows);

 private:
  explicit Store(std::unique_ptr<Db> db) : db_(std::move(db)) {}
  std::unique_ptr<Db> db_;
};

/// @brief This machine's host name.
std::string host_name();

/// @brief The worker's JSON result line parsed, if it is a complete result (an object with status
/// "done" or "unstable"); nullopt for anything else (empty, truncated, corrupt, another status).
std::optional<nlohmann::json> parse_result_line(const std::string& line);

/// @brief "" if the parameters a worker reported in its result match the case, else what differs.
std::string result_mismatch(const nlohmann::json& result, const CaseParams& params);

/// @brief Inserts (or replaces) the results row of a case from its parsed result line @p j and the raw
/// @p line. The caller holds a transaction.
void insert_result(Db& db, const std::string& case_id, const nlohmann::json& j, const std::string& line);

/// @brief The reason an unstable result gives (or a generic one).
std::string result_reason(const nlohmann::json& j);

/// @brief Whether table @p name exists (a database of schema version 1 has no Slurm tables).
bool has_table(Db& db, const std::string& name);

}  // namespace capsim::campaign

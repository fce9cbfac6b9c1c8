#pragma once
/// @file
/// @brief The campaign database: schema creation and version check, campaigns, cases, results,
/// attempts and transitions. Only the campaign manager opens it for writing. Every SQL statement of the
/// campaign layer lives in this folder (store/); the other folders call typed functions. Layering:
/// store -> analysis (the Transition / CaseSample value types), grid, common; never the reverse.

#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "campaign/analysis/transitions.h"
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

/// @brief Where a case stands (dry runs).
struct CaseState {
  std::string status;        ///< queued | running | done | unstable | failed
  bool resumable = false;    ///< a checkpoint exists
  int attempts = 0;          ///< starts so far
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

/// @brief A campaign's row (status listing).
struct CampaignInfo {
  std::int64_t campaign_id = 0;  ///< id
  std::string name;              ///< unique name
  std::string updated_at;        ///< last run
};

/// @brief Cases of a campaign per status.
struct StatusCounts {
  std::map<std::string, std::int64_t> by_status;  ///< status -> cases
  std::int64_t total = 0;                         ///< all cases
  std::int64_t adaptive = 0;                      ///< added by adaptive refinement
};

/// @brief A case that needs attention (failed, unstable, running, or queued after an attempt).
struct ProblemCase {
  std::string case_id, law, status, error;  ///< identity, law, status, last error
  double aspect_ratio = 0, capillary_number = 0;  ///< a/b, Ca
  int mesh_level = 0;                       ///< mesh level
  std::string group_key;                    ///< its transition group (GroupKey::str(), analysis/group_key.h)
  std::string out_dir;                      ///< its case folder ("" before its first start)
  double t_end = 0;                         ///< time.t_end of the case
};

/// @brief Filters of `capsim query cases` (empty / non-positive: no filter).
struct CaseFilter {
  std::string campaign;               ///< campaign name
  std::string law;                    ///< membrane law
  double aspect_ratio = 0;            ///< a/b (<= 0: any)
  double ca_min = 0, ca_max = 1e300;  ///< Ca range
  std::string status;                 ///< case status
  double viscosity_ratio = 0;         ///< flow.viscosity_ratio λ (<= 0: any)
};

/// @brief A finished case of a database with its result, as another database can take it over (`capsim campaign
/// import`, case_import.h).
struct FinishedCase {
  std::string case_id;         ///< identity
  std::string status;          ///< done | unstable
  std::string params_json;     ///< every case key, as stored
  std::string solver_version;  ///< the version in its identity
  std::string raw_json;        ///< the worker's result line
  std::string out_dir;         ///< its case folder as recorded ("" if none)
  std::string h5_path;         ///< its time series file as recorded ("" if none)
  double core_s = 0;           ///< what it cost where it ran (worker wall × threads, as `capsim query cases`)
};

/// @brief The campaign database.
class Store {
 public:
  /// @brief Opens for writing, creating the file and schema if needed (one transaction, before any
  /// worker). A database of an older schema version this build can migrate (1 -> 2: adds the Slurm
  /// tables; 2 -> 3: transitions keyed by group; 3 -> 4: role and error columns of transitions; 4 -> 5: level
  /// answers; 5 -> 6: the missing parts of each error; 6 -> 7: the regime-based transition Ca_TS) is migrated in one
  /// transaction; a newer or unknown version is refused.
  /// @throws BadInput for a corrupt/foreign file or a version it cannot read (nothing written).
  static std::unique_ptr<Store> open_for_write(const std::string& path);
  /// @brief Opens an existing database read-only (queries, status, dry runs). An older version that
  /// is a subset of the current one (1) is read as is. @throws BadInput.
  static std::unique_ptr<Store> open_readonly(const std::string& path);
  /// @brief The schema version this build creates (parsed from the embedded DDL).
  static int expected_schema_version();
  /// @brief The oldest schema version this build reads and migrates (schemas/NNN_*.sql from NNN = this + 1
  /// on are applied in order to migrate; an older file can be read as is where the query needs only its columns).
  static constexpr int kOldestMigratableVersion = 1;

  /// @brief The connection.
  Db& db() { return *db_; }

  /// @brief Inserts or updates a campaign by name; returns its id.
  std::int64_t upsert_campaign(const CampaignSpec& spec);
  /// @brief Id of the campaign named @p name.
  std::optional<std::int64_t> find_campaign(const std::string& name);
  /// @brief Name of the most recently updated campaign (for queries without --campaign).
  std::optional<std::string> latest_campaign();
  /// @brief Adds cases (new rows queued) and links them to the campaign; returns how many were new to the
  /// campaign (a case another campaign already holds is linked, and counts; one it holds already does not).
  /// @brief Recomputes est_cost (CaseParams::estimated_cost) of the campaign's cases whose stored value
  /// differs, so that a database written before the estimator changed starts its queue in today's order and
  /// the ETA fits finished and queued cases on one scale (EtaModel). Returns how many changed.
  int refresh_cost_estimates(std::int64_t campaign_id);
  int add_cases(std::int64_t campaign_id, const std::vector<CaseParams>& cases, const std::string& origin,
                const std::string& runs_dir);
  /// @brief Cases of a campaign.
  std::vector<CaseRow> campaign_cases(std::int64_t campaign_id);
  /// @brief The cases linked to a campaign by its grid (origin "grid") that are not in @p grid_ids: what an
  /// earlier version of its file linked (a value since removed from an axis, a changed default). By case id.
  std::vector<CaseRow> stale_grid_cases(std::int64_t campaign_id, const std::set<std::string>& grid_ids);
  /// @brief Removes the campaign's links to @p case_ids (the cases, their results and attempts stay in the
  /// database, and other campaigns keep theirs); returns how many links went.
  int unlink_cases(std::int64_t campaign_id, const std::vector<std::string>& case_ids);
  /// @brief The state of case @p case_id, nullopt if the database does not hold it.
  std::optional<CaseState> case_state(const std::string& case_id);
  /// @brief Every case with status running (orphans after a manager crash).
  std::vector<CaseRow> running_cases();
  /// @brief The case @p case_id if this database holds it finished (done or unstable, with its result row).
  std::optional<FinishedCase> finished_case(const std::string& case_id);
  /// @brief Records another database's result @p from for the unfinished case of the same identity here (one
  /// transaction): its results row (the worker's line as is, so its wall time and threads count as the case's
  /// cost), the case's status, code version and folder @p out_dir (if empty, the folder it had stays) and time
  /// series file @p h5_path (empty: none; an interrupted attempt's is not the result's), and an attempt with outcome
  /// "imported" whose error names @p source. Does nothing and returns false if the case is running or finished here.
  bool import_result(const FinishedCase& from, const std::string& out_dir, const std::string& h5_path,
                     const std::string& source);

  /// @brief Records the folder a case runs in (prepare_case_folder's choice; recovery and collection read it).
  void set_case_folder(const std::string& case_id, const std::string& out_dir);
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
  /// @brief Replaces the transitions of a campaign (one row per Transition::group_key).
  void save_transitions(std::int64_t campaign_id, const std::vector<Transition>& rows);
  /// @brief Every case of a campaign with the metrics and the regime of its result (the input of the analysis).
  std::vector<CaseSample> campaign_samples(std::int64_t campaign_id);
  /// @brief The stored transitions of a campaign (finest level first within law and a/b), with @p mesh_level
  /// (< 0: any) and @p skalak_C (< 0: any; neo-Hookean rows always) filters. A version-2 database has no
  /// group_key column: its rows are one per law, a/b, C and level, and come back with group_key "".
  std::vector<Transition> transitions(std::int64_t campaign_id, int mesh_level = -1, double skalak_C = -1);
  /// @brief The spec JSON a campaign was registered with (nullopt: no such campaign).
  std::optional<std::string> campaign_spec_json(std::int64_t campaign_id);
  /// @brief Campaigns named @p name ("" all), by id.
  std::vector<CampaignInfo> campaigns(const std::string& name);
  /// @brief Cases of a campaign per status.
  StatusCounts status_counts(std::int64_t campaign_id);
  /// @brief Up to @p limit cases of a campaign that need attention, by status, law, a/b, Ca.
  std::vector<ProblemCase> problem_cases(std::int64_t campaign_id, int limit);
  /// @brief Cases with their results (`capsim query cases`): identity columns, status, the result summary,
  /// wall_s, flow_evaluations, threads and core_s (worker wall × threads: the cost campaign status and the
  /// level costs sum), code_version, error, h5_path, params (every case key, JSON text), out_dir (the case
  /// folder) and summary (the worker's JSON result line as stored, a JSON column; null before a result).
  Table cases_table(const CaseFilter& filter);
  /// @brief Number of cases linked to a campaign with origin @p origin ("grid" | "adaptive").
  int count_campaign_cases(std::int64_t campaign_id, const std::string& origin);
  /// @brief Cases and cost of a campaign per mesh level (what a multi-fidelity campaign spent where).
  struct LevelCost {
    int mesh_level = 0;
    int cases = 0;        ///< linked to the campaign, any status
    int finished = 0;     ///< done or unstable
    double core_s = 0;    ///< Σ wall_s × threads of the finished cases, as their workers reported
  };
  std::vector<LevelCost> level_costs(std::int64_t campaign_id);

  /// @brief What one finished case of a campaign cost (the ETA's evidence).
  struct FinishedCost {
    int mesh_level = 0;
    double est_cost = 1;  ///< CaseParams::estimated_cost as stored
    double wall_s = 0;    ///< the worker's wall seconds over all attempts (results.wall_s)
    int threads = 1;      ///< threads it ran with
  };
  /// @brief The done or unstable cases of @p campaign_id with a recorded wall time.
  std::vector<FinishedCost> finished_costs(std::int64_t campaign_id);

 private:
  explicit Store(std::unique_ptr<Db> db) : db_(std::move(db)) {}
  std::unique_ptr<Db> db_;
};

/// @brief Runs the user's SQL (`capsim query sql`): every statement is prepared first and, if any of them
/// writes, none runs. Returns one table per statement that has result columns. @throws BadInput.
std::vector<Table> run_readonly_sql(Db& db, const std::string& text);

/// @brief Whether table @p table has column @p column.
bool has_column(Db& db, const std::string& table, const std::string& column);

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

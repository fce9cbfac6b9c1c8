#pragma once
/// @file
/// @brief `capsim campaign run`: expands a campaign, recovers from an earlier crash, runs the pending cases
/// as J worker processes, records outcomes, stops cleanly on SIGINT/SIGTERM, and recomputes transitions.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "campaign/grid/campaign_spec.h"
#include "campaign/store/store.h"

namespace capsim::campaign {

/// @brief Options of one `campaign run`.
struct RunOptions {
  std::string campaign_file;   ///< campaign TOML
  std::string db_path;         ///< SQLite database (created if missing)
  std::string runs_dir;        ///< case folders; default DB + ".runs"
  int jobs = 0;                ///< concurrent workers (0: cores / threads_per_job)
  int threads_per_job = 0;     ///< threads of each worker (0: cores / jobs, at least 1)
  bool dry_run = false;        ///< list what would run and why; writes nothing
  bool retry_failed = false;   ///< requeue failed cases
  std::string worker;          ///< worker executable (default $CAPSIM_WORKER or this program)
  std::string order = "longest";  ///< "longest" (estimated cost first), "shortest" (cheapest first) or "grid" (file order)
  double grace_s = 120;        ///< after forwarding a stop signal, SIGKILL workers still alive after this
};

/// @brief Exit codes of `campaign run`.
enum RunExit {
  kRunComplete = 0,     ///< every case has a recorded outcome done/unstable
  kRunSomeFailed = 1,   ///< finished, but some cases failed (see status / --retry-failed)
  kRunBadInput = 2,     ///< bad campaign file / database / options; nothing changed
  kRunInterrupted = 3,  ///< stopped by SIGINT/SIGTERM; rerun the same command to resume
};

/// @brief A check run after the campaign is prepared and before any local worker starts (the command line
/// passes the Slurm layer's check_no_live_slurm_tasks: the scheduler does not know Slurm, slurm/ uses it).
using BeforeRun = std::function<void(Store& store, std::int64_t campaign_id)>;

/// @brief Runs a campaign; returns a RunExit code. @throws BadInput (caller prints it, exits 2).
int run_campaign(const RunOptions& opt, const BeforeRun& before_run = {});

/// @brief The default runs folder of a database: DB + ".runs".
std::string default_runs_dir(const std::string& db_path);

/// @brief One writer per database: an exclusive flock on DB.lock (released by the kernel if the holder
/// dies). Every command that writes the database (run, submit, collect) holds it. @throws BadInput if
/// another process holds it.
class ManagerLock {
 public:
  explicit ManagerLock(const std::string& db_path);
  ~ManagerLock();
  ManagerLock(const ManagerLock&) = delete;
  ManagerLock& operator=(const ManagerLock&) = delete;

 private:
  std::string path_;
  int fd_ = -1;
};

/// @brief A campaign registered in its database, ready to run (by local workers or a Slurm array).
struct PreparedCampaign {
  CampaignSpec spec;                  ///< the validated file
  std::vector<CaseParams> cases;      ///< expanded grid
  std::unique_ptr<ManagerLock> lock;  ///< held while the database is open for writing
  std::unique_ptr<Store> store;       ///< opened for writing (created/migrated if needed)
  std::int64_t campaign_id = 0;       ///< its row
  std::string runs_dir;               ///< absolute folder of the case folders
};

/// @brief The common start of `campaign run` and `campaign submit`: validates the file, takes the
/// database lock, opens/creates the store, registers the campaign and its grid cases (queued), requeues
/// failed ones with opt.retry_failed, and recovers cases a crashed manager left running (orphan workers
/// stopped; a finished result ingested, else requeued). @p log receives one-line messages.
/// @throws BadInput (nothing changed).
PreparedCampaign prepare_campaign(const RunOptions& opt, const std::function<void(const std::string&)>& log);

/// @brief Creates the folder of a case (row.out_dir where it lies under runs_dir, else runs_dir/case_id: a
/// copied or moved database never writes into the original's folders) and writes its case.toml atomically;
/// returns the folder.
std::string prepare_case_folder(const CaseRow& row, const std::string& runs_dir);

/// @brief Recomputes the transitions of a campaign (analysis/ per group) and stores them; returns them.
/// @p levels: the campaign's [analysis] levels (roles and errors, analysis/uncertainty.h).
std::vector<Transition> analyse_campaign(Store& store, std::int64_t campaign_id, double d12_threshold,
                                         const std::string& method, const std::vector<int>& levels = {});

/// @brief analyse_campaign with the criterion, method and levels of the spec the campaign was registered with
/// (its stored spec JSON); false if the campaign has none. Used after a collection and by `capsim campaign
/// analyse` (transitions of a database refreshed with this build's analysis, no case run).
bool reanalyse_campaign(Store& store, std::int64_t campaign_id);

/// @brief One adaptive round (analysis/refinement.h) within the campaign's max_cases budget; returns how many
/// cases it added to the campaign (0: nothing left to refine).
/// With [analysis] levels, the next phase of analysis/multi_fidelity.h that adds cases (answer-level rounds,
/// then the dt check, then the check level); @p what, if given, names the phase.
/// With @p unfinished (the cases still running or queued; multi-fidelity only, else 0): the same for the cells
/// none of whose cases is among them — or for every cell when all of them are check-level cases
/// (analysis/multi_fidelity.h, rounds_may_overlap) — the top-up that lets a cell take its next round while
/// other cells' cases run. With @p cell_rounds (multi-fidelity): cells that have had max_rounds + 2 rounds
/// take none, and each cell that gets cases counts one more round.
int refine_campaign(Store& store, std::int64_t campaign_id, const CampaignSpec& spec, const std::string& runs_dir,
                    std::string* what = nullptr, const std::vector<CaseParams>* unfinished = nullptr,
                    std::map<std::string, int>* cell_rounds = nullptr);

/// @brief Writes @p text to @p path via a temporary file in the same folder and rename (atomic).
void write_file_atomic(const std::string& path, const std::string& text);

}  // namespace capsim::campaign

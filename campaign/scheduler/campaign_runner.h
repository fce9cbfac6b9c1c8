#pragma once
/// @file
/// @brief `capsim campaign run`: expands a campaign, recovers from an earlier crash, runs the pending cases
/// as J worker processes, records outcomes, stops cleanly on SIGINT/SIGTERM, and recomputes transitions.

#include <string>

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
  std::string order = "longest";  ///< "longest" (estimated cost first) or "grid" (file order)
  double grace_s = 120;        ///< after forwarding a stop signal, SIGKILL workers still alive after this
};

/// @brief Exit codes of `campaign run`.
enum RunExit {
  kRunComplete = 0,     ///< every case has a recorded outcome done/unstable
  kRunSomeFailed = 1,   ///< finished, but some cases failed (see status / --retry-failed)
  kRunBadInput = 2,     ///< bad campaign file / database / options; nothing changed
  kRunInterrupted = 3,  ///< stopped by SIGINT/SIGTERM; rerun the same command to resume
};

/// @brief Runs a campaign; returns a RunExit code. @throws BadInput (caller prints it, exits 2).
int run_campaign(const RunOptions& opt);

/// @brief The default runs folder of a database: DB + ".runs".
std::string default_runs_dir(const std::string& db_path);

}  // namespace capsim::campaign

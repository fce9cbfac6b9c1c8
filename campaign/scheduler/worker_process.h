#pragma once
/// @file
/// @brief Starting one worker (`capsim run ...` as a child process) and finding orphaned workers.

#include <sys/types.h>

#include <set>
#include <string>
#include <vector>

namespace capsim::campaign {

/// @brief How to start one case.
struct WorkerCommand {
  std::string executable;          ///< worker program (capsim itself unless CAPSIM_WORKER is set)
  std::vector<std::string> args;   ///< argv[1..]: run CASE.toml --out DIR --threads T [--resume] --json
  std::string stdout_path;         ///< truncated, receives the worker's stdout (last line = JSON result)
  std::string stderr_path;         ///< appended, receives its progress and errors
  int threads = 1;                 ///< exported as OMP_NUM_THREADS as well
};

/// @brief The worker executable: $CAPSIM_WORKER if set, else this program (/proc/self/exe).
std::string default_worker_executable();

/// @brief Arguments of `capsim run` for a case folder (the contract of campaign/README.md, "The worker contract").
std::vector<std::string> worker_args(const std::string& case_toml, const std::string& out_dir, int threads, bool resume);

/// @brief fork+exec of a worker in its own process group, with SIGTERM as parent-death signal (so a
/// killed manager does not leave it computing). Returns the pid. @throws std::runtime_error.
pid_t spawn_worker(const WorkerCommand& cmd);

/// @brief Pids of live processes whose command line has `--out DIR` with DIR inside @p runs_dir (workers
/// left behind by a manager that died), excluding zombies. With @p only_dirs non-empty, only workers whose
/// `--out` is one of these folders.
std::vector<pid_t> find_orphan_workers(const std::string& runs_dir, const std::set<std::string>& only_dirs = {});

/// @brief Sends SIGTERM to @p pids (they checkpoint), waits up to @p grace_s for them to end, then SIGKILL.
void stop_processes(const std::vector<pid_t>& pids, double grace_s);

/// @brief Last non-empty line of a file ("" if none).
std::string last_line_of(const std::string& path);

/// @brief The last @p max_chars characters of a file, newlines folded to " | ".
std::string tail_of(const std::string& path, std::size_t max_chars);

/// @brief True if a file whose name contains "checkpoint" exists in @p dir (a resumable case).
bool has_checkpoint(const std::string& dir);

/// @brief The part of a case still to run when it resumes from the checkpoint in its folder @p dir
/// (io::kCheckpointFileName, read for its γ̇t = t): 1 − t / @p t_end, in [0, 1]; 1 when the folder has no
/// readable checkpoint (the case starts afresh). For the ETA: an upper bound, since converged periods stop a
/// case before t_end.
double work_fraction_left(const std::string& dir, double t_end);

}  // namespace capsim::campaign

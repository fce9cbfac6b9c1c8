#pragma once
/// @file
/// @brief Taking finished cases over from another database (`capsim campaign import`).
///
/// A case's identity is a hash of every parameter that changes its result and of the solver version
/// (CaseParams::identity), so two databases that hold the same identity hold the same computation: a case one
/// of them has finished need not run again in the other. That happens whenever studies overlap — the
/// level-4 run of the oblate capsule without bending that the bending convergence study made is also a
/// bracketing case of the certified Table 1 — and when a study is split over machines.
///
/// Contract: only cases the target holds unfinished (queued, or failed) are taken, and only from a source that
/// holds them finished (done or unstable) with a result line. Every candidate is checked before anything is
/// written — its stored parameters must hash to its identity under this build, and its result must name the
/// same parameters — and one bad candidate refuses the whole import (BadInput: nothing changes). A case running
/// in the target is left alone. The worker's result line is stored as is, so its wall time and threads count as
/// the case's cost. The case folder's files (not its checkpoint) are copied into the target's runs folder, so the
/// target's time series files do not point into another database's folder.

#include <cstdint>
#include <string>
#include <vector>

#include "campaign/store/store.h"

namespace capsim::campaign {

/// @brief What to import.
struct ImportOptions {
  std::string source_path;  ///< the source database file (messages; its DB.runs folder is the fallback)
  std::string runs_dir;     ///< the target's runs folder: copied case folders go to runs_dir/<case_id>
  std::string campaign;     ///< only cases of this campaign of the target ("" every campaign)
  bool dry_run = false;     ///< list what would be imported, change nothing
};

/// @brief One case taken over.
struct ImportedCase {
  std::string case_id, law, status;  ///< identity, law, done | unstable
  double aspect_ratio = 0, capillary_number = 0;
  int mesh_level = 0;
  std::string folder;      ///< its folder in the target ("" if the source's folder was not found)
  double core_s = 0;       ///< what it cost where it ran: the worker's wall seconds × threads
};

/// @brief What an import did.
struct ImportReport {
  std::vector<ImportedCase> imported;         ///< taken over (or, in a dry run, would be)
  int unfinished = 0;                         ///< unfinished cases of the target considered
  int not_in_source = 0;                      ///< of those, not finished in the source
  int running = 0;                            ///< of those, running in the target: left alone
  std::vector<std::int64_t> campaigns;        ///< target campaigns that link an imported case
};

/// @brief Imports into @p target the finished cases of @p source that @p target holds unfinished.
/// @throws BadInput when a candidate fails its checks (nothing written) or the campaign does not exist.
ImportReport import_finished_cases(Store& target, Store& source, const ImportOptions& options);

}  // namespace capsim::campaign

#include "campaign/store/case_import.h"

#include <filesystem>
#include <optional>
#include <set>
#include <system_error>

#include "campaign/common/bad_input.h"

namespace capsim::campaign {

namespace {

namespace fs = std::filesystem;

// A candidate that passed its checks: the source's case and its parameters.
struct Candidate {
  FinishedCase from;
  CaseParams params;
};

// Why @p from may not be taken over for @p id, or "" if it may.
std::string check_candidate(const FinishedCase& from, const std::string& id, CaseParams& params) {
  try {
    params = CaseParams::from_json(from.params_json);
    if (params.identity(from.solver_version) != id)
      return "its stored parameters do not hash to its identity under this build (a foreign or altered database)";
  } catch (const std::exception& e) {
    return std::string("its stored parameters are unreadable: ") + e.what();
  }
  const auto j = parse_result_line(from.raw_json);
  if (!j) return "its result line is not a complete result";
  if (auto m = result_mismatch(*j, params); !m.empty()) return "its result names other parameters: " + m;
  return "";
}

// The source's folder of a case: where it ran, else SOURCE.runs/<id> (a database copied from another clone).
std::optional<fs::path> source_folder(const FinishedCase& from, const std::string& source_path) {
  std::error_code ec;
  if (!from.out_dir.empty() && fs::is_directory(from.out_dir, ec)) return fs::path(from.out_dir);
  const fs::path fallback = fs::path(source_path + ".runs") / from.case_id;
  if (fs::is_directory(fallback, ec)) return fallback;
  return std::nullopt;
}

// Copies the files of @p src (not its checkpoint: the case is finished) into a folder of the target's runs
// folder: <id>, or <id>.imported where <id> already holds files (an interrupted attempt's, left as they are).
// Returns the folder and the copied time series file.
std::pair<std::string, std::string> copy_case_files(const fs::path& src, const std::string& runs_dir,
                                                    const FinishedCase& from) {
  fs::path dest = fs::path(runs_dir) / from.case_id;
  std::error_code ec;
  if (fs::exists(dest, ec) && !fs::is_empty(dest, ec)) dest += ".imported";
  fs::create_directories(dest);
  std::string h5;
  const std::string h5_name = from.h5_path.empty() ? "" : fs::path(from.h5_path).filename().string();
  for (const auto& e : fs::directory_iterator(src)) {
    if (!e.is_regular_file()) continue;
    const std::string name = e.path().filename().string();
    if (name.rfind("checkpoint.", 0) == 0) continue;
    fs::copy_file(e.path(), dest / name, fs::copy_options::overwrite_existing);
    if (name == h5_name) h5 = (dest / name).string();
  }
  return {dest.string(), h5};
}

}  // namespace

ImportReport import_finished_cases(Store& target, Store& source, const ImportOptions& options) {
  ImportReport report;
  const auto camps = target.campaigns(options.campaign);
  if (camps.empty())
    throw BadInput(options.campaign.empty() ? std::string("the target database holds no campaign")
                                            : "the target database has no campaign named '" + options.campaign + "'");
  // Phase 1: every candidate checked before anything is written.
  std::vector<Candidate> candidates;
  std::set<std::string> seen;
  for (const auto& c : camps)
    for (const auto& row : target.campaign_cases(c.campaign_id)) {
      if (row.status == "done" || row.status == "unstable" || !seen.insert(row.case_id).second) continue;
      ++report.unfinished;
      if (row.status == "running") {
        ++report.running;
        continue;
      }
      auto from = source.finished_case(row.case_id);
      if (!from) {
        ++report.not_in_source;
        continue;
      }
      Candidate k{*from, {}};
      if (auto why = check_candidate(k.from, row.case_id, k.params); !why.empty())
        throw BadInput(options.source_path + ": case " + row.case_id + " cannot be imported: " + why +
                       "; nothing was imported");
      candidates.push_back(std::move(k));
    }
  // Phase 2: copy each case's files, then record it (one transaction per case).
  std::set<std::string> imported_ids;
  for (const auto& k : candidates) {
    ImportedCase out{k.from.case_id,        k.params.law(), k.from.status, k.params.aspect_ratio(),
                     k.params.capillary_number(), k.params.mesh_level(), "", k.from.core_s};
    if (!options.dry_run) {
      std::string h5;
      if (const auto src = source_folder(k.from, options.source_path)) std::tie(out.folder, h5) =
          copy_case_files(*src, options.runs_dir, k.from);
      if (!target.import_result(k.from, out.folder, h5, options.source_path)) continue;
    }
    imported_ids.insert(out.case_id);
    report.imported.push_back(std::move(out));
  }
  for (const auto& c : camps)
    for (const auto& row : target.campaign_cases(c.campaign_id))
      if (imported_ids.count(row.case_id)) {
        report.campaigns.push_back(c.campaign_id);
        break;
      }
  return report;
}

}  // namespace capsim::campaign

// `capsim campaign run|submit|collect|import|analyse|status`: the campaign manager's command line.

#include <cstdio>
#include <exception>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "campaign/cli/cli_app.h"
#include "campaign/cli/commands.h"
#include "campaign/analysis/group_key.h"
#include "campaign/common/bad_input.h"
#include "campaign/grid/decimal.h"
#include "campaign/grid/precision.h"
#include "campaign/query/table_output.h"
#include "campaign/scheduler/campaign_runner.h"
#include "campaign/scheduler/progress.h"
#include "campaign/scheduler/worker_process.h"
#include "campaign/slurm/slurm.h"
#include "campaign/store/case_import.h"
#include "campaign/store/store.h"
#include "solver/config/case_keys.h"
#include "solver/io/checkpoint.h"

namespace capsim::cli {

namespace {

using campaign::BadInput;

// The identity keys, beyond those with a column (law, a/b, C, level), whose value differs between the groups
// of a campaign — capsule.bending_modulus on a bending axis, time.dt of a dt/2 check: without them two rows
// of the status table, or two problem cases, read the same.
const std::set<std::string> kShownKeys = {"capsule.law", "capsule.aspect_ratio", "capsule.skalak_C", "mesh.level"};

std::vector<std::string> varying_keys(const std::vector<std::string>& group_keys) {
  std::map<std::string, std::set<std::string>> values;  // key -> the values it takes ("unset" where absent)
  std::vector<campaign::GroupKey> parsed;
  for (const auto& g : group_keys)
    if (auto k = campaign::GroupKey::parse(g)) {  // a version-2 row has no group key
      for (const auto& name : k->keys())
        if (!kShownKeys.count(name)) values[name];
      parsed.push_back(std::move(*k));
    }
  for (const auto& k : parsed)
    for (auto& [name, vs] : values) vs.insert(k.json_text(name));
  std::vector<std::string> out;
  for (const auto& [k, vs] : values)
    if (vs.size() > 1) out.push_back(k);
  return out;
}

// "capsule.bending_modulus=0.001, time.dt=0.01" for @p keys of @p group_key (a key left at its default is not
// in the group key: the registry's default is shown).
std::string key_values(const std::string& group_key, const std::vector<std::string>& keys) {
  const auto key = campaign::GroupKey::parse(group_key);
  std::string out;
  for (const auto& k : keys) {
    std::string v;
    if (key) v = key->text(k);
    else if (const auto* registered = config::find_case_key(k)) v = config::shortest_text(registered->default_value);
    out += (out.empty() ? "" : ", ") + k + "=" + v;
  }
  return out;
}

// The transitions as `status` prints them (with the regime bracket Ca_TS; its note is in `query transitions`):
// sampled Ca as sampled, CaH to the leading digit of its bracket
// width (its error bound), no digit more (`capsim query sql` gives the stored values in full). A column
// "group" names the other keys that tell the rows apart, where there are such.
campaign::Table transitions_table(const std::vector<campaign::Transition>& rows) {
  campaign::Table t;
  std::vector<std::string> groups;
  for (const auto& r : rows) groups.push_back(r.group_key);
  const auto keys = varying_keys(groups);
  t.columns = {"law", "aspect_ratio", "skalak_C", "mesh_level", "role", "n_samples", "ca_star_low", "ca_star_high",
               "ca_h", "ca_h_low", "ca_h_high", "ca_ts_low", "ca_ts_high", "method", "note"};
  if (!keys.empty()) t.columns.insert(t.columns.begin() + 4, "group");
  auto sampled = [](const std::optional<double>& x) {
    return x ? campaign::SqlValue{campaign::format_sampled(*x)} : campaign::SqlValue{nullptr};
  };
  for (const auto& r : rows) {
    campaign::SqlValue h = nullptr;
    if (r.ca_h)
      h = r.ca_h_err                  ? campaign::format_plus_minus(*r.ca_h, *r.ca_h_err)
          : r.ca_h_low && r.ca_h_high ? campaign::format_with_error(*r.ca_h, *r.ca_h_high - *r.ca_h_low)
                                      : campaign::format_significant(*r.ca_h, 3);
    t.rows.push_back({r.law, campaign::format_sampled(r.aspect_ratio),
                      r.skalak_C < 0 ? campaign::SqlValue{nullptr} : campaign::SqlValue{campaign::format_sampled(r.skalak_C)},
                      std::int64_t{r.mesh_level}, r.role, std::int64_t{r.n_samples}, sampled(r.ca_star_low),
                      sampled(r.ca_star_high), h, sampled(r.ca_h_low), sampled(r.ca_h_high), sampled(r.ca_ts_low),
                      sampled(r.ca_ts_high), r.method, r.note});
    if (!keys.empty()) t.rows.back().insert(t.rows.back().begin() + 4, key_values(r.group_key, keys));
  }
  return t;
}

// `capsim campaign analyse`: the stored transitions are what the analysis of the build that last ran a campaign
// made of its cases; after a change of the analysis (e.g. a sphere has no Ca*), this refreshes them in place
// without running anything. It takes the manager lock: not while a manager runs on the database.
int analyse(const std::string& db_path, const std::string& name) {
  if (!std::filesystem::is_regular_file(db_path)) throw BadInput(db_path + ": no such database");
  campaign::ManagerLock lock(db_path);
  auto store = campaign::Store::open_for_write(db_path);
  const auto camps = store->campaigns(name);
  if (camps.empty())
    throw BadInput(db_path + (name.empty() ? ": no campaign in this database" : ": no campaign named '" + name + "'"));
  for (const auto& c : camps) {
    const bool done = campaign::reanalyse_campaign(*store, c.campaign_id);  // one transaction (save_transitions)
    std::printf("campaign '%s': %s\n", c.name.c_str(), done ? "transitions recomputed" : "no stored spec, left as is");
    if (auto tr = store->transitions(c.campaign_id); done && !tr.empty())
      std::printf("%s", campaign::render(transitions_table(tr), campaign::Format::kMarkdown).c_str());
  }
  return 0;
}

// `capsim campaign import`: takes over the cases another database has finished that this one holds unfinished
// (campaign/store/case_import.h), then recomputes the transitions of the campaigns that gained results, as
// `analyse` does. It takes the manager lock: not while a manager runs on the database.
int import_cases(campaign::ImportOptions opt, const std::string& db_path) {
  namespace fs = std::filesystem;
  if (!fs::is_regular_file(db_path)) throw BadInput(db_path + ": no such database");
  if (!fs::is_regular_file(opt.source_path)) throw BadInput(opt.source_path + ": no such database");
  std::error_code ec;
  if (fs::equivalent(db_path, opt.source_path, ec))
    throw BadInput("--from " + opt.source_path + " is the database itself");
  if (opt.runs_dir.empty()) opt.runs_dir = db_path + ".runs";
  opt.runs_dir = fs::absolute(opt.runs_dir).string();
  std::optional<campaign::ManagerLock> lock;
  if (!opt.dry_run) lock.emplace(db_path);
  auto source = campaign::Store::open_readonly(opt.source_path);
  auto target = opt.dry_run ? campaign::Store::open_readonly(db_path) : campaign::Store::open_for_write(db_path);
  campaign::ImportReport report;
  try {
    report = campaign::import_finished_cases(*target, *source, opt);
  } catch (const fs::filesystem_error& e) {
    // A case's files are copied before its row changes: the cases imported so far are complete, the rest untouched.
    std::fprintf(stderr, "capsim campaign: error: cannot copy a case folder into %s: %s; the cases imported before it "
                 "stay imported, rerun the command once the folder is writable\n", opt.runs_dir.c_str(), e.what());
    return kExitWriteFailed;
  }
  double core_s = 0;
  for (const auto& c : report.imported) {
    core_s += c.core_s;
    std::printf("%s %s %s a/b=%s Ca=%s level %d: %s (%s core-h where it ran)%s\n",
                opt.dry_run ? "would import" : "imported", c.case_id.c_str(), c.law.c_str(),
                campaign::canonical_double(c.aspect_ratio).c_str(), campaign::canonical_double(c.capillary_number).c_str(),
                c.mesh_level, c.status.c_str(), campaign::format_significant(c.core_s / 3600.0, 3).c_str(),
                opt.dry_run || !c.folder.empty() ? "" : "; its case folder was not found, so no time series file");
  }
  std::printf("capsim campaign import: %s %zu of %d unfinished case(s) from %s (%s core-h saved); %d not finished "
              "there%s\n",
              opt.dry_run ? "would take" : "took", report.imported.size(), report.unfinished, opt.source_path.c_str(),
              campaign::format_significant(core_s / 3600.0, 3).c_str(), report.not_in_source,
              report.running ? (", " + std::to_string(report.running) + " running here (left alone)").c_str() : "");
  if (!opt.dry_run)
    for (const auto id : report.campaigns) campaign::reanalyse_campaign(*target, id);
  if (!opt.dry_run && !report.campaigns.empty())
    std::printf("capsim campaign import: transitions of %zu campaign(s) recomputed; `capsim campaign run` continues "
                "from here\n", report.campaigns.size());
  return 0;
}

// How far a running or interrupted case has got, from its last checkpoint in its folder (the worker writes one
// every output.checkpoint_interval and on interrupt): " (checkpoint at γ̇t = 20 of 40)", or "".
std::string checkpoint_progress(const campaign::ProblemCase& p) {
  if (p.status != "running" && p.status != "queued") return "";
  if (p.out_dir.empty()) return "";
  const std::filesystem::path file = std::filesystem::path(p.out_dir) / io::kCheckpointFileName;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return "";
  try {
    const io::Checkpoint cp = io::read_checkpoint(file);
    char buf[96];
    std::snprintf(buf, sizeof buf, " (checkpoint at γ̇t = %.4g of %.4g)", cp.time, p.t_end);
    return buf;
  } catch (const std::exception&) {
    return " (checkpoint unreadable: resuming will fail with exit 2; remove " + file.string() +
           " to start the case afresh)";
  }
}

int status(const std::string& db_path, const std::string& name) {
  auto store = campaign::Store::open_readonly(db_path);
  const auto camps = store->campaigns(name);
  for (const auto& c : camps) {
    std::printf("campaign '%s' (last run %s)\n", c.name.c_str(), c.updated_at.c_str());
    auto n = store->status_counts(c.campaign_id);
    std::printf("  %lld cases (%lld added by adaptive refinement): done %lld, unstable %lld, failed %lld, running %lld, "
                "queued %lld\n",
                (long long)n.total, (long long)n.adaptive, (long long)n.by_status["done"],
                (long long)n.by_status["unstable"], (long long)n.by_status["failed"], (long long)n.by_status["running"],
                (long long)n.by_status["queued"]);
    const auto problems = store->problem_cases(c.campaign_id, 50);
    const auto tr = store->transitions(c.campaign_id);
    std::vector<std::string> groups;
    for (const auto& r : tr) groups.push_back(r.group_key);
    for (const auto& p : problems) groups.push_back(p.group_key);
    const auto keys = varying_keys(groups);
    for (const auto& p : problems) {
      std::string err = p.status == "running" ? "" : p.error;  // a running case's error is its last attempt's
      if (err.size() > 160) err = err.substr(0, 157) + "...";
      const std::string more = keys.empty() ? "" : " " + key_values(p.group_key, keys);
      std::string note = err + checkpoint_progress(p);
      if (err.empty() && !note.empty()) note.erase(0, 1);  // the progress alone: no leading blank
      std::printf("  %-8s %s  %s a/b=%s Ca=%s level %d%s  %s\n", p.status.c_str(), p.case_id.c_str(), p.law.c_str(),
                  campaign::canonical_double(p.aspect_ratio).c_str(), campaign::canonical_double(p.capillary_number).c_str(),
                  p.mesh_level, more.c_str(), note.c_str());
    }
    // What each mesh level cost (a multi-fidelity campaign's saving is read here).
    if (const auto costs = store->level_costs(c.campaign_id); costs.size() > 1) {
      std::printf("  per mesh level:");
      for (const auto& l : costs)
        std::printf(" level %d: %d cases (%d finished, %s core-h);", l.mesh_level, l.cases, l.finished,
                    campaign::format_significant(l.core_s / 3600.0, 3).c_str());
      std::printf("\n");
    }
    // The work still to do, as the runner's ETA would see it (one thread per case).
    {
      // A case with a checkpoint counts the part after it (a running case's is where it has got to).
      std::vector<campaign::EtaModel::Work> left;
      for (const auto& r : store->campaign_cases(c.campaign_id))
        if (r.status == "queued" || r.status == "running") {
          campaign::EtaModel::Work w{r.params.mesh_level(), r.est_cost, campaign::work_fraction_left(r.out_dir, r.params.t_end())};
          w.est_cost_below = r.params.estimated_cost_on_level(r.params.mesh_level() - 1);
          left.push_back(w);
        }
      const double s = left.empty() ? -1 : campaign::learn_eta(*store, c.campaign_id, 1).remaining_s(left, 1);
      if (s > 0)
        std::printf("  work left: about %s core-h in the %zu queued and running cases (from what its finished cases "
                    "cost, per mesh level, after their checkpoints; good to a factor of about two)\n",
                    campaign::format_significant(s / 3600.0, 2).c_str(), left.size());
    }
    if (!tr.empty()) std::printf("%s", campaign::render(transitions_table(tr), campaign::Format::kMarkdown).c_str());
    campaign::print_slurm_status(store->db(), c.campaign_id);
  }
  if (camps.empty()) {
    if (!name.empty()) throw BadInput(db_path + ": no campaign named '" + name + "'");
    std::printf("no campaign in %s\n", db_path.c_str());
  }
  return 0;
}

}  // namespace

int campaign_command(const std::vector<std::string>& args) {
  CLI::App app{"capsim campaign: run a study (grid of cases) into a SQLite database, resumably", "capsim campaign"};
  app.require_subcommand(1);
  campaign::RunOptions opt;
  auto* run = app.add_subcommand("run", "expand the campaign, run what is not done yet, resume after interruptions");
  run->add_option("campaign", opt.campaign_file, "campaign TOML file (see schemas/campaign_keys.md)")->required();
  run->add_option("--db", opt.db_path, "SQLite results database (created if missing)")->required();
  run->add_option("--jobs,-j", opt.jobs, "concurrent worker processes (default: cores / threads-per-job)");
  run->add_option("--threads-per-job,-t", opt.threads_per_job, "threads per worker (default: cores / jobs)");
  run->add_flag("--dry-run", opt.dry_run, "list what would run and why, change nothing");
  run->add_flag("--retry-failed", opt.retry_failed, "run failed cases again");
  run->add_option("--runs-dir", opt.runs_dir, "folder of the case folders (default: DB.runs)");
  run->add_option("--order", opt.order,
                  "longest (estimated cost first, default), shortest (cheapest first: the most answers before an "
                  "interruption) or grid (file order)");
  run->add_option("--grace", opt.grace_s, "seconds workers get to checkpoint after SIGINT/SIGTERM (default 120)");
  run->add_option("--worker", opt.worker, "worker executable (default: $CAPSIM_WORKER, else this capsim)")
      ->group("");  // hidden: for tests and alternative workers

  campaign::SubmitOptions sub;
  auto* submit = app.add_subcommand(
      "submit", "register the campaign as `run` does, submit the cases not done yet as a Slurm job array (sbatch)");
  submit->add_option("campaign", sub.run.campaign_file, "campaign TOML file (see schemas/campaign_keys.md)")->required();
  submit->add_option("--db", sub.run.db_path, "SQLite results database (created if missing; array tasks never open it)")
      ->required();
  submit->add_option("--array-limit", sub.array_limit, "at most K array tasks at once (--array=0-N%K)");
  submit->add_option("--partition", sub.partition, "Slurm partition");
  submit->add_option("--time", sub.time_limit, "time limit per array task, HH:MM:SS (SIGTERM 60 s before: checkpoint)");
  submit->add_option("--cases-per-task", sub.cases_per_task, "cases run one after the other by each array task (default 1)");
  submit->add_option("--threads-per-job,-t", sub.run.threads_per_job, "threads per case (--cpus-per-task; default 1)");
  submit->add_flag("--dry-run", sub.run.dry_run, "print the sbatch script that would be submitted, change nothing");
  submit->add_flag("--retry-failed", sub.run.retry_failed, "submit failed cases again");
  submit->add_option("--runs-dir", sub.run.runs_dir, "shared folder of the case folders (default: DB.runs)");
  submit->add_option("--signal-lead", sub.signal_lead_s, "seconds before the time limit Slurm sends SIGTERM (default 60)");
  submit->add_option("--worker", sub.run.worker, "worker executable (default: $CAPSIM_WORKER, else this capsim)")->group("");

  campaign::CollectOptions col;
  auto* collect = app.add_subcommand("collect", "ingest the results array tasks left in the case folders (idempotent)");
  collect->add_option("--db", col.db_path, "SQLite results database")->required();
  collect->add_option("--campaign", col.campaign, "only this campaign");

  campaign::ImportOptions imp;
  std::string import_db;
  auto* im = app.add_subcommand("import",
                                "take over the cases another database has finished that this one holds unfinished "
                                "(same identity: same parameters and solver version)");
  im->add_option("--db", import_db, "SQLite results database to import into")->required();
  im->add_option("--from", imp.source_path, "the other database (read only)")->required();
  im->add_option("--campaign", imp.campaign, "only cases of this campaign");
  im->add_option("--runs-dir", imp.runs_dir, "folder the copied case folders go to (default: DB.runs)");
  im->add_flag("--dry-run", imp.dry_run, "list what would be imported, change nothing");

  std::string analyse_db, analyse_name;
  auto* an = app.add_subcommand("analyse",
                                "recompute the transitions of each campaign (or one) with this build's analysis; runs no case");
  an->add_option("--db", analyse_db, "SQLite results database")->required();
  an->add_option("--campaign", analyse_name, "only this campaign");

  std::string status_db, status_name;
  auto* st = app.add_subcommand("status", "counts per status, failures, transitions of each campaign");
  st->add_option("--db", status_db, "SQLite results database")->required();
  st->add_option("--campaign", status_name, "only this campaign");

  if (const auto code = parse_args(app, args)) return *code;
  try {
    if (*run) {
      if (opt.jobs < 0 || opt.threads_per_job < 0 || (run->count("--jobs") && opt.jobs == 0) ||
          (run->count("--threads-per-job") && opt.threads_per_job == 0))
        throw BadInput("--jobs and --threads-per-job must be >= 1");
      return campaign::run_campaign(opt, campaign::check_no_live_slurm_tasks);
    }
    if (*submit) {
      if (submit->count("--array-limit") && sub.array_limit < 1) throw BadInput("--array-limit must be >= 1");
      if (submit->count("--threads-per-job") && sub.run.threads_per_job < 1)
        throw BadInput("--threads-per-job must be >= 1");
      if (sub.signal_lead_s < 1) throw BadInput("--signal-lead must be >= 1");
      return campaign::submit_campaign(sub);
    }
    if (*collect) return campaign::collect_campaign(col);
    if (*im) return import_cases(imp, import_db);
    if (*an) return analyse(analyse_db, analyse_name);
    return status(status_db, status_name);
  } catch (const BadInput& e) {
    std::fprintf(stderr, "capsim campaign: error: %s\n", campaign::one_line(e.what()).c_str());
    return kExitBadInput;
  }
}

}  // namespace capsim::cli

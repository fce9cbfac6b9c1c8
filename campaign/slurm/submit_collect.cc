// `capsim campaign submit|collect` and the Slurm lines of `campaign status`.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "campaign/analysis/transitions.h"
#include "campaign/common/bad_input.h"
#include "campaign/common/exit_codes.h"
#include "campaign/grid/campaign_spec.h"
#include "campaign/scheduler/worker_process.h"
#include "campaign/slurm/slurm.h"
#include "campaign/slurm/slurm_internal.h"
#include "campaign/scheduler/campaign_runner.h"
#include "campaign/store/slurm_store.h"
#include "campaign/store/store.h"

namespace capsim::campaign {

namespace fs = std::filesystem;

namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The result line of a case folder: the last non-empty line of DIR/result.json ("" if none).
std::string result_line_of(const std::string& dir) { return last_line_of(dir + "/" + kResultFile); }

/// DIR/slurm_exit.json if it exists, parses, and belongs to @p job_task ("" = any).
std::optional<nlohmann::json> exit_record(const std::string& dir, const std::string& job_task) {
  const std::string path = dir + "/" + kSlurmExitFile;
  if (!fs::exists(path)) return std::nullopt;
  try {
    auto j = nlohmann::json::parse(read_text(path));
    if (!j.is_object() || !j.contains("exit_code") || !j["exit_code"].is_number_integer()) return std::nullopt;
    if (!job_task.empty() && (!j.contains("job") || !j["job"].is_string() || j["job"].get<std::string>() != job_task))
      return std::nullopt;
    return j;
  } catch (...) {
    return std::nullopt;
  }
}

std::optional<double> opt_num(const std::optional<nlohmann::json>& j, const char* k) {
  if (!j || !j->contains(k) || !(*j)[k].is_number()) return std::nullopt;
  return (*j)[k].get<double>();
}
std::optional<std::string> opt_str(const std::optional<nlohmann::json>& j, const char* k) {
  if (!j || !j->contains(k) || !(*j)[k].is_string()) return std::nullopt;
  return (*j)[k].get<std::string>();
}

/// What one collect pass did.
struct CollectCounts {
  int ingested_done = 0, ingested_unstable = 0, failed = 0, interrupted = 0, lost = 0, live = 0, unknown = 0;
  std::vector<std::string> invalid;          ///< result files present but not a valid result
  std::set<std::int64_t> changed_campaigns;  ///< campaigns whose results changed (re-analyse)
  int changes() const { return ingested_done + ingested_unstable + failed + interrupted + lost; }
};

void add_attempt(Db& db, const std::string& case_id, const std::optional<nlohmann::json>& ex, const std::string& outcome,
                 std::optional<int> exit_code, const std::string& error) {
  const bool resumed = ex && ex->contains("resumed") && (*ex)["resumed"].is_boolean() && (*ex)["resumed"].get<bool>();
  add_collected_attempt(db, case_id, opt_str(ex, "host"), resumed, outcome, exit_code, error);
}

/// The core of collect (also the first step of submit). The caller holds the database lock; one
/// transaction. Only cases not finished (queued/failed) are touched, so a second pass changes nothing.
CollectCounts collect_pass(Store& store, std::optional<std::int64_t> campaign_id, const QueueState& queue) {
  Db& db = store.db();
  CollectCounts n;
  Transaction t(db);
  // 1. Valid result files in the folders of unfinished cases (whoever wrote them: an array task, a hand run).
  {
    struct Found {
      std::string id, line, dir;
      CaseParams params;
    };
    std::vector<Found> found;
    for (auto& c : unfinished_cases(db, campaign_id)) {
      if (c.out_dir.empty() || !fs::exists(c.out_dir + "/" + kResultFile)) continue;
      found.push_back({c.case_id, result_line_of(c.out_dir), c.out_dir, std::move(c.params)});
    }
    for (auto& f : found) {
      auto j = parse_result_line(f.line);
      std::string why;
      if (!j) why = "not a complete JSON result (status done|unstable)";
      else if (auto m = result_mismatch(*j, f.params); !m.empty()) why = "parameters differ from the case: " + m;
      if (!why.empty()) {
        n.invalid.push_back(f.dir + "/" + kResultFile + ": " + why);
        continue;
      }
      const std::string status = (*j)["status"].get<std::string>();
      const auto ex = exit_record(f.dir, "");
      insert_result(db, f.id, *j, f.line);
      const std::string h5 = fs::exists(f.dir + "/case.h5") ? f.dir + "/case.h5" : "";
      const std::string reason = status == "unstable" ? result_reason(*j) : "";
      mark_collected_result(db, f.id, status, opt_num(ex, "wall_s"), opt_num(j, "wall_s"), opt_str(ex, "host"),
                            opt_str(j, "code_version"), reason, h5);
      add_attempt(db, f.id, ex, status, 0, reason);
      if (has_table(db, "slurm_tasks")) resolve_task(db, "", f.id, "ingested", 0, opt_str(ex, "host"), opt_num(ex, "wall_s"));
      (status == "done" ? n.ingested_done : n.ingested_unstable)++;
      for (auto c : campaigns_of_case(db, f.id)) n.changed_campaigns.insert(c);
    }
  }
  // 2. Cases of array tasks that ended without a valid result: failed, interrupted (resumable) or lost.
  if (has_table(db, "slurm_tasks")) {
    for (const auto& task : submitted_tasks(db, campaign_id)) {
      if (!queue.available) {
        ++n.unknown;
        continue;
      }
      if (queue.live(task.job_id, task.task_index)) {
        ++n.live;
        continue;
      }
      const std::string job_task = task.job_id + "_" + std::to_string(task.task_index);
      const auto ex = exit_record(task.out_dir, job_task);
      const bool checkpoint = has_checkpoint(task.out_dir);
      std::string state, status, error;
      std::optional<int> code;
      if (ex) code = (*ex)["exit_code"].get<int>();
      if (task.status != "queued" && task.status != "failed") {
        state = "ingested";  // finished by other means (e.g. a local `campaign run`)
      } else if (code && *code == 0) {
        state = status = "failed";
        error = "Slurm array task " + job_task + ": worker exited 0 but " + kResultFile +
                " is missing or not a valid result; stdout ends: " + tail_of(task.out_dir + "/stdout.log", 300);
      } else if (code && *code == kExitInterrupted) {
        state = "interrupted";
        status = "queued";
        error = "interrupted in Slurm array task " + job_task + std::string(checkpoint ? " (checkpoint written; the next "
                                                                            "submit resumes it)" : "");
      } else if (code) {
        state = status = "failed";
        error = "worker exited with code " + std::to_string(*code) + describe_exit_code(*code) +
                (*code > 128 ? " (signal " + std::to_string(*code - 128) + ")" : "") + " in Slurm array task " +
                job_task + "; stderr: " + tail_of(task.out_dir + "/stderr.log", 600);
      } else {
        state = "lost";
        status = "queued";
        error = "Slurm array task " + job_task + " ended without finishing this case (time limit, cancellation or node "
                "failure)" + std::string(checkpoint ? "; resumes from its checkpoint" : "");
      }
      if (!status.empty()) {
        mark_collected_failure(db, task.case_id, status, status == "queued" && checkpoint, error, code, opt_str(ex, "host"),
                               ex.has_value());
        if (ex) add_attempt(db, task.case_id, ex, state == "failed" ? "failed" : "interrupted", code, error);
        for (auto c : campaigns_of_case(db, task.case_id)) n.changed_campaigns.insert(c);
      }
      resolve_task(db, task.job_id, task.case_id, state, code, opt_str(ex, "host"), opt_num(ex, "wall_s"));
      if (state == "failed") ++n.failed;
      else if (state == "interrupted") ++n.interrupted;
      else if (state == "lost") ++n.lost;
    }
    close_collected_jobs(db);
  }
  t.commit();
  return n;
}

/// Recomputes the transitions of the campaigns whose results changed (as `campaign run` does at its end).
void reanalyse(Store& store, const std::set<std::int64_t>& campaigns) {
  for (auto id : campaigns) reanalyse_campaign(store, id);
}

std::string summary(const CollectCounts& n, const QueueState& q) {
  std::ostringstream o;
  o << "ingested " << n.ingested_done + n.ingested_unstable << " result(s) (done " << n.ingested_done << ", unstable "
    << n.ingested_unstable << "), " << n.failed << " failed, " << n.interrupted << " interrupted (resumable), " << n.lost
    << " lost (requeued)";
  if (n.live) o << "; " << n.live << " case(s) still in queued/running array tasks";
  if (n.unknown)
    o << "; " << n.unknown << " case(s) of submitted jobs without a result left as they are (Slurm state unknown: "
      << q.error << ")";
  return o.str();
}

std::string timestamp() {
  std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", std::localtime(&t));
  return buf;
}

}  // namespace

int collect_campaign(const CollectOptions& opt) {
  if (!fs::exists(opt.db_path)) throw BadInput(opt.db_path + ": no such database file");
  ManagerLock lock(opt.db_path);
  auto store = Store::open_for_write(opt.db_path);
  std::optional<std::int64_t> cid;
  if (!opt.campaign.empty()) {
    cid = store->find_campaign(opt.campaign);
    if (!cid) throw BadInput(opt.db_path + ": no campaign named '" + opt.campaign + "'");
  }
  const QueueState queue = query_queue(open_job_ids(store->db()));
  CollectCounts n = collect_pass(*store, cid, queue);
  reanalyse(*store, n.changed_campaigns);
  if (!opt.quiet) {
    std::printf("capsim campaign collect: %s\n", summary(n, queue).c_str());
    for (const auto& bad : n.invalid) std::printf("  not ingested: %s\n", bad.c_str());
  }
  return 0;
}

void check_no_live_slurm_tasks(Store& store, std::int64_t campaign_id) {
  const auto ids = open_job_ids(store.db());
  if (ids.empty()) return;
  const QueueState queue = query_queue(ids);
  CollectCounts n = collect_pass(store, std::nullopt, queue);
  reanalyse(store, n.changed_campaigns);
  const auto [open, jobs] = open_tasks_of_campaign(store.db(), campaign_id);
  if (open > 0)
    throw BadInput(std::to_string(open) + " case(s) of this campaign are in Slurm job(s) " + jobs +
                   (queue.available ? " still queued or running" : " whose state is unknown (" + queue.error + ")") +
                   "; wait for them (or scancel) and run `capsim campaign collect` before `campaign run`");
}

int submit_campaign(const SubmitOptions& opt) {
  // Every check that needs no database first, so bad input changes nothing.
  if (opt.cases_per_task < 1) throw BadInput("--cases-per-task must be >= 1");
  if (opt.array_limit < 0) throw BadInput("--array-limit must be >= 1");
  if (opt.run.threads_per_job < 0) throw BadInput("--threads-per-job must be >= 1");
  if (!opt.time_limit.empty() && !valid_slurm_time(opt.time_limit))
    throw BadInput("--time: expected HH:MM:SS (or MM, MM:SS, D-HH, D-HH:MM, D-HH:MM:SS), got '" + opt.time_limit + "'");
  if (opt.partition.find_first_of(" \t\n\r#'\"\\") != std::string::npos)
    throw BadInput("--partition: not a partition name: '" + opt.partition + "'");
  const CampaignSpec spec = load_campaign_file(opt.run.campaign_file);  // validates the file
  const std::string sbatch = find_program("sbatch");
  if (sbatch.empty() && !opt.run.dry_run)
    throw BadInput("sbatch not found in PATH: `campaign submit` needs a Slurm cluster (scripts/setup-slurm starts a "
                   "local one; `campaign run` runs on this machine); nothing was changed");
  const int threads = opt.run.threads_per_job > 0 ? opt.run.threads_per_job : 1;
  const std::string worker = fs::absolute(opt.run.worker.empty() ? default_worker_executable() : opt.run.worker).string();

  SbatchSettings s;
  s.job_name = "capsim-" + spec.name;
  s.campaign_name = spec.name;
  s.db_path = fs::absolute(opt.run.db_path).string();
  s.worker = worker;
  s.cases_per_task = opt.cases_per_task;
  s.array_limit = opt.array_limit;
  s.threads = threads;
  s.partition = opt.partition;
  s.time_limit = opt.time_limit;
  s.signal_lead_s = opt.signal_lead_s;

  if (opt.run.dry_run) {
    // Nothing is written: the cases a submission would hand to Slurm now, and its script.
    std::unique_ptr<Store> store;
    if (fs::exists(opt.run.db_path)) store = Store::open_readonly(opt.run.db_path);
    const std::string runs = fs::weakly_canonical(fs::absolute(
        opt.run.runs_dir.empty() ? default_runs_dir(opt.run.db_path) : opt.run.runs_dir)).string();
    std::set<std::string> busy;
    if (store) {
      const QueueState q = query_queue(open_job_ids(store->db()));
      for (const auto& task : submitted_tasks(store->db()))
        if (!q.available || q.live(task.job_id, task.task_index)) busy.insert(task.case_id);
    }
    std::vector<std::pair<double, std::string>> pending;
    for (const auto& p : expand_grid(spec)) {
      const std::string id = p.identity(solver_version());
      std::string status = "queued";
      if (store)
        if (auto st = store->case_state(id)) status = st->status;
      if (status == "failed" && opt.run.retry_failed) status = "queued";
      if (status != "queued" || busy.count(id) || parse_result_line(result_line_of(runs + "/" + id))) continue;
      pending.emplace_back(p.estimated_cost(), id);
    }
    std::stable_sort(pending.begin(), pending.end(), [](auto& a, auto& b) { return a.first > b.first; });
    for (auto& [_, id] : pending) s.case_ids.push_back(id);
    s.runs_dir = runs;
    s.log_dir = runs + "/slurm";
    if (s.case_ids.empty()) {
      std::printf("# nothing to submit: every case of '%s' is done, failed, submitted or has a result to collect\n",
                  spec.name.c_str());
      return 0;
    }
    std::printf("%s", make_sbatch_script(s).c_str());
    std::fprintf(stderr, "capsim campaign submit --dry-run: would submit %zu case(s) in %d array task(s)%s\n",
                 s.case_ids.size(), array_size(static_cast<int>(s.case_ids.size()), s.cases_per_task),
                 sbatch.empty() ? " (note: sbatch is not in PATH here)" : "");
    return 0;
  }

  auto log = [](const std::string& m) { std::fprintf(stderr, "%s\n", m.c_str()); };
  PreparedCampaign pc = prepare_campaign(opt.run, log);
  Store& store = *pc.store;
  Db& db = store.db();
  // Ingest what earlier array tasks left, so nothing finished is submitted again.
  QueueState queue = query_queue(open_job_ids(db));
  CollectCounts n = collect_pass(store, std::nullopt, queue);
  reanalyse(store, n.changed_campaigns);
  if (n.changes()) log("capsim campaign submit: collected first: " + summary(n, queue));
  if (spec.analysis.adaptive || !spec.analysis.levels.empty()) {
    // Adaptive or multi-fidelity mode: once the campaign has nothing queued, one round (phase) per submit.
    auto rows = store.campaign_cases(pc.campaign_id);
    if (std::none_of(rows.begin(), rows.end(), [](const CaseRow& r) { return r.status == "queued"; })) {
      std::string what;
      int added = refine_campaign(store, pc.campaign_id, spec, pc.runs_dir, &what);
      if (added) log("capsim campaign submit: " + what + ": " + std::to_string(added) + " case(s) added");
    }
  }
  std::set<std::string> busy;
  for (const auto& task : submitted_tasks(db))
    if (!queue.available || queue.live(task.job_id, task.task_index)) busy.insert(task.case_id);
  if (!busy.empty() && !queue.available)
    log("capsim campaign submit: " + std::to_string(busy.size()) + " case(s) of earlier jobs are left alone (" +
        queue.error + ")");
  std::vector<CaseRow> pending;
  for (auto& r : store.campaign_cases(pc.campaign_id))
    if (r.status == "queued" && !busy.count(r.case_id)) pending.push_back(std::move(r));
  std::stable_sort(pending.begin(), pending.end(),
                   [](const CaseRow& a, const CaseRow& b) { return a.est_cost > b.est_cost; });
  if (pending.empty()) {
    std::printf("nothing to submit: the %zu case(s) of '%s' are done, failed (see --retry-failed) or in live array "
                "tasks (%zu)\n", store.campaign_cases(pc.campaign_id).size(), spec.name.c_str(), busy.size());
    return 0;
  }
  for (auto& r : pending) {
    r.out_dir = prepare_case_folder(r, pc.runs_dir);
    store.set_case_folder(r.case_id, r.out_dir);
    // A leftover result file that is not a valid result (it was not ingested) would make the task skip the
    // case: keep it aside for inspection.
    const std::string rf = r.out_dir + "/" + kResultFile;
    if (fs::exists(rf)) fs::rename(rf, rf + ".invalid-" + timestamp());
    s.case_ids.push_back(r.case_id);
  }
  s.runs_dir = pc.runs_dir;
  s.log_dir = pc.runs_dir + "/slurm";
  fs::create_directories(s.log_dir);
  const std::string script_path = s.log_dir + "/submit-" + timestamp() + "-" + std::to_string(getpid()) + ".sh";
  write_file_atomic(script_path, make_sbatch_script(s));
  chmod(script_path.c_str(), 0755);
  auto r = run_program({sbatch, "--parsable", script_path});
  std::string job = r.out;
  job = job.substr(0, job.find_first_of(";\n"));
  while (!job.empty() && std::isspace(static_cast<unsigned char>(job.back()))) job.pop_back();
  if (r.code != 0 || job.empty() || !std::all_of(job.begin(), job.end(), ::isdigit))
    throw BadInput("sbatch rejected the job (exit " + std::to_string(r.code) + "): " + one_line(r.err.empty() ? r.out : r.err) +
                   "; script " + script_path + "; no job recorded");
  const int tasks = array_size(static_cast<int>(s.case_ids.size()), s.cases_per_task);
  {
    SlurmJobRecord rec;
    rec.job_id = job;
    rec.campaign_id = pc.campaign_id;
    rec.script_path = script_path;
    rec.n_tasks = tasks;
    rec.cases_per_task = s.cases_per_task;
    rec.array_limit = s.array_limit;
    rec.partition = s.partition;
    rec.time_limit = s.time_limit;
    rec.threads = threads;
    for (const auto& p : pending) {
      rec.case_ids.push_back(p.case_id);
      rec.resumed.push_back(has_checkpoint(p.out_dir));
    }
    record_slurm_job(db, rec);
  }
  std::printf("submitted job %s: %zu case(s) of '%s' in %d array task(s), %d per task%s%s%s, %d thread(s) each\n",
              job.c_str(), s.case_ids.size(), spec.name.c_str(), tasks, s.cases_per_task,
              s.array_limit > 0 ? (", at most " + std::to_string(s.array_limit) + " at once").c_str() : "",
              s.partition.empty() ? "" : (", partition " + s.partition).c_str(),
              s.time_limit.empty() ? "" : (", time " + s.time_limit).c_str(), threads);
  std::printf("script %s\nthen: capsim campaign collect --db %s\n", script_path.c_str(), opt.run.db_path.c_str());
  return 0;
}

void print_slurm_status(Db& db, std::int64_t campaign_id) {
  const auto open = open_slurm_jobs(db, campaign_id);
  if (open.empty()) return;
  struct Job {
    std::string id, submitted;
    std::int64_t tasks, cases, open;
  };
  std::vector<Job> jobs;
  for (const auto& j : open) jobs.push_back({j.job_id, j.submitted_at, j.n_tasks, j.n_cases, j.open_cases});
  std::vector<std::string> ids;
  for (auto& j : jobs) ids.push_back(j.id);
  const QueueState q = query_queue(ids);
  std::optional<std::map<std::string, std::map<std::string, int>>> acct;
  for (const auto& j : jobs) {
    std::printf("  slurm job %s (submitted %s): %lld case(s) in %lld array task(s), %lld not collected yet\n",
                j.id.c_str(), j.submitted.c_str(), (long long)j.cases, (long long)j.tasks, (long long)j.open);
    if (!q.available) {
      std::printf("    queue: unknown (%s)\n", q.error.c_str());
      continue;
    }
    std::map<std::string, int> by;
    if (auto it = q.tasks.find(j.id); it != q.tasks.end())
      for (auto& [_, st] : it->second) by[st]++;
    if (by.empty() && !q.folded_pending.count(j.id)) {
      if (!acct) acct = query_sacct(ids);
      std::string ended = "no task queued or running (ended)";
      if (acct && acct->count(j.id)) {
        ended += "; sacct:";
        for (auto& [st, k] : acct->at(j.id)) ended += " " + st + " " + std::to_string(k);
      }
      std::printf("    queue: %s; run `capsim campaign collect`\n", ended.c_str());
      continue;
    }
    std::string line;
    for (auto& [st, k] : by) line += (line.empty() ? "" : ", ") + std::to_string(k) + " " + st;
    if (q.folded_pending.count(j.id)) line += (line.empty() ? "" : ", ") + std::string("more PENDING");
    std::printf("    queue: %s\n", line.c_str());
  }
}

}  // namespace capsim::campaign

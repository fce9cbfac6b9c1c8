#include "campaign/scheduler/campaign_runner.h"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <thread>

#include "campaign/analysis/multi_fidelity.h"
#include "campaign/analysis/refinement.h"
#include "campaign/analysis/uncertainty.h"
#include "campaign/analysis/transitions.h"
#include "campaign/common/bad_input.h"
#include "campaign/grid/campaign_spec.h"
#include "campaign/grid/decimal.h"
#include "campaign/grid/precision.h"
#include "campaign/scheduler/progress.h"
#include "campaign/scheduler/worker_process.h"
#include "campaign/store/store.h"
#include "solver/io/atomic_file.h"

namespace capsim::campaign {

namespace fs = std::filesystem;

namespace {

volatile sig_atomic_t g_stop_signal = 0;
volatile sig_atomic_t g_stop_count = 0;

void on_stop_signal(int sig) {
  g_stop_signal = sig;
  g_stop_count = g_stop_count + 1;
}

/// Installs SIGINT/SIGTERM handlers for the lifetime of a run and restores the old ones.
class SignalGuard {
 public:
  SignalGuard() {
    g_stop_signal = 0;
    g_stop_count = 0;
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
    struct sigaction ign {};
    ign.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &ign, &old_pipe_);
  }
  ~SignalGuard() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
    sigaction(SIGPIPE, &old_pipe_, nullptr);
  }

 private:
  struct sigaction old_int_ {}, old_term_ {}, old_pipe_ {};
};

struct Running {
  CaseRow row;
  std::int64_t attempt_id = 0;
  std::chrono::steady_clock::time_point start;
  double fraction_left = 1;  ///< of the whole case, when this attempt started (a resumed case has run part)
};

class Runner {
 public:
  Runner(const RunOptions& opt, Store& store, std::int64_t campaign_id, const std::string& name, int jobs, int threads,
         std::string runs_dir)
      : opt_(opt), store_(store), campaign_id_(campaign_id), progress_(name), jobs_(jobs), threads_(threads),
        runs_dir_(std::move(runs_dir)), worker_(opt.worker.empty() ? default_worker_executable() : opt.worker),
        host_(host_name()) {}

  /// The next round's cases, asked for when a worker is free (at the start and each time a case ends) and
  /// cases are still running or queued: called with those cases (the running and the queued), returns how
  /// many cases it added to the campaign (refine_campaign's top-up). New cases join the queue in --order.
  using TopUp = std::function<int(const std::vector<CaseParams>& unfinished)>;
  void set_top_up(TopUp top_up) { top_up_ = std::move(top_up); }
  /// Queue the coarser mesh levels first and, within a level, cell by cell (cells whose round has started,
  /// then by their queued work; --order within a cell): in a multi-fidelity campaign a scan case gates its
  /// cell's whole answer level, and a cell's next round waits for the last case of its round
  /// (order_by_level_and_cell).
  void set_coarse_levels_first(bool on) { coarse_levels_first_ = on; }
  /// A multi-fidelity campaign's answer level: the ETA then counts what refinement will still add to each
  /// cell (CellTally, EtaModel::remaining_s).
  void set_answer_level(int level) { tally_.emplace(level); }

  /// Runs every queued case of the campaign (and what the top-up adds meanwhile); returns false if stopped
  /// by a signal.
  bool run_queued() {
    learn_costs();
    started_cells_.clear();  // nothing runs yet
    auto rows = store_.campaign_cases(campaign_id_);
    tell_tally(rows);
    std::vector<CaseRow> pending = startable(rows);
    order(pending);
    total_ = static_cast<int>(rows.size());
    finished_ = failed_ = 0;
    for (auto& r : rows) {
      if (r.status == "done" || r.status == "unstable") ++finished_;
      if (r.status == "failed") ++failed_;
    }
    bool forwarded = false;
    bool top_up_due = true;  // asked again each time a worker ends (new results may let it add cases)
    std::chrono::steady_clock::time_point kill_deadline{};
    while (!pending.empty() || !running_.empty()) {
      if (g_stop_signal && !forwarded) {
        forwarded = true;
        progress_.message("capsim campaign: " + std::string(strsignal(g_stop_signal)) + ": stopping " +
                          std::to_string(running_.size()) + " worker(s) (they checkpoint); rerun to resume");
        for (auto& [pid, _] : running_) kill(pid, SIGTERM);
        kill_deadline = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                                std::chrono::duration<double>(opt_.grace_s));
      }
      if (forwarded && (g_stop_count > 1 || std::chrono::steady_clock::now() > kill_deadline)) {
        for (auto& [pid, _] : running_) kill(-pid, SIGKILL);
      }
      const std::size_t before = running_.size();
      reap();
      if (running_.size() < before) {
        top_up_due = true;
        close_rounds(pending);
      }
      if (top_up_ && top_up_due && !g_stop_signal && (!pending.empty() || !running_.empty()) &&
          static_cast<int>(running_.size()) < jobs_) {
        top_up_due = false;
        std::vector<CaseParams> unfinished;
        for (const auto& [_, r] : running_) unfinished.push_back(r.row.params);
        for (const auto& r : pending) unfinished.push_back(r.params);
        if (top_up_(unfinished) > 0) {
          rows = store_.campaign_cases(campaign_id_);
          tell_tally(rows);
          pending = startable(rows);  // the queue with the new cases, in --order
          order(pending);
          total_ = static_cast<int>(rows.size());
        }
      }
      while (!g_stop_signal && static_cast<int>(running_.size()) < jobs_ && !pending.empty()) {
        CaseRow row = std::move(pending.back());
        pending.pop_back();
        start(row);
      }
      queued_ = static_cast<int>(pending.size());
      progress_.show(counts(pending));
      if (g_stop_signal && running_.empty()) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
    }
    queued_ = static_cast<int>(pending.size());
    progress_.show(counts(pending), true);
    return g_stop_signal == 0;
  }

  void finish() { progress_.finish(); }
  void message(const std::string& m) { progress_.message(m); }
  int failed() const { return failed_; }
  int interrupted() const { return static_cast<int>(interrupted_.size()); }

 private:
  // The queued cases this run may start: not interrupted by it, not running.
  std::vector<CaseRow> startable(const std::vector<CaseRow>& rows) const {
    std::set<std::string> running_ids;
    for (const auto& [_, r] : running_) running_ids.insert(r.row.case_id);
    std::vector<CaseRow> out;
    for (const auto& r : rows)
      if (r.status == "queued" && !interrupted_.count(r.case_id) && !running_ids.count(r.case_id)) out.push_back(r);
    return out;
  }

  // The queue in the order of --order, the next case last (pop_back).
  void order(std::vector<CaseRow>& pending) {
    // longest first keeps the workers busy to the end of a campaign that finishes (the long cases do not
    // start last); shortest first completes the most answers per hour of one that will be interrupted.
    // Both by the work left: a case that resumes from a checkpoint at γ̇t = 30 of 40 is a quarter of a case
    // (an interrupted level-4 case is then finished first by `--order shortest`, not left behind whole ones).
    const bool by_work = opt_.order == "longest" || opt_.order == "shortest";
    // The whole case as the ETA predicts it (wall ∝ est^β per level), the estimate itself before any finished.
    std::map<std::string, double> left;
    if (by_work || coarse_levels_first_)
      for (const auto& r : pending) {
        const double whole = eta_.expected_s(r.params.mesh_level(), r.est_cost, est_below(r));
        left[r.case_id] = (whole >= 0 ? whole : r.est_cost) *
                          (r.resumable ? work_fraction_left(r.out_dir, r.params.t_end()) : 1.0);
      }
    if (by_work) {
      // Equal estimates are common (the stage count at rest is an integer): the smaller Ca counts as longer,
      // since its stiffness is the larger and the prestress of the run adds its next stage sooner.
      const auto longer = [&](const CaseRow& a, const CaseRow& b) {
        if (left[a.case_id] != left[b.case_id]) return left[a.case_id] > left[b.case_id];
        return a.params.capillary_number() < b.params.capillary_number();
      };
      const bool longest = opt_.order == "longest";
      std::stable_sort(pending.begin(), pending.end(),
                       [&](const CaseRow& a, const CaseRow& b) { return longest ? longer(a, b) : longer(b, a); });
    }
    if (coarse_levels_first_) order_by_level_and_cell(pending, left);
    std::reverse(pending.begin(), pending.end());  // pop_back = next case
  }

  // Multi-fidelity: the coarser levels first, since a scan case gates its cell's whole answer level. Within a
  // level the queue goes cell by cell, because refine_campaign releases a cell's next round only when none of
  // its cases runs or waits: a round is of no use to its cell's chain of rounds until its last case ends.
  // Longest first across cells scattered each round over the whole queue: in the main command (2 workers;
  // results/benchmarks.md, "The main command over time") the three cheap CaH cases of the Skalak a/b 0.5
  // cell's level-3 round (25–31 s) waited ≈ 11 min behind the other cells' long cases, and the rounds that
  // needed them (≈ 2–3 min of dependent cases) then ran alone at the end, one core idle for the last ≈ 215 s.
  // A worker idles only when nothing is queued and what is left waits for a running case of its own cell, so
  // the rule releases rounds as early as it can and starts the big ones early:
  //  1. cells whose round has started (started_cells_) first: finishing it releases the cell's next round, which
  //     then runs beside the other cells' cases; those cost the same later, whereas a started round left
  //     half-run delays its cell's whole chain (the scatter above, in small: a new round added by the top-up
  //     would otherwise go ahead of a started one with less left). A started cell goes first whatever its
  //     running cases still take: that time passes whatever is queued behind them, so it is not in the rank.
  //  2. then the most queued work first, from `left` whatever --order is (the best estimate of seconds: the ETA
  //     per level, a resumed case by what it has left; with `--order grid` too, so that grid chooses only the
  //     order within a cell): the queued work is what is known of a cell's chain (its later rounds are not),
  //     and a big round started last is the idle tail that longest first avoids for single cases. With
  //     `--order shortest` the least work first instead: that order is for a campaign that will be interrupted
  //     (a certified table's level-4 checks), and a cell's answer is complete only when all of its cases are.
  //  3. ties by cell key; within a cell, --order (the stable sort keeps the order it was given).
  // Plain campaigns (one level) keep --order alone.
  void order_by_level_and_cell(std::vector<CaseRow>& pending, const std::map<std::string, double>& left) const {
    std::map<std::string, std::string> cell;  // case id -> cell_key
    std::map<std::pair<int, std::string>, double> queued_work;  // (mesh level, cell) -> work left of its queued cases
    for (const auto& r : pending) {
      const std::string c = GroupKey::of(r.params).cell().str();
      cell[r.case_id] = c;
      queued_work[{r.params.mesh_level(), c}] += left.at(r.case_id);
    }
    const bool least_work_first = opt_.order == "shortest";
    std::stable_sort(pending.begin(), pending.end(), [&](const CaseRow& a, const CaseRow& b) {
      const int level_a = a.params.mesh_level(), level_b = b.params.mesh_level();
      if (level_a != level_b) return level_a < level_b;
      const std::string& cell_a = cell.at(a.case_id);
      const std::string& cell_b = cell.at(b.case_id);
      if (cell_a == cell_b) return false;
      const bool started_a = started_cells_.count(cell_a) > 0, started_b = started_cells_.count(cell_b) > 0;
      if (started_a != started_b) return started_a;
      const double work_a = queued_work.at({level_a, cell_a}), work_b = queued_work.at({level_b, cell_b});
      if (work_a != work_b) return least_work_first ? work_a < work_b : work_a > work_b;
      return cell_a < cell_b;
    });
  }

  // A cell's round ends when none of its cases runs or waits (refine_campaign may then add the next one, which
  // has not started): called after cases end, before the top-up.
  void close_rounds(const std::vector<CaseRow>& pending) {
    if (started_cells_.empty()) return;
    std::set<std::string> live;
    for (const auto& [_, r] : running_) live.insert(GroupKey::of(r.row.params).cell().str());
    for (const auto& r : pending) live.insert(GroupKey::of(r.params).cell().str());
    std::erase_if(started_cells_, [&](const std::string& c) { return live.count(c) == 0; });
  }

  ProgressCounts counts(const std::vector<CaseRow>& pending) const {
    ProgressCounts c;
    c.total = total_;
    c.finished = finished_;
    c.failed = failed_;
    c.running = static_cast<int>(running_.size());
    c.queued = queued_;
    std::vector<EtaModel::Work> work;
    work.reserve(pending.size() + running_.size());
    std::set<std::string> busy;  // multi-fidelity: the cells with a case running or waiting
    const auto cell = [&](const CaseRow& r) {
      if (!tally_) return std::string();
      const auto it = cell_of_.find(r.case_id);
      return *busy.insert(it != cell_of_.end() ? it->second : CellTally::cell_of(r.params)).first;
    };
    // A queued resumable case is counted whole: reading its checkpoint at every redraw is not worth it.
    for (const auto& r : pending)
      work.push_back({r.params.mesh_level(), r.est_cost, 1.0, false, 0.0, cell(r), est_below(r)});
    const auto now = std::chrono::steady_clock::now();
    for (const auto& [_, r] : running_)
      work.push_back({r.row.params.mesh_level(), r.row.est_cost, r.fraction_left, true,
                      std::chrono::duration<double>(now - r.start).count(), cell(r.row), est_below(r.row)});
    c.eta_s = tally_ ? eta_.remaining_s(work, jobs_, tally_->outlook(busy)) : eta_.remaining_s(work, jobs_);
    return c;
  }

  void start(CaseRow row) {
    if (coarse_levels_first_) started_cells_.insert(GroupKey::of(row.params).cell().str());
    row.out_dir = prepare_case_folder(row, runs_dir_);
    store_.set_case_folder(row.case_id, row.out_dir);
    const std::string toml = row.out_dir + "/case.toml";
    // Resumable, and its checkpoint is where it runs now (not when a copied database starts afresh).
    const bool resume = row.resumable && has_checkpoint(row.out_dir);
    WorkerCommand cmd;
    cmd.executable = worker_;
    cmd.args = worker_args(toml, row.out_dir, threads_, resume);
    cmd.stdout_path = row.out_dir + "/stdout.log";
    cmd.stderr_path = row.out_dir + "/stderr.log";
    cmd.threads = threads_;
    {
      std::ofstream err(cmd.stderr_path, std::ios::app);
      err << "=== capsim campaign: attempt " << row.attempts + 1 << (resume ? " (resume)" : "") << " on " << host_
          << " ===\n";
    }
    pid_t pid = spawn_worker(cmd);
    Running r;
    r.fraction_left = resume ? work_fraction_left(row.out_dir, row.params.t_end()) : 1.0;
    r.attempt_id = store_.mark_running(row.case_id, host_, pid, resume);
    r.row = std::move(row);
    r.start = std::chrono::steady_clock::now();
    running_.emplace(pid, std::move(r));
  }

  // The ETA learns from every finished case of the campaign (learn_eta), earlier runs included.
  void learn_costs() { eta_ = learn_eta(store_, campaign_id_, threads_); }

  // A case's estimate one mesh level coarser (the ETA carries the measured cost of that level to a level with no
  // finished case yet), computed once per case.
  double est_below(const CaseRow& r) const {
    auto it = est_below_.find(r.case_id);
    if (it == est_below_.end()) it = est_below_.emplace(r.case_id, r.params.estimated_cost_on_level(r.params.mesh_level() - 1)).first;
    return it->second;
  }

  // Tells the multi-fidelity tally the cases it has not seen: at the first call every case of the campaign,
  // then the batch a top-up or a refinement round added.
  void tell_tally(const std::vector<CaseRow>& rows) {
    if (!tally_) return;
    std::vector<std::pair<CaseParams, double>> batch;
    for (const auto& r : rows)
      if (!cell_of_.count(r.case_id)) {
        cell_of_.emplace(r.case_id, CellTally::cell_of(r.params));
        batch.emplace_back(r.params, r.est_cost);
      }
    if (!batch.empty()) tally_->add_batch(batch, !tallied_);
    tallied_ = true;
  }

  void reap() {
    while (true) {
      int st = 0;
      pid_t pid = waitpid(-1, &st, WNOHANG);
      if (pid <= 0) return;
      auto it = running_.find(pid);
      if (it == running_.end()) continue;
      Running r = std::move(it->second);
      running_.erase(it);
      WorkerOutcome out;
      out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - r.start).count();
      if (WIFEXITED(st)) out.exit_code = WEXITSTATUS(st);
      else if (WIFSIGNALED(st)) out.signal = WTERMSIG(st);
      out.last_line = last_line_of(r.row.out_dir + "/stdout.log");
      out.stderr_tail = tail_of(r.row.out_dir + "/stderr.log", 600);
      const std::string h5 = fs::exists(r.row.out_dir + "/case.h5") ? r.row.out_dir + "/case.h5" : "";
      const std::string status = store_.record_outcome(r.row.case_id, r.attempt_id, out, h5, r.row.params);
      if (status == "done" || status == "unstable") {
        ++finished_;
        learn_costs();
      } else if (status == "failed") {
        ++failed_;
        progress_.message("capsim campaign: case " + r.row.case_id + " (Ca=" +
                          canonical_double(r.row.params.capillary_number()) + ", a/b=" +
                          canonical_double(r.row.params.aspect_ratio()) + ", " + r.row.params.law() + ") failed: " +
                          (out.signal ? "signal " + std::to_string(out.signal) : "exit " + std::to_string(out.exit_code)));
      } else {
        interrupted_.insert(r.row.case_id);
      }
    }
  }

  const RunOptions& opt_;
  Store& store_;
  std::int64_t campaign_id_;
  Progress progress_;
  int jobs_, threads_;
  std::string runs_dir_, worker_, host_;
  std::map<pid_t, Running> running_;
  std::set<std::string> interrupted_;
  int total_ = 0, finished_ = 0, failed_ = 0, queued_ = 0;
  EtaModel eta_;  // per mesh level, wall seconds against estimated cost of the campaign's finished cases
  TopUp top_up_;  // empty: the queue is all there is until run_queued returns
  bool coarse_levels_first_ = false;
  std::set<std::string> started_cells_;  // multi-fidelity: the cells a case of whose current round has started
  std::optional<CellTally> tally_;        // multi-fidelity: what refinement will still add, per cell (the ETA's)
  std::map<std::string, std::string> cell_of_;  // case id -> its cell, for every case the tally has been told
  bool tallied_ = false;
  mutable std::map<std::string, double> est_below_;  // case id -> its estimate one level coarser (est_below)
};

/// After a manager crash: stop leftover workers, then ingest finished results or requeue.
void recover(Store& store, const std::string& runs_dir, const std::function<void(const std::string&)>& log) {
  // Only workers of cases this database has `running` (a local manager's) are orphans; a worker of a
  // Slurm array task on this host (its case is queued here) is left alone.
  std::set<std::string> running_dirs;
  for (const auto& row : store.running_cases()) running_dirs.insert(row.out_dir);
  auto orphans = running_dirs.empty() ? std::vector<pid_t>{} : find_orphan_workers(runs_dir, running_dirs);
  if (!orphans.empty()) {
    log("capsim campaign: stopping " + std::to_string(orphans.size()) +
                          " worker(s) left by an earlier manager");
    stop_processes(orphans, 60);
  }
  for (const auto& row : store.running_cases()) {
    const std::string line = last_line_of(row.out_dir + "/stdout.log");
    const std::string h5 = fs::exists(row.out_dir + "/case.h5") ? row.out_dir + "/case.h5" : "";
    const std::string status = store.recover_orphan(row.case_id, line, has_checkpoint(row.out_dir), h5, row.params);
    log("capsim campaign: case " + row.case_id + " was running when the manager stopped: " +
                          (status == "queued" ? "requeued" : "result ingested (" + status + ")"));
  }
}

}  // namespace

std::vector<Transition> analyse_campaign(Store& store, std::int64_t campaign_id, double d12_threshold,
                                         const std::string& method, const std::vector<int>& levels) {
  const auto groups = group_cases(store.campaign_samples(campaign_id));
  auto rows = analyse_groups(groups, d12_threshold, method);
  estimate_errors(rows, groups, ErrorOptions{levels});
  store.save_transitions(campaign_id, rows);
  return rows;
}

// The `method` column of the transitions: how the campaign chose its samples.
static std::string analysis_method(bool adaptive, bool multi_fidelity) {
  return multi_fidelity ? "multi-fidelity" : adaptive ? "adaptive" : "grid";
}

bool reanalyse_campaign(Store& store, std::int64_t campaign_id) {
  const auto spec_json = store.campaign_spec_json(campaign_id);
  if (!spec_json) return false;
  double threshold = 0.05;
  bool adaptive = false;
  std::vector<int> levels;
  try {
    auto j = nlohmann::json::parse(*spec_json);
    threshold = j.at("analysis").at("D12_threshold").get<double>();
    adaptive = j.at("analysis").value("adaptive", false);
    if (j.at("analysis").contains("levels")) levels = j.at("analysis").at("levels").get<std::vector<int>>();
  } catch (...) {
    // A spec from before these keys: the defaults (threshold 0.05, one level, grid).
  }
  analyse_campaign(store, campaign_id, threshold, analysis_method(adaptive, !levels.empty()), levels);
  return true;
}

int refine_campaign(Store& store, std::int64_t campaign_id, const CampaignSpec& spec, const std::string& runs_dir,
                    std::string* what, const std::vector<CaseParams>* unfinished,
                    std::map<std::string, int>* cell_rounds) {
  const int budget = spec.analysis.max_cases - store.count_campaign_cases(campaign_id, "adaptive");
  auto groups = group_cases(store.campaign_samples(campaign_id));
  std::vector<CaseParams> add;
  std::string phase = "adaptive refinement";
  if (!spec.analysis.levels.empty()) {
    // The phases of analysis/multi_fidelity.h, the first that has something to add.
    const auto& lv = spec.analysis.levels;
    const MultiFidelityOptions mf{lv, spec.analysis.d12_threshold, spec.analysis.ca_tolerance, spec.analysis.adaptive,
                                  spec.analysis.dt_check, spec.analysis.check_precision, spec.analysis.stop_for_answer};
    // A top-up while cases run or wait (Runner::set_top_up): the same phases for every cell once only check-level
    // cases are left (rounds_may_overlap); before that, for the cells none of whose cases runs or waits. A cell's
    // phases read only its own cases, so it takes the round it would take after a global barrier, only sooner:
    // the same cases, without a worker idling until the slowest cell's round ends.
    if (unfinished) {
      std::vector<int> levels;
      for (const auto& p : *unfinished) levels.push_back(p.mesh_level());
      if (!rounds_may_overlap(mf, levels)) {
        std::set<std::string> busy;
        for (const auto& p : *unfinished) busy.insert(GroupKey::of(p).cell().str());
        std::erase_if(groups, [&](const SampleGroup& g) { return busy.count(cell_key(g.key.group_key)) > 0; });
      }
    }
    // Each cell takes at most max_rounds answer-level rounds and two more (the dt check, the check level).
    if (cell_rounds)
      std::erase_if(groups, [&](const SampleGroup& g) {
        const auto it = cell_rounds->find(cell_key(g.key.group_key));
        return it != cell_rounds->end() && it->second >= spec.analysis.max_rounds + 2;
      });
    if (groups.empty()) return 0;
    add = answer_level_round(groups, mf, budget);
    phase = "multi-fidelity: level " + std::to_string(lv[1]) + " (seed, re-bracket" +
            (spec.analysis.adaptive ? ", refine)" : ")");
    // The dt check (answer level, one case per cell) before the check level: the check level's cases cost
    // hours and a campaign may be interrupted among them; its errors should have their dt part by then.
    if (add.empty() && spec.analysis.dt_check) {
      add = dt_check_cases(groups, mf, budget);
      phase = "multi-fidelity: dt/2 check on level " + std::to_string(lv[1]);
    }
    if (add.empty() && lv.size() > 2) {
      add = check_level_cases(groups, mf, budget);
      phase = "multi-fidelity: mesh check on level " + std::to_string(lv[2]);
    }
  } else {
    if (unfinished) return 0;  // the top-up is for multi-fidelity rounds only
    add = refinement_round(groups, spec.analysis.d12_threshold, spec.analysis.ca_tolerance, budget);
  }
  if (what) *what = phase;
  if (add.empty()) return 0;
  Transaction t(store.db());
  const int added = store.add_cases(campaign_id, add, "adaptive", runs_dir);
  t.commit();
  if (cell_rounds) {
    std::set<std::string> cells;
    for (const auto& p : add) cells.insert(GroupKey::of(p).cell().str());
    for (const auto& c : cells) ++(*cell_rounds)[c];
  }
  return added;
}

namespace {

/// The identities of the expanded grid under this build's solver version.
std::set<std::string> grid_identities(const std::vector<CaseParams>& cases) {
  const std::string version = solver_version();
  std::set<std::string> ids;
  for (const auto& p : cases) ids.insert(p.identity(version));
  return ids;
}

/// "neo-hookean a/b 2 Ca 0.35 level 4 (queued), …" for up to four cases, then "and N more".
std::string describe_cases(const std::vector<CaseRow>& rows) {
  std::string out;
  for (std::size_t i = 0; i < rows.size() && i < 4; ++i) {
    const auto& p = rows[i].params;
    out += (i ? ", " : "") + p.law() + " a/b " + canonical_double(p.aspect_ratio()) + " Ca " +
           canonical_double(p.capillary_number()) + " level " + std::to_string(p.mesh_level()) + " (" +
           rows[i].status + ")";
  }
  if (rows.size() > 4) out += " and " + std::to_string(rows.size() - 4) + " more";
  return out;
}

int dry_run(const RunOptions& opt, const CampaignSpec& spec, const std::vector<CaseParams>& cases) {
  std::unique_ptr<Store> store;
  if (fs::exists(opt.db_path)) store = Store::open_readonly(opt.db_path);
  const std::string version = solver_version();
  std::map<std::string, int> counts;
  std::printf("%-16s  %-11s  %-8s  %-6s  %-5s  %s\n", "case_id", "law", "a/b", "Ca", "level", "action");
  for (const auto& p : cases) {
    const std::string id = p.identity(version);
    std::string action = "run: new";
    if (store) {
      if (auto st = store->case_state(id)) {
        if (st->status == "done" || st->status == "unstable") action = "skip: " + st->status;
        else if (st->status == "failed") action = opt.retry_failed ? "run: retry failed (" + st->error.substr(0, 60) + ")"
                                                                   : "skip: failed (use --retry-failed)";
        else if (st->status == "running") action = "run: orphaned by a stopped manager (recovered first)";
        else if (st->resumable) action = "run: interrupted, resume from checkpoint";
        else if (st->attempts > 0) action = "run: interrupted, restart";
        else action = "run: queued";
      }
    }
    counts[action.substr(0, action.find(':'))]++;
    std::printf("%-16s  %-11s  %-8s  %-6s  %-5d  %s\n", id.c_str(), p.law().c_str(),
                canonical_double(p.aspect_ratio()).c_str(), canonical_double(p.capillary_number()).c_str(),
                p.mesh_level(), action.c_str());
  }
  int dropped = 0;
  if (store) {
    if (auto id = store->find_campaign(spec.name)) {
      for (const auto& r : store->stale_grid_cases(*id, grid_identities(cases))) {
        ++dropped;
        std::printf("%-16s  %-11s  %-8s  %-6s  %-5d  %s\n", r.case_id.c_str(), r.params.law().c_str(),
                    canonical_double(r.params.aspect_ratio()).c_str(),
                    canonical_double(r.params.capillary_number()).c_str(), r.params.mesh_level(),
                    ("unlink: no longer in the grid (" + r.status + "; stays in the database)").c_str());
      }
    }
  }
  std::printf("%zu cases: %d to run, %d to skip%s%s\n", cases.size(), counts["run"], counts["skip"],
              dropped ? (", " + std::to_string(dropped) + " to unlink").c_str() : "",
              spec.analysis.adaptive ? " (adaptive mode may add more)" : "");
  return kRunComplete;
}

}  // namespace

std::string default_runs_dir(const std::string& db_path) { return db_path + ".runs"; }

ManagerLock::ManagerLock(const std::string& db_path) : path_(db_path + ".lock") {
  fd_ = open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw BadInput(path_ + ": cannot create lock file: " + std::strerror(errno));
  if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    char buf[64] = {0};
    (void)!pread(fd_, buf, sizeof buf - 1, 0);
    close(fd_);
    fd_ = -1;
    throw BadInput(db_path + ": another campaign manager is running on this database (pid " +
                   std::string(buf[0] ? buf : "?") + ")");
  }
  std::string pid = std::to_string(getpid());
  (void)!ftruncate(fd_, 0);
  (void)!pwrite(fd_, pid.data(), pid.size(), 0);
}

ManagerLock::~ManagerLock() {
  if (fd_ >= 0) close(fd_);
}

void write_file_atomic(const std::string& path, const std::string& text) { io::write_text_atomically(path, text); }

std::string prepare_case_folder(const CaseRow& row, const std::string& runs_dir) {
  // The folder lives under the runs folder of this invocation; the stored one is reused only where it lies
  // there (the same --runs-dir as before). A copy of a database, or one moved to another machine, keeps the
  // absolute folders of the original: writing there would overwrite another campaign's files (and a live
  // worker's logs), so such a case gets a fresh folder here (a checkpoint left there is not used).
  std::string dir = runs_dir + "/" + row.case_id;
  if (!row.out_dir.empty()) {
    const fs::path base = fs::weakly_canonical(fs::absolute(runs_dir));
    const fs::path stored = fs::weakly_canonical(fs::absolute(row.out_dir));
    if (std::mismatch(base.begin(), base.end(), stored.begin(), stored.end()).first == base.end()) dir = row.out_dir;
  }
  fs::create_directories(dir);
  write_file_atomic(dir + "/case.toml", row.params.to_toml());
  return dir;
}

PreparedCampaign prepare_campaign(const RunOptions& opt, const std::function<void(const std::string&)>& log) {
  PreparedCampaign pc;
  pc.spec = load_campaign_file(opt.campaign_file);
  pc.cases = expand_grid(pc.spec);
  const fs::path db_dir = fs::absolute(opt.db_path).parent_path();
  if (!fs::is_directory(db_dir)) throw BadInput(opt.db_path + ": folder " + db_dir.string() + " does not exist");
  pc.lock = std::make_unique<ManagerLock>(opt.db_path);
  pc.store = Store::open_for_write(opt.db_path);
  pc.runs_dir =
      fs::weakly_canonical(fs::absolute(opt.runs_dir.empty() ? default_runs_dir(opt.db_path) : opt.runs_dir)).string();
  fs::create_directories(pc.runs_dir);
  {
    Transaction t(pc.store->db());
    pc.campaign_id = pc.store->upsert_campaign(pc.spec);
    pc.store->add_cases(pc.campaign_id, pc.cases, "grid", pc.runs_dir);
    pc.store->refresh_cost_estimates(pc.campaign_id);
    // The campaign is its file's grid plus what its analysis added: links an earlier version of the file made
    // (a value since removed from an axis) go, or the run would start cases the dry run does not list and the
    // analysis would read samples the file no longer asks for. The cases themselves stay in the database.
    const auto stale = pc.store->stale_grid_cases(pc.campaign_id, grid_identities(pc.cases));
    if (!stale.empty()) {
      std::vector<std::string> ids;
      for (const auto& r : stale) ids.push_back(r.case_id);
      pc.store->unlink_cases(pc.campaign_id, ids);
      log("capsim campaign: " + std::to_string(stale.size()) + " case(s) an earlier version of '" + pc.spec.name +
          "' linked are no longer in its grid (" + describe_cases(stale) +
          "): unlinked, not run and not analysed; their rows and results stay in the database");
    }
    if (opt.retry_failed) pc.store->requeue_failed(pc.campaign_id);
    t.commit();
  }
  recover(*pc.store, pc.runs_dir, log);
  return pc;
}

int run_campaign(const RunOptions& opt, const BeforeRun& before_run) {
  const CampaignSpec spec = load_campaign_file(opt.campaign_file);
  const std::vector<CaseParams> cases = expand_grid(spec);
  if (opt.order != "longest" && opt.order != "shortest" && opt.order != "grid")
    throw BadInput("--order: expected 'longest', 'shortest' or 'grid', got '" + opt.order + "'");
  if (opt.dry_run) return dry_run(opt, spec, cases);

  const int cores = std::max(1u, std::thread::hardware_concurrency());
  int jobs = opt.jobs, threads = opt.threads_per_job;
  if (jobs < 0 || threads < 0) throw BadInput("--jobs and --threads-per-job must be >= 1");
  if (jobs == 0 && threads == 0) threads = 1;
  if (jobs == 0) jobs = std::max(1, cores / threads);
  if (threads == 0) threads = std::max(1, cores / jobs);

  Runner* runner_ptr = nullptr;
  std::vector<std::string> early;  // messages before the progress display exists
  PreparedCampaign pc = prepare_campaign(opt, [&](const std::string& m) {
    if (runner_ptr) runner_ptr->message(m);
    else early.push_back(m);
  });
  if (before_run) before_run(*pc.store, pc.campaign_id);
  SignalGuard signals;
  auto& store = pc.store;
  const std::int64_t campaign_id = pc.campaign_id;
  const std::string& runs_dir = pc.runs_dir;
  Runner runner(opt, *store, campaign_id, spec.name, jobs, threads, runs_dir);
  runner_ptr = &runner;
  for (const auto& m : early) runner.message(m);
  runner.message("capsim campaign: '" + spec.name + "': " + std::to_string(cases.size()) + " grid cases, " +
                 std::to_string(jobs) + " job(s) x " + std::to_string(threads) + " thread(s), database " + opt.db_path);

  // Plain adaptive mode: at most max_rounds rounds. Multi-fidelity: max_rounds answer-level rounds and two more
  // (the dt check, the check level) per cell, counted in cell_rounds below; rounds_done only numbers the messages.
  const int rounds = spec.analysis.max_rounds;
  int rounds_done = 0;
  // Multi-fidelity: a free worker asks for the next round's cases instead of waiting for the round to end —
  // of the cells none of whose cases runs or waits, or of every cell once only check-level cases are left
  // (they take hours on level 4; rounds_may_overlap): a cell's seeds, bisections, dt check or check cases join
  // the queue in --order as soon as its own cases are done. The round limit is then per cell (cell_rounds).
  std::map<std::string, int> cell_rounds;
  const bool multi_fidelity = !spec.analysis.levels.empty();
  // Cells run ahead of each other, so a cell's scan case must not queue behind another cell's answer-level cases:
  // the coarser levels first. That alone did not shorten the main command's idle tail, the last cell's chain of
  // dependent rounds (results/benchmarks.md, "The main command over time"): longest first across cells had
  // spread that cell's round over the queue, and its next round waits for the round's last case. So within a
  // level the queue also goes cell by cell, a started round first, then the cells with the most queued work
  // (Runner::order).
  runner.set_coarse_levels_first(multi_fidelity);
  if (spec.analysis.levels.size() >= 2) runner.set_answer_level(spec.analysis.levels[1]);
  if (multi_fidelity)
    runner.set_top_up([&](const std::vector<CaseParams>& unfinished) {
      std::string what;
      const int added = refine_campaign(*store, campaign_id, spec, runs_dir, &what, &unfinished, &cell_rounds);
      if (added > 0) {
        ++rounds_done;
        runner.message("capsim campaign: round " + std::to_string(rounds_done) + ", " + what + ", while " +
                       std::to_string(unfinished.size()) + " case(s) run or wait: " + std::to_string(added) +
                       " case(s) added");
      }
      return added;
    });
  bool completed = runner.run_queued();
  const std::string method = analysis_method(spec.analysis.adaptive, multi_fidelity);
  if (completed && (spec.analysis.adaptive || multi_fidelity)) {
    while ((multi_fidelity || rounds_done < rounds) && completed) {
      std::string what;
      int added = refine_campaign(*store, campaign_id, spec, runs_dir, &what, nullptr,
                                  multi_fidelity ? &cell_rounds : nullptr);
      if (added == 0) break;
      ++rounds_done;
      runner.message(spec.analysis.levels.empty()
                         ? "capsim campaign: adaptive round " + std::to_string(rounds_done) + ": " +
                               std::to_string(added) + " case(s) added"
                         : "capsim campaign: round " + std::to_string(rounds_done) + ", " + what + ": " +
                               std::to_string(added) + " case(s) added");
      completed = runner.run_queued();
    }
  }
  runner.finish();
  analyse_campaign(*store, campaign_id, spec.analysis.d12_threshold, method, spec.analysis.levels);
  if (!spec.analysis.levels.empty()) {
    std::string cost = "capsim campaign: cases per mesh level (finished / linked, core-hours):";
    for (const auto& l : store->level_costs(campaign_id))
      cost += " level " + std::to_string(l.mesh_level) + " " + std::to_string(l.finished) + "/" +
              std::to_string(l.cases) + " (" + format_significant(l.core_s / 3600.0, 3) + " h);";
    std::fprintf(stderr, "%s\n", cost.c_str());
    if (spec.analysis.adaptive) {
      int saved = 0;
      for (const auto& t : store->transitions(campaign_id))
        if (t.role == "answer") saved += bisections_saved(t, spec.analysis.ca_tolerance);
      std::fprintf(stderr,
                   "capsim campaign: stopping each bracket at its numerical error saved %d answer-level case(s) "
                   "(the bisections down to ca_tolerance = %s)\n",
                   saved, format_significant(spec.analysis.ca_tolerance, 3).c_str());
    }
  }
  if (!completed) {
    std::fprintf(stderr, "capsim campaign: interrupted; the database is consistent. Rerun the same command to resume.\n");
    return kRunInterrupted;
  }
  if (runner.interrupted() > 0) {
    std::fprintf(stderr, "capsim campaign: %d case(s) were interrupted from outside; rerun to resume them\n",
                 runner.interrupted());
    return kRunInterrupted;
  }
  if (runner.failed() > 0) {
    std::fprintf(stderr, "capsim campaign: finished with %d failed case(s); see `capsim query cases --status failed "
                         "--db %s`, rerun with --retry-failed to retry\n", runner.failed(), opt.db_path.c_str());
    return kRunSomeFailed;
  }
  std::fprintf(stderr, "capsim campaign: complete\n");
  return kRunComplete;
}

}  // namespace capsim::campaign

#include "campaign/store/store.h"

#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <map>

#include <nlohmann/json.hpp>
#include <regex>
#include <variant>

#include "campaign/analysis/group_key.h"
#include "campaign/common/bad_input.h"
#include "campaign/common/exit_codes.h"
#include "capsim/schema_sql.h"
#include "capsim/version.h"
#include "solver/config/case_config.h"
#include "solver/config/case_keys.h"
#include "solver/driver/case_summary.h"

namespace capsim::campaign {

namespace {

constexpr std::int64_t kApplicationId = 1129336909;  // "CPSM", see schemas/001_campaign_v1.sql
const char* kNow = "strftime('%Y-%m-%dT%H:%M:%fZ','now')";

std::int64_t as_int(const std::optional<SqlValue>& v) {
  if (!v) return 0;
  if (auto* i = std::get_if<std::int64_t>(&*v)) return *i;
  return 0;
}

/// Reads the header pragmas; a non-database file fails here, before anything is written. Sets @p version
/// to the file's schema version (0 for a fresh file).
void verify_header(Db& db, bool& fresh, std::int64_t& file_version) {
  std::int64_t app = 0, version = 0, tables = 0;
  try {
    app = as_int(db.scalar("PRAGMA application_id"));
    version = as_int(db.scalar("PRAGMA user_version"));
    tables = as_int(db.scalar("SELECT count(*) FROM sqlite_master"));
  } catch (const DbError& e) {
    throw BadInput(db.path() + ": not a capsim database or corrupt (" + e.what() + ")");
  }
  fresh = (app == 0 && version == 0 && tables == 0);
  file_version = version;
  if (fresh) return;
  if (app != kApplicationId)
    throw BadInput(db.path() + ": not a capsim campaign database (application_id " + std::to_string(app) + ")");
  const int want = Store::expected_schema_version();
  if (version < Store::kOldestMigratableVersion || version > want)
    throw BadInput(db.path() + ": database schema version " + std::to_string(version) + ", this capsim (" +
                   std::string(kGitCommit) + ") reads versions " + std::to_string(Store::kOldestMigratableVersion) +
                   ".." + std::to_string(want) + "; use a matching capsim or a new --db file");
  std::string check;
  try {
    check = std::get<std::string>(db.scalar("PRAGMA quick_check").value_or(SqlValue{std::string("?")}));
  } catch (const std::exception& e) {
    throw BadInput(db.path() + ": database is corrupt (" + e.what() + ")");
  }
  if (check != "ok") throw BadInput(db.path() + ": database is corrupt (quick_check: " + check + ")");
}

}  // namespace

std::optional<nlohmann::json> parse_result_line(const std::string& line) {
  try {
    auto j = nlohmann::json::parse(line);
    const std::string status = driver::CaseSummary::from_json(j).status;  // the worker's summary, checked
    if (status != "done" && status != "unstable") return std::nullopt;
    return j;
  } catch (...) {
    return std::nullopt;
  }
}

namespace {
SqlValue real_or_null(double x) { return std::isfinite(x) ? SqlValue{x} : SqlValue{nullptr}; }
SqlValue jstr(const nlohmann::json& j, const char* k) {
  if (!j.contains(k) || !j[k].is_string()) return nullptr;
  return j[k].get<std::string>();
}
}  // namespace

std::string result_mismatch(const nlohmann::json& j, const CaseParams& p) {
  driver::CaseSummary s;
  try {
    s = driver::CaseSummary::from_json(j);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  // The case's parameters as the solver resolves them (CaseParameters::of, the one list of what a result must
  // echo): a key added to it (a viscosity ratio, an orientation) is checked here without a change.
  driver::CaseParameters expected;
  try {
    expected = driver::CaseParameters::of(config::parse_case_config(p.to_toml(), "case " + p.to_json()));
  } catch (const std::exception& e) {
    return e.what();
  }
  return driver::parameter_mismatch(s.parameters, expected);
}

void insert_result(Db& db, const std::string& case_id, const nlohmann::json& j, const std::string& line) {
  const driver::CaseSummary r = driver::CaseSummary::from_json(j);
  Stmt s(db, std::string("INSERT OR REPLACE INTO results(case_id,status,min_D12,max_tau_min,mean_D12,period,regime,"
                         "volume_drift,steps,dt,t_final,wall_s,code_version,raw_json,recorded_at) "
                         "VALUES(?,?,?,?,?,?,?,?,?,?,?,?,?,?,") + kNow + ")");
  s.bind(1, case_id).bind(2, r.status).bind(3, real_or_null(r.analysis.min_D12));
  s.bind(4, real_or_null(r.analysis.max_tau_min)).bind(5, real_or_null(r.analysis.mean_D12));
  s.bind(6, real_or_null(r.analysis.period)).bind(7, std::string(diagnostics::to_string(r.analysis.regime)));
  s.bind(8, real_or_null(r.volume_drift)).bind(9, std::int64_t{r.steps}).bind(10, real_or_null(r.dt));
  s.bind(11, real_or_null(r.t_final)).bind(12, real_or_null(r.wall_s));
  s.bind(13, r.code_version.empty() ? SqlValue{nullptr} : SqlValue{r.code_version}).bind(14, line);
  s.step();
}

std::string result_reason(const nlohmann::json& j) {
  try {
    if (auto reason = driver::CaseSummary::from_json(j).reason; !reason.empty()) return reason;
  } catch (const std::invalid_argument&) {
  }
  return "blow-up reported by the solver";
}

bool has_table(Db& db, const std::string& name) {
  Stmt s(db, "SELECT 1 FROM sqlite_master WHERE type='table' AND name=?");
  s.bind(1, name);
  return s.step();
}

bool has_column(Db& db, const std::string& table, const std::string& column) {
  Stmt s(db, "SELECT 1 FROM pragma_table_info(?) WHERE name=?");
  s.bind(1, table).bind(2, column);
  return s.step();
}

std::vector<Table> run_readonly_sql(Db& db, const std::string& text) {
  sqlite3* h = db.handle();
  struct Finalize {
    void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
  };
  std::vector<std::unique_ptr<sqlite3_stmt, Finalize>> stmts;
  const char* p = text.c_str();
  while (*p) {
    sqlite3_stmt* raw = nullptr;
    const char* tail = nullptr;
    if (sqlite3_prepare_v2(h, p, -1, &raw, &tail) != SQLITE_OK) throw BadInput(std::string("sql: ") + sqlite3_errmsg(h));
    p = tail;
    if (!raw) continue;  // whitespace or comment
    stmts.emplace_back(raw);
    if (!sqlite3_stmt_readonly(raw))
      throw BadInput(std::string("sql: refused, the database is opened read-only and this statement writes: ") +
                     sqlite3_sql(raw));
  }
  if (stmts.empty()) throw BadInput("sql: empty statement");
  std::vector<Table> out;
  for (auto& st : stmts) {
    sqlite3_stmt* raw = st.get();
    Table t;
    const int n = sqlite3_column_count(raw);
    for (int c = 0; c < n; ++c) t.columns.push_back(sqlite3_column_name(raw, c));
    int rc;
    while ((rc = sqlite3_step(raw)) == SQLITE_ROW) {
      std::vector<SqlValue> row;
      for (int c = 0; c < n; ++c) {
        switch (sqlite3_column_type(raw, c)) {
          case SQLITE_NULL: row.emplace_back(nullptr); break;
          case SQLITE_INTEGER: row.emplace_back(static_cast<std::int64_t>(sqlite3_column_int64(raw, c))); break;
          case SQLITE_FLOAT: row.emplace_back(sqlite3_column_double(raw, c)); break;
          default: {
            const unsigned char* x = sqlite3_column_text(raw, c);
            row.emplace_back(std::string(x ? reinterpret_cast<const char*>(x) : ""));
          }
        }
      }
      t.rows.push_back(std::move(row));
    }
    if (rc != SQLITE_DONE) throw BadInput(std::string("sql: ") + sqlite3_errmsg(h));
    if (n > 0) out.push_back(std::move(t));
  }
  return out;
}

namespace {
/// Collects the rows of a read-only statement.
Table read_table(Stmt& stmt) {
  Table t;
  for (int c = 0; c < stmt.columns(); ++c) t.columns.push_back(stmt.column_name(c));
  while (stmt.step()) {
    std::vector<SqlValue> row;
    for (int c = 0; c < stmt.columns(); ++c) row.push_back(stmt.column(c));
    t.rows.push_back(std::move(row));
  }
  return t;
}
}  // namespace

std::string host_name() {
  char buf[256] = {0};
  if (gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

int Store::expected_schema_version() {
  static const int v = [] {
    std::regex re(R"(PRAGMA\s+user_version\s*=\s*(\d+))", std::regex::icase);
    std::string sql = kSchemaSql;
    int found = 0;
    for (auto it = std::sregex_iterator(sql.begin(), sql.end(), re); it != std::sregex_iterator(); ++it)
      found = std::stoi((*it)[1]);
    return found;
  }();
  return v;
}

std::unique_ptr<Store> Store::open_for_write(const std::string& path) {
  struct stat st {};
  if (stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) throw BadInput(path + ": not a regular file");
  std::unique_ptr<Db> db;
  try {
    db = std::make_unique<Db>(path, false, true);
  } catch (const DbError& e) {
    throw BadInput(e.what());
  }
  bool fresh = false;
  std::int64_t version = 0;
  verify_header(*db, fresh, version);
  try {
    db->exec("PRAGMA journal_mode=WAL");
    db->exec("PRAGMA synchronous=NORMAL");
    db->exec("PRAGMA foreign_keys=ON");
    if (fresh) {
      Transaction t(*db);
      db->exec(kSchemaSql);
      Stmt s(*db, std::string("INSERT OR REPLACE INTO meta(key,value) VALUES('created_at',") + kNow +
                      "),('created_by',?),('schema_version',?)");
      s.bind(1, std::string(kGitCommit)).bind(2, std::to_string(expected_schema_version()));
      s.step();
      t.commit();
    } else if (version < expected_schema_version()) {
      // Migration: each schemas/NNN_*.sql above the file's version, in order, once (002 only adds tables;
      // 003 rebuilds `transitions` with its group key), all in one transaction.
      Transaction t(*db);
      for (const auto& part : kSchemaParts)
        if (part.version > version) db->exec(part.sql);
      Stmt s(*db, std::string("INSERT OR REPLACE INTO meta(key,value) VALUES('migrated_at',") + kNow +
                      "),('migrated_from',?),('migrated_by',?),('schema_version',?)");
      s.bind(1, std::to_string(version)).bind(2, std::string(kGitCommit));
      s.bind(3, std::to_string(expected_schema_version()));
      s.step();
      if (as_int(db->scalar("PRAGMA user_version")) != expected_schema_version())
        throw BadInput(path + ": migration from schema version " + std::to_string(version) + " failed");
      t.commit();
    }
  } catch (const DbError& e) {
    throw BadInput(e.what());
  }
  return std::unique_ptr<Store>(new Store(std::move(db)));
}

std::unique_ptr<Store> Store::open_readonly(const std::string& path) {
  if (access(path.c_str(), F_OK) != 0) throw BadInput(path + ": no such database file");
  std::unique_ptr<Db> db;
  try {
    db = std::make_unique<Db>(path, true, false);
  } catch (const DbError& e) {
    throw BadInput(e.what());
  }
  bool fresh = false;
  std::int64_t version = 0;
  verify_header(*db, fresh, version);
  if (fresh) throw BadInput(path + ": empty database (no campaign has been run into it)");
  db->exec("PRAGMA query_only=ON");
  return std::unique_ptr<Store>(new Store(std::move(db)));
}

std::int64_t Store::upsert_campaign(const CampaignSpec& spec) {
  Stmt s(*db_, std::string("INSERT INTO campaigns(name,description,source_path,spec_json,created_at,updated_at) "
                           "VALUES(?,?,?,?,") + kNow + "," + kNow + ") ON CONFLICT(name) DO UPDATE SET "
                           "description=excluded.description, source_path=excluded.source_path, "
                           "spec_json=excluded.spec_json, updated_at=excluded.updated_at");
  s.bind(1, spec.name).bind(2, spec.description).bind(3, spec.source).bind(4, spec.to_json());
  s.step();
  return *find_campaign(spec.name);
}

std::optional<std::int64_t> Store::find_campaign(const std::string& name) {
  Stmt s(*db_, "SELECT campaign_id FROM campaigns WHERE name=?");
  s.bind(1, name);
  if (!s.step()) return std::nullopt;
  return s.integer(0);
}

std::optional<std::string> Store::latest_campaign() {
  Stmt s(*db_, "SELECT name FROM campaigns ORDER BY updated_at DESC, campaign_id DESC LIMIT 1");
  if (!s.step()) return std::nullopt;
  return s.text(0);
}

int Store::add_cases(std::int64_t campaign_id, const std::vector<CaseParams>& cases, const std::string& origin,
                     const std::string& runs_dir) {
  const std::string version = solver_version();
  Stmt ins(*db_, std::string("INSERT OR IGNORE INTO cases(case_id,params_json,capillary_number,aspect_ratio,law,"
                             "skalak_C,mesh_level,solver_version,status,est_cost,created_at,out_dir) "
                             "VALUES(?,?,?,?,?,?,?,?,'queued',?,") + kNow + ",?)");
  Stmt link(*db_, "INSERT OR IGNORE INTO campaign_cases(campaign_id,case_id,origin) VALUES(?,?,?)");
  int linked = 0;
  for (const auto& p : cases) {
    const std::string id = p.identity(version);
    ins.reset();
    ins.bind(1, id).bind(2, p.to_json()).bind(3, p.capillary_number()).bind(4, p.aspect_ratio()).bind(5, p.law());
    ins.bind(6, p.law() == "neo-hookean" ? SqlValue{nullptr} : SqlValue{p.skalak_C()});
    ins.bind(7, std::int64_t{p.mesh_level()}).bind(8, version).bind(9, p.estimated_cost());
    ins.bind(10, runs_dir + "/" + id);
    ins.step();
    link.reset();
    link.bind(1, campaign_id).bind(2, id).bind(3, origin);
    link.step();
    linked += db_->changes();
  }
  return linked;
}

// The threads a finished case ran with (results.raw_json; 1 when the worker did not say), and its cost in
// core-seconds: the one definition of both for the queries below (macros: they join string literals).
#define CAPSIM_CASE_THREADS "coalesce(json_extract(r.raw_json, '$.threads'), 1)"
#define CAPSIM_CASE_CORE_S "r.wall_s * " CAPSIM_CASE_THREADS

int Store::refresh_cost_estimates(std::int64_t campaign_id) {
  std::vector<std::pair<std::string, double>> changed;
  {
    Stmt s(*db_,
           "SELECT c.case_id, c.params_json, c.est_cost FROM cases c JOIN campaign_cases cc ON cc.case_id=c.case_id "
           "WHERE cc.campaign_id=?");
    s.bind(1, campaign_id);
    while (s.step()) {
      double est = 0;
      try {
        est = CaseParams::from_json(s.text(1)).estimated_cost();
      } catch (const std::exception&) {
        continue;  // a case today's parser no longer reads keeps its stored estimate (it is only an order)
      }
      if (est != s.real(2).value_or(0.0)) changed.emplace_back(s.text(0), est);
    }
  }
  Stmt upd(*db_, "UPDATE cases SET est_cost=? WHERE case_id=?");
  for (const auto& [id, est] : changed) {
    upd.reset();
    upd.bind(1, est).bind(2, id);
    upd.step();
  }
  return static_cast<int>(changed.size());
}

namespace {
const char* kCaseCols =
    "c.case_id,c.params_json,c.status,c.resumable,c.attempts,c.est_cost,c.out_dir,coalesce(c.host,''),"
    "coalesce(c.worker_pid,0),coalesce(c.error,'')";
CaseRow read_case(const Stmt& s) {
  CaseRow r;
  r.case_id = s.text(0);
  r.params = CaseParams::from_json(s.text(1));
  r.status = s.text(2);
  r.resumable = s.integer(3) != 0;
  r.attempts = static_cast<int>(s.integer(4));
  r.est_cost = s.real(5).value_or(1.0);
  r.out_dir = s.text(6);
  r.host = s.text(7);
  r.worker_pid = s.integer(8);
  r.error = s.text(9);
  return r;
}
}  // namespace

std::vector<CaseRow> Store::stale_grid_cases(std::int64_t campaign_id, const std::set<std::string>& grid_ids) {
  Stmt s(*db_, std::string("SELECT ") + kCaseCols +
                   " FROM cases c JOIN campaign_cases cc ON cc.case_id=c.case_id WHERE cc.campaign_id=? "
                   "AND cc.origin='grid' ORDER BY c.case_id");
  s.bind(1, campaign_id);
  std::vector<CaseRow> out;
  while (s.step())
    if (!grid_ids.count(s.text(0))) out.push_back(read_case(s));
  return out;
}

int Store::unlink_cases(std::int64_t campaign_id, const std::vector<std::string>& case_ids) {
  Stmt del(*db_, "DELETE FROM campaign_cases WHERE campaign_id=? AND case_id=?");
  int n = 0;
  for (const auto& id : case_ids) {
    del.reset();
    del.bind(1, campaign_id).bind(2, id);
    del.step();
    n += db_->changes();
  }
  return n;
}

std::vector<CaseRow> Store::campaign_cases(std::int64_t campaign_id) {
  Stmt s(*db_, std::string("SELECT ") + kCaseCols +
                   " FROM cases c JOIN campaign_cases cc ON cc.case_id=c.case_id WHERE cc.campaign_id=? "
                   "ORDER BY c.law, c.aspect_ratio, c.skalak_C, c.mesh_level, c.capillary_number");
  s.bind(1, campaign_id);
  std::vector<CaseRow> out;
  while (s.step()) out.push_back(read_case(s));
  return out;
}

std::optional<CaseState> Store::case_state(const std::string& case_id) {
  Stmt s(*db_, "SELECT status, resumable, attempts, coalesce(error,'') FROM cases WHERE case_id=?");
  s.bind(1, case_id);
  if (!s.step()) return std::nullopt;
  return CaseState{s.text(0), s.integer(1) != 0, static_cast<int>(s.integer(2)), s.text(3)};
}

std::vector<CaseRow> Store::running_cases() {
  Stmt s(*db_, std::string("SELECT ") + kCaseCols + " FROM cases c WHERE c.status='running'");
  std::vector<CaseRow> out;
  while (s.step()) out.push_back(read_case(s));
  return out;
}

std::optional<FinishedCase> Store::finished_case(const std::string& case_id) {
  Stmt s(*db_, "SELECT c.case_id, c.status, c.params_json, c.solver_version, r.raw_json, coalesce(c.out_dir,''), "
               "coalesce(c.h5_path,''), coalesce(" CAPSIM_CASE_CORE_S ", 0) FROM cases c JOIN results r ON "
               "r.case_id=c.case_id WHERE c.case_id=? AND c.status IN ('done','unstable')");
  s.bind(1, case_id);
  if (!s.step()) return std::nullopt;
  return FinishedCase{s.text(0), s.text(1), s.text(2), s.text(3), s.text(4), s.text(5), s.text(6),
                      s.real(7).value_or(0.0)};
}

bool Store::import_result(const FinishedCase& from, const std::string& out_dir, const std::string& h5_path,
                          const std::string& source) {
  const auto j = parse_result_line(from.raw_json);
  if (!j) throw BadInput(source + ": case " + from.case_id + " has no complete result line");
  Transaction t(*db_);
  {
    Stmt q(*db_, "SELECT status FROM cases WHERE case_id=?");
    q.bind(1, from.case_id);
    if (!q.step()) return false;
    const std::string st = q.text(0);
    if (st != "queued" && st != "failed") return false;
  }
  insert_result(*db_, from.case_id, *j, from.raw_json);
  const std::string status = (*j)["status"].get<std::string>();
  Stmt u(*db_, std::string("UPDATE cases SET status=?, resumable=0, finished_at=") + kNow +
                   ", wall_s=(SELECT wall_s FROM results WHERE case_id=?), exit_code=0, "
                   "code_version=coalesce(?,code_version), error=?, out_dir=coalesce(?,out_dir), h5_path=? WHERE case_id=?");
  u.bind(1, status).bind(2, from.case_id).bind(3, jstr(*j, "code_version"));
  u.bind(4, status == "unstable" ? SqlValue{result_reason(*j)} : SqlValue{nullptr});
  u.bind(5, out_dir.empty() ? SqlValue{nullptr} : SqlValue{out_dir});
  u.bind(6, h5_path.empty() ? SqlValue{nullptr} : SqlValue{h5_path}).bind(7, from.case_id);
  u.step();
  Stmt a(*db_, std::string("INSERT INTO attempts(case_id,started_at,finished_at,host,outcome,exit_code,error) "
                           "VALUES(?,") + kNow + "," + kNow + ",?,'imported',0,?)");
  a.bind(1, from.case_id).bind(2, host_name()).bind(3, "imported from " + source);
  a.step();
  t.commit();
  return true;
}

void Store::set_case_folder(const std::string& case_id, const std::string& out_dir) {
  Stmt u(*db_, "UPDATE cases SET out_dir=? WHERE case_id=? AND out_dir IS NOT ?");
  u.bind(1, out_dir).bind(2, case_id).bind(3, out_dir);
  u.step();
}

std::int64_t Store::mark_running(const std::string& case_id, const std::string& host, std::int64_t pid,
                                 bool resumed) {
  Transaction t(*db_);
  Stmt u(*db_, std::string("UPDATE cases SET status='running', attempts=attempts+1, started_at=") + kNow +
                   ", finished_at=NULL, exit_code=NULL, host=?, worker_pid=? WHERE case_id=?");
  u.bind(1, host).bind(2, pid).bind(3, case_id);
  u.step();
  Stmt a(*db_, std::string("INSERT INTO attempts(case_id,started_at,host,worker_pid,resumed) VALUES(?,") + kNow +
                   ",?,?,?)");
  a.bind(1, case_id).bind(2, host).bind(3, pid).bind(4, std::int64_t{resumed ? 1 : 0});
  a.step();
  std::int64_t id = sqlite3_last_insert_rowid(db_->handle());
  t.commit();
  return id;
}

std::string Store::record_outcome(const std::string& case_id, std::int64_t attempt_id, const WorkerOutcome& out,
                                  const std::string& h5_path, const CaseParams& params) {
  std::string status, outcome, error;
  bool resumable = false;
  std::optional<nlohmann::json> j;
  if (out.signal == 0 && out.exit_code == 0) {
    j = parse_result_line(out.last_line);
    if (!j) {
      status = outcome = "failed";
      error = "worker exited 0 without a JSON result line (status done|unstable) on stdout; stderr: " + out.stderr_tail;
    } else if (auto m = result_mismatch(*j, params); !m.empty()) {
      status = outcome = "failed";
      error = "worker reported parameters that differ from the case: " + m;
      j.reset();
    } else {
      status = outcome = (*j)["status"].get<std::string>();
      if (status == "unstable") error = result_reason(*j);
    }
  } else if (out.signal == 0 && out.exit_code == kExitInterrupted && parse_result_line(out.last_line) &&
             result_mismatch(*parse_result_line(out.last_line), params).empty()) {
    // Interrupted after the result was printed: the result stands.
    j = parse_result_line(out.last_line);
    status = outcome = (*j)["status"].get<std::string>();
    if (status == "unstable") error = result_reason(*j);
  } else if (out.signal == 0 && out.exit_code == kExitInterrupted) {
    status = "queued";
    outcome = "interrupted";
    resumable = true;
    error = "interrupted (checkpoint written; resumes with --resume)";
  } else {
    status = outcome = "failed";
    error = out.signal ? "worker killed by signal " + std::to_string(out.signal) + " (" + strsignal(out.signal) + ")"
                       : "worker exited with code " + std::to_string(out.exit_code) + describe_exit_code(out.exit_code);
    if (!out.stderr_tail.empty()) error += "; stderr: " + out.stderr_tail;
  }
  Transaction t(*db_);
  if (j) insert_result(*db_, case_id, *j, out.last_line);
  Stmt u(*db_, std::string("UPDATE cases SET status=?, resumable=?, finished_at=") + kNow +
                   ", wall_s=?, exit_code=?, code_version=coalesce(?,code_version), error=?, h5_path=? WHERE case_id=?");
  u.bind(1, status).bind(2, std::int64_t{resumable ? 1 : 0}).bind(3, out.wall_s);
  u.bind(4, out.signal ? SqlValue{std::int64_t{-out.signal}} : SqlValue{std::int64_t{out.exit_code}});
  u.bind(5, j ? jstr(*j, "code_version") : SqlValue{nullptr});
  u.bind(6, error.empty() ? SqlValue{nullptr} : SqlValue{error});
  u.bind(7, h5_path.empty() ? SqlValue{nullptr} : SqlValue{h5_path}).bind(8, case_id);
  u.step();
  Stmt a(*db_, std::string("UPDATE attempts SET finished_at=") + kNow + ", outcome=?, exit_code=?, error=? WHERE attempt_id=?");
  a.bind(1, outcome).bind(2, out.signal ? SqlValue{std::int64_t{-out.signal}} : SqlValue{std::int64_t{out.exit_code}});
  a.bind(3, error.empty() ? SqlValue{nullptr} : SqlValue{error}).bind(4, attempt_id);
  a.step();
  t.commit();
  return status;
}

std::string Store::recover_orphan(const std::string& case_id, const std::string& result_line, bool resumable,
                                  const std::string& h5_path, const CaseParams& params) {
  auto j = parse_result_line(result_line);
  if (j && !result_mismatch(*j, params).empty()) j.reset();
  Transaction t(*db_);
  std::string status;
  if (j) {
    status = (*j)["status"].get<std::string>();
    insert_result(*db_, case_id, *j, result_line);
    Stmt u(*db_, std::string("UPDATE cases SET status=?, resumable=0, finished_at=") + kNow +
                     ", exit_code=0, code_version=coalesce(?,code_version), error=?, h5_path=? WHERE case_id=?");
    u.bind(1, status).bind(2, jstr(*j, "code_version"));
    u.bind(3, status == "unstable" ? SqlValue{result_reason(*j)} : SqlValue{nullptr});
    u.bind(4, h5_path.empty() ? SqlValue{nullptr} : SqlValue{h5_path}).bind(5, case_id);
    u.step();
  } else {
    status = "queued";
    Stmt u(*db_, "UPDATE cases SET status='queued', resumable=?, error=? WHERE case_id=?");
    u.bind(1, std::int64_t{resumable ? 1 : 0});
    u.bind(2, std::string("manager stopped while this case ran") + (resumable ? "; resumes from its checkpoint" : ""));
    u.bind(3, case_id);
    u.step();
  }
  Stmt a(*db_, std::string("UPDATE attempts SET finished_at=") + kNow +
                   ", outcome=? WHERE case_id=? AND finished_at IS NULL");
  a.bind(1, std::string(j ? "ingested" : "orphaned")).bind(2, case_id);
  a.step();
  t.commit();
  return status;
}

int Store::requeue_failed(std::int64_t campaign_id) {
  Stmt s(*db_, "UPDATE cases SET status='queued', resumable=0 WHERE status='failed' AND case_id IN "
               "(SELECT case_id FROM campaign_cases WHERE campaign_id=?)");
  s.bind(1, campaign_id);
  s.step();
  return db_->changes();
}

void Store::save_transitions(std::int64_t campaign_id, const std::vector<Transition>& rows) {
  Transaction t(*db_);
  Stmt d(*db_, "DELETE FROM transitions WHERE campaign_id=?");
  d.bind(1, campaign_id);
  d.step();
  Stmt s(*db_, std::string("INSERT INTO transitions(campaign_id,group_key,law,aspect_ratio,skalak_C,mesh_level,"
                           "d12_threshold,n_samples,ca_star_low,ca_star_high,ca_star_below,ca_star_above,ca_min_d12,"
                           "ca_h,ca_h_low,ca_h_high,ca_h_low_case,ca_h_high_case,method,note,role,ca_star_low_err,"
                           "ca_star_high_err,ca_h_err,ca_star_low_err_source,ca_star_high_err_source,ca_h_err_source,"
                           "error_levels,error_note,level_answers,ca_star_low_err_lacks,ca_star_high_err_lacks,"
                           "ca_h_err_lacks,ca_ts_low,ca_ts_high,ca_ts_note,updated_at) "
                           "VALUES(?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,") + kNow + ")");
  auto opt_text = [](const std::string& x) { return x.empty() ? SqlValue{nullptr} : SqlValue{x}; };
  for (const auto& r : rows) {
    s.reset();
    s.bind(1, campaign_id).bind(2, r.group_key).bind(3, r.law).bind(4, r.aspect_ratio).bind(5, r.skalak_C);
    s.bind(6, std::int64_t{r.mesh_level}).bind(7, r.d12_threshold).bind(8, std::int64_t{r.n_samples});
    s.bind_opt(9, r.ca_star_low).bind_opt(10, r.ca_star_high).bind_opt(11, r.ca_star_below);
    s.bind_opt(12, r.ca_star_above).bind_opt(13, r.ca_min_d12).bind_opt(14, r.ca_h).bind_opt(15, r.ca_h_low);
    s.bind_opt(16, r.ca_h_high).bind(17, opt_text(r.ca_h_low_case)).bind(18, opt_text(r.ca_h_high_case));
    s.bind(19, r.method).bind(20, r.note).bind(21, r.role).bind_opt(22, r.ca_star_low_err);
    s.bind_opt(23, r.ca_star_high_err).bind_opt(24, r.ca_h_err).bind(25, opt_text(r.ca_star_low_err_source));
    s.bind(26, opt_text(r.ca_star_high_err_source)).bind(27, opt_text(r.ca_h_err_source));
    s.bind(28, opt_text(r.error_levels)).bind(29, r.error_note);
    s.bind(30, opt_text(level_answers_json(r.level_answers)));
    s.bind(31, opt_text(r.ca_star_low_err_lacks)).bind(32, opt_text(r.ca_star_high_err_lacks));
    s.bind(33, opt_text(r.ca_h_err_lacks));
    s.bind_opt(34, r.ca_ts_low).bind_opt(35, r.ca_ts_high).bind(36, opt_text(r.ca_ts_note));
    s.step();
  }
  t.commit();
}

std::vector<CaseSample> Store::campaign_samples(std::int64_t campaign_id) {
  Stmt s(*db_,
         "SELECT c.case_id, c.params_json, c.status, r.min_D12, r.max_tau_min, "
         "json_extract(r.raw_json, '$.min_D12_period_spread'), json_extract(r.raw_json, '$.max_tau_min_period_spread'), "
         "r.dt, coalesce(r.regime,'') FROM cases c JOIN campaign_cases cc ON cc.case_id=c.case_id "
         "LEFT JOIN results r ON r.case_id=c.case_id "
         "WHERE cc.campaign_id=? ORDER BY c.law, c.aspect_ratio, coalesce(c.skalak_C,-1), c.mesh_level, "
         "c.capillary_number");
  s.bind(1, campaign_id);
  std::vector<CaseSample> out;
  while (s.step())
    out.push_back({s.text(0), CaseParams::from_json(s.text(1)), s.text(2), s.real(3), s.real(4), s.real(5), s.real(6),
                   s.real(7), s.text(8)});
  return out;
}

std::vector<Transition> Store::transitions(std::int64_t campaign_id, int mesh_level, double skalak_C) {
  const bool grouped = has_column(*db_, "transitions", "group_key");
  const bool with_errors = has_column(*db_, "transitions", "role");  // schema 4
  const bool with_level_answers = has_column(*db_, "transitions", "level_answers");  // schema 5
  const bool with_lacks = has_column(*db_, "transitions", "ca_h_err_lacks");           // schema 6
  const bool with_ts = has_column(*db_, "transitions", "ca_ts_low");                    // schema 7
  Stmt s(*db_, std::string("SELECT ") + (grouped ? "group_key" : "''") +
                   ", law, aspect_ratio, skalak_C, mesh_level, d12_threshold, n_samples, ca_star_low, ca_star_high, "
                   "ca_star_below, ca_star_above, ca_min_d12, ca_h, ca_h_low, ca_h_high, coalesce(ca_h_low_case,''), "
                   "coalesce(ca_h_high_case,''), method, note, " +
                   (with_errors ? "role, ca_star_low_err, ca_star_high_err, ca_h_err, coalesce(ca_star_low_err_source,''), "
                                  "coalesce(ca_star_high_err_source,''), coalesce(ca_h_err_source,''), "
                                  "coalesce(error_levels,''), error_note"
                                : "'answer', NULL, NULL, NULL, '', '', '', '', ''") +
                   (with_level_answers ? ", coalesce(level_answers,'')" : ", ''") +
                   (with_lacks ? ", coalesce(ca_star_low_err_lacks,''), coalesce(ca_star_high_err_lacks,''), "
                                 "coalesce(ca_h_err_lacks,'')"
                               : ", '', '', ''") +
                   (with_ts ? ", ca_ts_low, ca_ts_high, coalesce(ca_ts_note,'')" : ", NULL, NULL, ''") +
                   " FROM transitions WHERE campaign_id=?1 "
                   "AND (?2 < 0 OR mesh_level = ?2) AND (?3 < -0.5 OR skalak_C = ?3 OR law='neo-hookean') "
                   "ORDER BY law, aspect_ratio, mesh_level DESC, 1");
  s.bind(1, campaign_id).bind(2, std::int64_t{mesh_level}).bind(3, skalak_C);
  std::vector<Transition> out;
  while (s.step()) {
    Transition t;
    t.group_key = s.text(0);
    t.law = s.text(1);
    t.aspect_ratio = *s.real(2);
    t.skalak_C = *s.real(3);
    t.mesh_level = static_cast<int>(s.integer(4));
    t.d12_threshold = *s.real(5);
    t.n_samples = static_cast<int>(s.integer(6));
    t.ca_star_low = s.real(7);
    t.ca_star_high = s.real(8);
    t.ca_star_below = s.real(9);
    t.ca_star_above = s.real(10);
    t.ca_min_d12 = s.real(11);
    t.ca_h = s.real(12);
    t.ca_h_low = s.real(13);
    t.ca_h_high = s.real(14);
    t.ca_h_low_case = s.text(15);
    t.ca_h_high_case = s.text(16);
    t.method = s.text(17);
    t.note = s.text(18);
    t.role = s.text(19);
    t.ca_star_low_err = s.real(20);
    t.ca_star_high_err = s.real(21);
    t.ca_h_err = s.real(22);
    t.ca_star_low_err_source = s.text(23);
    t.ca_star_high_err_source = s.text(24);
    t.ca_h_err_source = s.text(25);
    t.error_levels = s.text(26);
    t.error_note = s.text(27);
    t.level_answers = level_answers_from_json(s.text(28));
    t.ca_star_low_err_lacks = s.text(29);
    t.ca_star_high_err_lacks = s.text(30);
    t.ca_h_err_lacks = s.text(31);
    t.ca_ts_low = s.real(32);
    t.ca_ts_high = s.real(33);
    t.ca_ts_note = s.text(34);
    out.push_back(std::move(t));
  }
  return out;
}

std::optional<std::string> Store::campaign_spec_json(std::int64_t campaign_id) {
  Stmt s(*db_, "SELECT spec_json FROM campaigns WHERE campaign_id=?");
  s.bind(1, campaign_id);
  if (!s.step()) return std::nullopt;
  return s.text(0);
}

std::vector<CampaignInfo> Store::campaigns(const std::string& name) {
  Stmt s(*db_, "SELECT campaign_id, name, updated_at FROM campaigns WHERE (?1 = '' OR name = ?1) ORDER BY campaign_id");
  s.bind(1, name);
  std::vector<CampaignInfo> out;
  while (s.step()) out.push_back({s.integer(0), s.text(1), s.text(2)});
  return out;
}

StatusCounts Store::status_counts(std::int64_t campaign_id) {
  Stmt s(*db_, "SELECT c.status, count(*), sum(cc.origin='adaptive') FROM cases c JOIN campaign_cases cc "
               "ON cc.case_id=c.case_id WHERE cc.campaign_id=? GROUP BY c.status");
  s.bind(1, campaign_id);
  StatusCounts n;
  while (s.step()) {
    n.by_status[s.text(0)] = s.integer(1);
    n.total += s.integer(1);
    n.adaptive += s.integer(2);
  }
  return n;
}

std::vector<ProblemCase> Store::problem_cases(std::int64_t campaign_id, int limit) {
  Stmt s(*db_, "SELECT c.case_id, c.law, c.aspect_ratio, c.capillary_number, c.status, "
               "coalesce(c.error,''), c.mesh_level, c.params_json, coalesce(c.out_dir,'') FROM cases c JOIN campaign_cases cc "
               "ON cc.case_id=c.case_id "
               "WHERE cc.campaign_id=? AND (c.status IN ('failed','unstable','running') OR "
               "(c.status='queued' AND c.attempts>0)) ORDER BY c.status, c.law, c.aspect_ratio, "
               "c.capillary_number LIMIT ?");
  s.bind(1, campaign_id).bind(2, std::int64_t{limit});
  std::vector<ProblemCase> out;
  while (s.step()) {
    ProblemCase p;
    p.case_id = s.text(0);
    p.law = s.text(1);
    p.aspect_ratio = *s.real(2);
    p.capillary_number = *s.real(3);
    p.status = s.text(4);
    p.error = s.text(5);
    p.mesh_level = static_cast<int>(s.integer(6));
    const CaseParams params = CaseParams::from_json(s.text(7));
    p.group_key = GroupKey::of(params).str();
    p.out_dir = s.text(8);
    p.t_end = params.t_end();
    out.push_back(std::move(p));
  }
  return out;
}

Table Store::cases_table(const CaseFilter& f) {
  Stmt s(*db_,
         "SELECT c.case_id, c.law, c.aspect_ratio, c.skalak_C, c.mesh_level, c.capillary_number, c.status, "
         "c.attempts, r.min_D12, r.max_tau_min, r.mean_D12, r.period, r.regime, r.volume_drift, r.steps, "
         "r.dt, r.t_final, coalesce(r.wall_s, c.wall_s) AS wall_s, "
         "json_extract(r.raw_json, '$.flow_evaluations') AS flow_evaluations, "
         "CASE WHEN r.case_id IS NULL THEN NULL ELSE " CAPSIM_CASE_THREADS " END AS threads, "
         CAPSIM_CASE_CORE_S " AS core_s, "
         "c.code_version, c.error, c.h5_path, c.params_json AS params, c.out_dir, r.raw_json AS summary, "
         // λ: stored in params only where set (a case key at its default is left out of the identity).
         "coalesce(json_extract(c.params_json, '$.\"flow.viscosity_ratio\"'), ?7) AS viscosity_ratio, "
         "json_extract(r.raw_json, '$.gmres_iterations_mean') AS gmres_iterations_mean, "
         // The initial orientation (stored in params only where set, as λ) and what the axis ended doing.
         "coalesce(json_extract(c.params_json, '$.\"capsule.tilt\"'), ?9) AS tilt, "
         "coalesce(json_extract(c.params_json, '$.\"capsule.azimuth\"'), ?10) AS azimuth, "
         "json_extract(r.raw_json, '$.final_tilt') AS final_tilt, "
         "json_extract(r.raw_json, '$.tilt_growth_rate') AS tilt_growth_rate, "
         "json_extract(r.raw_json, '$.tilt_growth_rate_error') AS tilt_growth_rate_error, "
         "json_extract(r.raw_json, '$.final_spin_rate') AS final_spin_rate "
         "FROM cases c LEFT JOIN results r ON r.case_id=c.case_id "
         "WHERE (?1 = '' OR c.case_id IN (SELECT cc.case_id FROM campaign_cases cc JOIN campaigns k "
         "ON k.campaign_id=cc.campaign_id WHERE k.name=?1)) "
         "AND (?2 = '' OR c.law = ?2) AND (?3 <= 0 OR abs(c.aspect_ratio - ?3) < 1e-12) "
         "AND c.capillary_number >= ?4 AND c.capillary_number <= ?5 AND (?6 = '' OR c.status = ?6) "
         "AND (?8 <= 0 OR abs(coalesce(json_extract(c.params_json, '$.\"flow.viscosity_ratio\"'), ?7) - ?8) "
         "<= 1e-12 * ?8) "
         "ORDER BY c.law, c.aspect_ratio, c.skalak_C, viscosity_ratio, c.mesh_level, c.capillary_number");
  const double lambda_default = GroupKey::parse("{}")->viscosity_ratio();  // the key registry's default
  s.bind(1, f.campaign).bind(2, f.law).bind(3, f.aspect_ratio).bind(4, f.ca_min).bind(5, f.ca_max).bind(6, f.status);
  s.bind(7, lambda_default).bind(8, f.viscosity_ratio);
  // The orientation keys' defaults, from the key registry (a case at its default leaves the key out of params).
  auto key_default = [](const char* name) { return std::get<double>(config::find_case_key(name)->default_value); };
  s.bind(9, key_default("capsule.tilt")).bind(10, key_default("capsule.azimuth"));
  Table t = read_table(s);
  t.json_columns = {"summary"};
  return t;
}

int Store::count_campaign_cases(std::int64_t campaign_id, const std::string& origin) {
  Stmt s(*db_, "SELECT count(*) FROM campaign_cases WHERE campaign_id=? AND origin=?");
  s.bind(1, campaign_id).bind(2, origin);
  s.step();
  return static_cast<int>(s.integer(0));
}

std::vector<Store::FinishedCost> Store::finished_costs(std::int64_t campaign_id) {
  Stmt s(*db_,
         "SELECT c.mesh_level, c.est_cost, r.wall_s, " CAPSIM_CASE_THREADS " "
         "FROM cases c JOIN campaign_cases cc ON cc.case_id=c.case_id JOIN results r ON r.case_id=c.case_id "
         "WHERE cc.campaign_id=? AND c.status IN ('done', 'unstable') AND r.wall_s > 0");
  s.bind(1, campaign_id);
  std::vector<FinishedCost> out;
  while (s.step())
    out.push_back({static_cast<int>(s.integer(0)), s.real(1).value_or(1.0), s.real(2).value_or(0.0),
                   static_cast<int>(s.integer(3))});
  return out;
}

std::vector<Store::LevelCost> Store::level_costs(std::int64_t campaign_id) {
  Stmt s(*db_,
         "SELECT c.mesh_level, count(*), count(r.case_id), "
         "coalesce(sum(" CAPSIM_CASE_CORE_S "), 0) "
         "FROM cases c JOIN campaign_cases cc ON cc.case_id=c.case_id LEFT JOIN results r ON r.case_id=c.case_id "
         "WHERE cc.campaign_id=? GROUP BY c.mesh_level ORDER BY c.mesh_level");
  s.bind(1, campaign_id);
  std::vector<LevelCost> out;
  while (s.step())
    out.push_back({static_cast<int>(s.integer(0)), static_cast<int>(s.integer(1)), static_cast<int>(s.integer(2)),
                   s.real(3).value_or(0.0)});
  return out;
}

}  // namespace capsim::campaign

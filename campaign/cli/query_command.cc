// `capsim query table1|cases|sql`: read-only queries of a campaign database.
#include <sqlite3.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "campaign/cli/commands.h"
#include "campaign/common/bad_input.h"
#include "campaign/grid/decimal.h"
#include "campaign/query/table_output.h"
#include "campaign/store/store.h"

namespace capsim::cli {

namespace {

using campaign::BadInput;
using campaign::SqlValue;

std::string resolve_campaign(campaign::Store& store, const std::string& name) {
  if (!name.empty()) {
    if (!store.find_campaign(name)) throw BadInput(store.db().path() + ": no campaign named '" + name + "'");
    return name;
  }
  auto latest = store.latest_campaign();
  if (!latest) throw BadInput(store.db().path() + ": no campaign in this database");
  return *latest;
}

std::string law_label(const std::string& law, double C) {
  if (law == "neo-hookean") return "NH";
  if (law == "skalak") return "Sk, C = " + campaign::canonical_double(C);
  return law;
}

// A number of the table, or "–" for NULL.
std::string format_value(const SqlValue& v, const char* format) {
  if (auto* d = std::get_if<double>(&v)) {
    char buf[32];
    std::snprintf(buf, sizeof buf, format, *d);
    return buf;
  }
  return "–";
}

// A sampled capillary number as it was sampled (0.175 stays 0.175, 0.2 prints as 0.2): "%.2f" would round
// the adaptive refinements' edges onto the coarse grid.
std::string sampled(const SqlValue& v) { return format_value(v, "%.6g"); }

std::string fixed2(const SqlValue& v) { return format_value(v, "%.2f"); }

int table1(campaign::Store& store, const std::string& name, campaign::Format fmt, int mesh_level, double skalak_C) {
  const std::string camp = resolve_campaign(store, name);
  campaign::Stmt s(store.db(),
                   "SELECT t.law, t.aspect_ratio, t.skalak_C, t.mesh_level, t.ca_star_low, t.ca_star_high, t.ca_h "
                   "FROM transitions t JOIN campaigns c ON c.campaign_id=t.campaign_id WHERE c.name=? "
                   "AND (?2 < 0 OR t.mesh_level = ?2) AND (?3 < -0.5 OR t.skalak_C = ?3 OR t.law='neo-hookean') "
                   "ORDER BY t.law, t.aspect_ratio, t.mesh_level DESC");
  s.bind(1, camp).bind(2, std::int64_t{mesh_level}).bind(3, skalak_C);
  struct Row {
    std::string law;
    double ar, C;
    std::int64_t level;
    SqlValue lo, hi, h;
  };
  std::vector<Row> rows;
  std::map<std::pair<std::string, double>, int> seen;
  while (s.step()) {
    Row r{s.text(0), *s.real(1), *s.real(2), s.integer(3), s.column(4), s.column(5), s.column(6)};
    auto key = std::make_pair(r.law, r.ar);
    if (seen.count(key)) {
      const Row& first = rows[seen[key]];
      if (first.level == r.level)
        throw BadInput("campaign '" + camp + "' has several skalak_C values for " + r.law + " a/b=" +
                       campaign::canonical_double(r.ar) + "; choose one with --skalak-C");
      continue;  // keep the finest mesh level
    }
    seen[key] = static_cast<int>(rows.size());
    rows.push_back(r);
  }
  if (rows.empty())
    throw BadInput("campaign '" + camp + "' has no transitions yet (run it first: capsim campaign run ...)");
  if (fmt != campaign::Format::kMarkdown) {
    campaign::Table t;
    t.columns = {"law", "aspect_ratio", "ca_star_low", "ca_star_high", "ca_h"};
    for (const auto& r : rows) t.rows.push_back({r.law, r.ar, r.lo, r.hi, r.h});
    std::printf("%s", campaign::render(t, fmt).c_str());
    return 0;
  }
  // Markdown laid out like the seed's Table 1: one column per a/b, a Ca* line and a CaH line per law.
  std::vector<double> ars;
  std::vector<std::pair<std::string, double>> laws;
  for (const auto& r : rows) {
    if (std::find(ars.begin(), ars.end(), r.ar) == ars.end()) ars.push_back(r.ar);
    auto l = std::make_pair(r.law, r.C);
    if (std::find(laws.begin(), laws.end(), l) == laws.end()) laws.push_back(l);
  }
  std::sort(ars.begin(), ars.end());
  std::string out = "| |";
  for (double a : ars) out += " a/b = " + campaign::canonical_double(a) + " |";
  out += "\n|---|";
  for (std::size_t i = 0; i < ars.size(); ++i) out += "---|";
  out += "\n";
  for (const auto& [law, C] : laws) {
    std::string star = "| " + law_label(law, C) + " |", h = "| |";
    for (double a : ars) {
      const Row* r = nullptr;
      for (const auto& x : rows)
        if (x.law == law && x.C == C && x.ar == a) r = &x;
      if (!r) {
        star += " |";
        h += " |";
        continue;
      }
      star += std::holds_alternative<double>(r->lo) ? " Ca* ∈ [" + sampled(r->lo) + ", " + sampled(r->hi) + "] |"
                                                    : " Ca* not found |";
      h += std::holds_alternative<double>(r->h) ? " CaH = " + fixed2(r->h) + " |" : " CaH not bracketed |";
    }
    out += star + "\n" + h + "\n";
  }
  std::printf("%s", out.c_str());
  return 0;
}

int cases(campaign::Store& store, const std::string& name, campaign::Format fmt, const std::string& law,
          double ar, double ca_min, double ca_max, const std::string& status) {
  std::string camp;
  if (!name.empty()) camp = resolve_campaign(store, name);
  if (!status.empty() && status != "queued" && status != "running" && status != "done" && status != "unstable" &&
      status != "failed")
    throw BadInput("--status: expected queued, running, done, unstable or failed, got '" + status + "'");
  if (!law.empty() && law != "neo-hookean" && law != "skalak")
    throw BadInput("--law: expected neo-hookean or skalak, got '" + law + "'");
  campaign::Stmt s(store.db(),
                   "SELECT c.case_id, c.law, c.aspect_ratio, c.skalak_C, c.mesh_level, c.capillary_number, c.status, "
                   "c.attempts, r.min_D12, r.max_tau_min, r.mean_D12, r.period, r.regime, r.volume_drift, r.steps, "
                   "r.dt, r.t_final, coalesce(r.wall_s, c.wall_s) AS wall_s, c.code_version, c.error, c.h5_path "
                   "FROM cases c LEFT JOIN results r ON r.case_id=c.case_id "
                   "WHERE (?1 = '' OR c.case_id IN (SELECT cc.case_id FROM campaign_cases cc JOIN campaigns k "
                   "ON k.campaign_id=cc.campaign_id WHERE k.name=?1)) "
                   "AND (?2 = '' OR c.law = ?2) AND (?3 <= 0 OR abs(c.aspect_ratio - ?3) < 1e-12) "
                   "AND c.capillary_number >= ?4 AND c.capillary_number <= ?5 AND (?6 = '' OR c.status = ?6) "
                   "ORDER BY c.law, c.aspect_ratio, c.skalak_C, c.mesh_level, c.capillary_number");
  s.bind(1, camp).bind(2, law).bind(3, ar).bind(4, ca_min).bind(5, ca_max).bind(6, status);
  auto t = campaign::query_table(store.db(), s);
  std::printf("%s", campaign::render(t, fmt).c_str());
  return 0;
}

int sql(campaign::Store& store, const std::string& text, campaign::Format fmt) {
  sqlite3* h = store.db().handle();
  // Prepare every statement first: if any of them writes, nothing runs.
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
  for (auto& st : stmts) {
    sqlite3_stmt* raw = st.get();
    campaign::Table t;
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
    if (n > 0) std::printf("%s", campaign::render(t, fmt).c_str());
  }
  return 0;
}

}  // namespace

int query_command(const std::vector<std::string>& args) {
  CLI::App app{"capsim query: read-only queries of a campaign database", "capsim query"};
  app.require_subcommand(1);
  std::string db, format = "md", camp;
  auto common = [&](CLI::App* sub) {
    sub->add_option("--db", db, "SQLite results database")->required();
    sub->add_option("--format", format, "md (default), csv or json");
  };
  auto* t1 = app.add_subcommand("table1", "Ca* interval and CaH per law and a/b, laid out like the seed's Table 1");
  common(t1);
  t1->add_option("--campaign", camp, "campaign name (default: the most recently run)");
  int mesh_level = -1;
  double skalak_C = -1;
  t1->add_option("--mesh-level", mesh_level, "only this mesh level (default: the finest per group)");
  t1->add_option("--skalak-C", skalak_C, "only this Skalak C");
  auto* cs = app.add_subcommand("cases", "cases with their results; CSV export for plotting");
  common(cs);
  std::string law, status;
  double ar = 0, ca_min = 0, ca_max = 1e300;
  cs->add_option("--campaign", camp, "only cases of this campaign");
  cs->add_option("--law", law, "neo-hookean or skalak");
  cs->add_option("--aspect-ratio", ar, "only this a/b");
  cs->add_option("--ca-min", ca_min, "smallest capillary number");
  cs->add_option("--ca-max", ca_max, "largest capillary number");
  cs->add_option("--status", status, "queued, running, done, unstable or failed");
  auto* sq = app.add_subcommand("sql", "run read-only SQL (writes are refused)");
  common(sq);
  std::string text;
  sq->add_option("statement", text, "SQL text, e.g. \"SELECT * FROM transitions\"")->required();

  std::vector<std::string> rev(args.rbegin(), args.rend());
  try {
    app.parse(rev);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    std::fprintf(stderr, "capsim query: %s (see capsim query --help)\n", e.what());
    return kExitBadInput;
  }
  try {
    const auto fmt = campaign::parse_format(format);
    auto store = campaign::Store::open_readonly(db);
    if (*t1) return table1(*store, camp, fmt, mesh_level, skalak_C);
    if (*cs) return cases(*store, camp, fmt, law, ar, ca_min, ca_max, status);
    return sql(*store, text, fmt);
  } catch (const BadInput& e) {
    std::fprintf(stderr, "capsim query: error: %s\n", campaign::one_line(e.what()).c_str());
    return kExitBadInput;
  } catch (const campaign::DbError& e) {
    std::fprintf(stderr, "capsim query: error: %s\n", campaign::one_line(e.what()).c_str());
    return kExitBadInput;
  }
}

}  // namespace capsim::cli

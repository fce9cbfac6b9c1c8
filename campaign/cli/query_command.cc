// `capsim query table1|cases|transitions|sql`: read-only queries of a campaign database.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "campaign/cli/cli_app.h"
#include "campaign/cli/commands.h"
#include "campaign/analysis/group_key.h"
#include "campaign/analysis/uncertainty.h"
#include "campaign/common/bad_input.h"
#include "campaign/grid/decimal.h"
#include "campaign/grid/precision.h"
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

SqlValue value_of(const std::optional<double>& x) { return x ? SqlValue{*x} : SqlValue{nullptr}; }

// The physical axes of a campaign besides law, a/b and Ca that `query table1` can pick one value of: each a key
// of the case registry (absent from a stored group key means its default, the seed's capsule), the option that
// picks it and how the table names it. A new axis (a tilt, an azimuth) is one line here.
struct PhysicalAxis {
  const char* key;     // dotted case key
  const char* option;  // table1's option
  const char* label;   // the line above a table whose value is not the default
};
constexpr PhysicalAxis kPhysicalAxes[] = {
    {"capsule.bending_modulus", "--bending-modulus", "Bending modulus κ_b"},
    {"flow.viscosity_ratio", "--viscosity-ratio", "Viscosity ratio λ (inner/outer)"},
};

// The value of @p axis in a stored group key; the registry's default for a key it does not hold (or a version-2
// row's empty key).
double axis_value(const PhysicalAxis& axis, const std::string& group_key) {
  static const auto defaults = campaign::GroupKey::parse("{}");
  const auto key = campaign::GroupKey::parse(group_key);
  return (key ? *key : *defaults).number(axis.key);
}

bool same_value(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b)); }

double bending_modulus_of(const std::string& group_key) { return axis_value(kPhysicalAxes[0], group_key); }

// Every stored field of @p rows (of campaign @p campaign_of[i]) as the JSON and CSV of `query table1` and
// `query transitions` give them. The first eighteen columns are those table1 has always had, in their order:
// the fields added since come after them, so that readers of the older output read the newer one.
campaign::Table transitions_table(const std::vector<campaign::Transition>& rows,
                                  const std::vector<std::string>& campaign_of) {
  campaign::Table t;
  t.columns = {"law",          "aspect_ratio",     "ca_star_low", "ca_star_high", "ca_h",
               "ca_star_low_err", "ca_star_high_err", "ca_h_err",    "mesh_level",   "error_levels",
               "ca_star_low_err_source", "ca_star_high_err_source", "ca_h_err_source", "bending_modulus", "level_answers",
               "ca_star_low_err_lacks", "ca_star_high_err_lacks", "ca_h_err_lacks",
               // added for the scripts that render Table 1 (scripts/table1, scripts/plot):
               "campaign", "skalak_C", "role", "n_samples", "ca_star_below", "ca_star_above", "ca_min_d12", "ca_h_low",
               "ca_h_high", "method", "note", "error_note", "group_key",
               // the regime-based tumbling-to-swinging bracket (analysis/transitions.h, schema 7):
               "ca_ts_low", "ca_ts_high", "ca_ts_note"};
  t.json_columns = {"level_answers", "group_key"};  // {"ca_h": {"2": 0.23, "4": 0.61}, ...}: nested in JSON output
  auto text_or_null = [](const std::string& x) { return x.empty() ? SqlValue{nullptr} : SqlValue{x}; };
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    t.rows.push_back({r.law, r.aspect_ratio, value_of(r.ca_star_low), value_of(r.ca_star_high), value_of(r.ca_h),
                      value_of(r.ca_star_low_err), value_of(r.ca_star_high_err), value_of(r.ca_h_err),
                      std::int64_t{r.mesh_level}, text_or_null(r.error_levels), text_or_null(r.ca_star_low_err_source),
                      text_or_null(r.ca_star_high_err_source), text_or_null(r.ca_h_err_source),
                      bending_modulus_of(r.group_key), text_or_null(campaign::level_answers_json(r.level_answers)),
                      text_or_null(r.ca_star_low_err_lacks), text_or_null(r.ca_star_high_err_lacks),
                      text_or_null(r.ca_h_err_lacks), campaign_of[i],
                      r.skalak_C < 0 ? SqlValue{nullptr} : SqlValue{r.skalak_C}, r.role, std::int64_t{r.n_samples},
                      value_of(r.ca_star_below), value_of(r.ca_star_above), value_of(r.ca_min_d12),
                      value_of(r.ca_h_low), value_of(r.ca_h_high), r.method, text_or_null(r.note),
                      text_or_null(r.error_note), text_or_null(r.group_key), value_of(r.ca_ts_low),
                      value_of(r.ca_ts_high), text_or_null(r.ca_ts_note)});
  }
  return t;
}

// Table 1's Ca_TS line of one cell: the bracket as sampled, "(regime)" naming where it comes from; without one,
// why (the note: "tumbles at every sampled Ca (0.02 to 5)"); nothing for a sphere, which does not tumble. A row
// analysed before schema 7 has neither bracket nor note.
std::string regime_transition_text(const campaign::Transition& r) {
  if (campaign::is_sphere(r)) return "";
  if (r.ca_ts_low && r.ca_ts_high) {
    const bool monotone = r.ca_ts_note.rfind(campaign::kRegimesNotMonotone, 0) != 0;
    return "Ca_TS ∈ (" + campaign::format_sampled(*r.ca_ts_low) + ", " + campaign::format_sampled(*r.ca_ts_high) +
           ") (regime" + (monotone ? "" : ", not monotone") + ")";
  }
  if (!r.ca_ts_note.empty()) return r.ca_ts_note;
  return "Ca_TS not analysed (capsim campaign analyse)";
}

// `only[i]`: the value of kPhysicalAxes[i] asked for (nullopt: any, but one per cell).
int table1(campaign::Store& store, const std::string& name, campaign::Format fmt, int mesh_level, double skalak_C,
           const std::vector<std::optional<double>>& only) {
  const std::string camp = resolve_campaign(store, name);
  std::vector<campaign::Transition> rows;
  // Per (law, a/b): the finest mesh level. Two groups there (two Skalak C, or a numerics axis) do not fit in
  // one cell of the table: say which keys differ instead of picking one.
  std::map<std::pair<std::string, double>, std::size_t> seen;
  for (auto& r : store.transitions(*store.find_campaign(camp), mesh_level, skalak_C)) {
    // Scan, mesh-check and dt-check groups serve the answer's error; with --mesh-level the user asks for
    // that level whatever its role.
    if (r.role != "answer" && mesh_level < 0) continue;
    // --bending-modulus, --viscosity-ratio: one value of a campaign with that axis.
    bool wanted = true;
    for (std::size_t a = 0; a < std::size(kPhysicalAxes); ++a)
      if (only[a] && !same_value(axis_value(kPhysicalAxes[a], r.group_key), *only[a])) wanted = false;
    if (!wanted) continue;
    auto key = std::make_pair(r.law, r.aspect_ratio);
    if (auto it = seen.find(key); it != seen.end()) {
      const auto& first = rows[it->second];
      if (first.mesh_level == r.mesh_level) {
        if (first.skalak_C != r.skalak_C)
          throw BadInput("campaign '" + camp + "' has several skalak_C values for " + r.law + " a/b=" +
                         campaign::canonical_double(r.aspect_ratio) + "; choose one with --skalak-C");
        for (const auto& axis : kPhysicalAxes) {
          const double u = axis_value(axis, first.group_key), v = axis_value(axis, r.group_key);
          if (u != v)
            throw BadInput("campaign '" + camp + "' has several values of " + axis.key + " for " + r.law +
                           " a/b=" + campaign::canonical_double(r.aspect_ratio) + " (" +
                           campaign::canonical_double(u) + " and " + campaign::canonical_double(v) +
                           "); choose one with " + axis.option);
        }
        throw BadInput("campaign '" + camp + "' has several transition groups for " + r.law + " a/b=" +
                       campaign::canonical_double(r.aspect_ratio) + " at mesh level " + std::to_string(r.mesh_level) +
                       ", they differ in " + campaign::group_difference(first.group_key, r.group_key) +
                       "; see `capsim query sql \"SELECT group_key, ca_star_low, ca_star_high, ca_h FROM transitions\"`");
      }
      continue;  // keep the finest mesh level
    }
    seen[key] = rows.size();
    rows.push_back(std::move(r));
  }
  if (rows.empty())
    for (std::size_t a = 0; a < std::size(kPhysicalAxes); ++a)
      if (only[a])
        throw BadInput("campaign '" + camp + "' has no transitions with " + kPhysicalAxes[a].key + " = " +
                       campaign::canonical_double(*only[a]));
  if (rows.empty())
    throw BadInput("campaign '" + camp + "' has no transitions yet (run it first: capsim campaign run ...)");
  if (fmt != campaign::Format::kMarkdown) {
    std::printf("%s", campaign::render(transitions_table(rows, std::vector<std::string>(rows.size(), camp)), fmt).c_str());
    return 0;
  }
  // Markdown laid out like the seed's Table 1: one column per a/b, a Ca* line and a CaH line per law, and a third
  // line with the regime-based bracket Ca_TS (not the seed's: where the Ca* criterion misfires, e.g. a viscous
  // interior, it is the transition). With an
  // error estimate (analysis/uncertainty.h) an answer prints "x ± e", x to the digit of e. Without one, the
  // Ca* edges are sampled values (printed as sampled) and CaH, interpolated in its bracket, is rounded to the
  // leading digit of the bracket width (a lower bound of its error: the mesh error is not known). An error
  // that lacks a part (no data: one level, no dt check) is a lower bound too: its ± is marked "†" and a legend
  // under the table names the missing parts.
  std::vector<double> ars;
  std::vector<std::pair<std::string, double>> laws;
  for (const auto& r : rows) {
    if (std::find(ars.begin(), ars.end(), r.aspect_ratio) == ars.end()) ars.push_back(r.aspect_ratio);
    auto l = std::make_pair(r.law, r.skalak_C);
    if (std::find(laws.begin(), laws.end(), l) == laws.end()) laws.push_back(l);
  }
  std::sort(ars.begin(), ars.end());
  std::set<std::string> lacking;  // the missing parts of the errors marked † (analysis/uncertainty.h kErrorParts)
  std::string out = "| |";
  for (double a : ars) out += " a/b = " + campaign::canonical_double(a) + " |";
  out += "\n|---|";
  for (std::size_t i = 0; i < ars.size(); ++i) out += "---|";
  out += "\n";
  for (const auto& [law, C] : laws) {
    std::string star = "| " + law_label(law, C) + " |", h = "| |", ts = "| |";
    for (double a : ars) {
      const campaign::Transition* r = nullptr;
      for (const auto& x : rows)
        if (x.law == law && x.skalak_C == C && x.aspect_ratio == a) r = &x;
      if (!r) {
        star += " |";
        h += " |";
        ts += " |";
        continue;
      }
      // An answer with an error estimate prints "x ± e" (digits of the error), "x ± e†" when e lacks a part;
      // an edge without one prints as sampled.
      auto with_error = [&](double x, double e, const std::string& lacks) {
        if (lacks.empty()) return campaign::format_plus_minus(x, e);
        for (std::size_t a = 0, b; a <= lacks.size(); a = b + 1) {  // split "mesh,dt" into its parts
          b = std::min(lacks.find(',', a), lacks.size());
          lacking.insert(lacks.substr(a, b - a));
        }
        return campaign::format_plus_minus(x, e) + "†";
      };
      auto edge = [&](const std::optional<double>& x, const std::optional<double>& e, const std::string& lacks) {
        return e ? with_error(*x, *e, lacks) : campaign::format_sampled(*x);
      };
      star += r->ca_star_low && r->ca_star_high
                  ? " Ca* ∈ [" + edge(r->ca_star_low, r->ca_star_low_err, r->ca_star_low_err_lacks) + ", " +
                        edge(r->ca_star_high, r->ca_star_high_err, r->ca_star_high_err_lacks) + "] |"
              : campaign::is_sphere(*r) ? " ⋆ (a sphere does not tumble) |"
                                        : " Ca* not found |";
      h += r->ca_h && r->ca_h_low && r->ca_h_high
               ? " CaH = " + (r->ca_h_err ? with_error(*r->ca_h, *r->ca_h_err, r->ca_h_err_lacks)
                                          : campaign::format_with_error(*r->ca_h, *r->ca_h_high - *r->ca_h_low)) + " |"
               : " CaH not bracketed |";
      ts += " " + regime_transition_text(*r) + " |";
    }
    out += star + "\n" + h + "\n" + ts + "\n";
  }
  if (!lacking.empty()) {
    // The union of the missing parts in the order of kErrorParts, each with why it has no data.
    constexpr const char* why[] = {"no other mesh level", "period spread not recorded", "no dt/2 check"};
    static_assert(std::size(why) == std::size(campaign::kErrorParts), "one reason per named part");
    std::string parts;
    for (std::size_t i = 0; i < std::size(campaign::kErrorParts); ++i)
      if (lacking.count(campaign::kErrorParts[i]))
        parts += (parts.empty() ? "" : ", ") + std::string(campaign::kErrorParts[i]) + ": " + why[i];
    out += "\n† a lower bound: this error lacks a part that had no data (" + parts +
           "); the JSON's *_err_lacks name them per answer.\n";
  }
  // A capsule that is not the seed's (bending stiffness, another viscosity ratio): say so above the table (one
  // value per table, as two would be two groups in a cell, refused above).
  std::string header;
  static const auto defaults = campaign::GroupKey::parse("{}");
  for (const auto& axis : kPhysicalAxes)
    if (const double x = axis_value(axis, rows.front().group_key); x != defaults->number(axis.key))
      header += std::string(axis.label) + " = " + campaign::canonical_double(x) + " (" + axis.key + ")\n";
  if (!header.empty()) out = header + "\n" + out;
  std::printf("%s", out.c_str());
  return 0;
}

int cases(campaign::Store& store, const std::string& name, campaign::Format fmt, const std::string& law,
          double ar, double ca_min, double ca_max, const std::string& status, double viscosity_ratio) {
  std::string camp;
  if (!name.empty()) camp = resolve_campaign(store, name);
  if (!status.empty() && status != "queued" && status != "running" && status != "done" && status != "unstable" &&
      status != "failed")
    throw BadInput("--status: expected queued, running, done, unstable or failed, got '" + status + "'");
  if (!law.empty() && law != "neo-hookean" && law != "skalak")
    throw BadInput("--law: expected neo-hookean or skalak, got '" + law + "'");
  campaign::CaseFilter f;
  f.campaign = camp;
  f.law = law;
  f.aspect_ratio = ar;
  f.ca_min = ca_min;
  f.ca_max = ca_max;
  f.status = status;
  f.viscosity_ratio = viscosity_ratio;
  auto t = store.cases_table(f);
  if (fmt != campaign::Format::kJson) {
    // The case folder and the stored result line serve scripts (JSON); the tables for reading keep their width.
    for (const char* wide : {"summary", "out_dir"}) {
      const auto c = std::find(t.columns.begin(), t.columns.end(), wide) - t.columns.begin();
      t.columns.erase(t.columns.begin() + c);
      for (auto& row : t.rows) row.erase(row.begin() + c);
    }
  }
  std::printf("%s", campaign::render(t, fmt).c_str());
  return 0;
}

// `query transitions`: every stored transition group of a campaign (or of every campaign), all levels and roles.
int transitions(campaign::Store& store, const std::string& name, campaign::Format fmt, const std::string& role) {
  if (!role.empty() && role != "answer" && role != "scan" && role != "mesh_check" && role != "dt_check")
    throw BadInput("--role: expected answer, scan, mesh_check or dt_check, got '" + role + "'");
  const auto camps = store.campaigns(name);
  if (!name.empty() && camps.empty()) throw BadInput(store.db().path() + ": no campaign named '" + name + "'");
  std::vector<campaign::Transition> rows;
  std::vector<std::string> campaign_of;
  for (const auto& c : camps)
    for (auto& r : store.transitions(c.campaign_id))
      if (role.empty() || r.role == role) {
        rows.push_back(std::move(r));
        campaign_of.push_back(c.name);
      }
  std::printf("%s", campaign::render(transitions_table(rows, campaign_of), fmt).c_str());
  return 0;
}

int sql(campaign::Store& store, const std::string& text, campaign::Format fmt) {
  for (const auto& t : campaign::run_readonly_sql(store.db(), text)) std::printf("%s", campaign::render(t, fmt).c_str());
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
  auto* t1 = app.add_subcommand("table1", "Ca* interval, CaH and the regime bracket Ca_TS per law and a/b, laid out "
                                          "like the seed's Table 1");
  common(t1);
  t1->add_option("--campaign", camp, "campaign name (default: the most recently run)");
  int mesh_level = -1;
  double skalak_C = -1;
  t1->add_option("--mesh-level", mesh_level, "only this mesh level (default: the finest per group)");
  t1->add_option("--skalak-C", skalak_C, "only this Skalak C");
  std::vector<std::optional<double>> only(std::size(kPhysicalAxes));
  t1->add_option("--bending-modulus", only[0], "only this capsule.bending_modulus (a campaign with a bending axis)")
      ->check(CLI::NonNegativeNumber);
  t1->add_option("--viscosity-ratio", only[1], "only this flow.viscosity_ratio (a campaign with a viscosity_ratio axis)")
      ->check(CLI::PositiveNumber);
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
  double cases_lambda = 0;
  cs->add_option("--viscosity-ratio", cases_lambda, "only this flow.viscosity_ratio (the column viscosity_ratio)")
      ->check(CLI::PositiveNumber);
  auto* tr = app.add_subcommand("transitions", "every stored transition group (all mesh levels and roles) with its "
                                               "errors and provenance");
  common(tr);
  std::string role;
  tr->add_option("--campaign", camp, "only this campaign (default: every campaign)");
  tr->add_option("--role", role, "only this role: answer, scan, mesh_check or dt_check");
  auto* sq = app.add_subcommand("sql", "run read-only SQL (writes are refused)");
  common(sq);
  std::string text;
  sq->add_option("statement", text, "SQL text, e.g. \"SELECT * FROM transitions\"")->required();

  if (const auto code = parse_args(app, args)) return *code;
  try {
    const auto fmt = campaign::parse_format(format);
    auto store = campaign::Store::open_readonly(db);
    if (*t1)
      return table1(*store, camp, fmt, mesh_level, skalak_C, only);
    if (*cs) return cases(*store, camp, fmt, law, ar, ca_min, ca_max, status, cases_lambda);
    if (*tr) return transitions(*store, camp, fmt, role);
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

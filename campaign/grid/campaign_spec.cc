#include "campaign/grid/campaign_spec.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "campaign/common/bad_input.h"
#include "campaign/grid/decimal.h"
#include "solver/config/case_config.h"
#include "solver/config/toml_value.h"

namespace capsim::campaign {

namespace {

[[noreturn]] void fail(const std::string& source, const std::string& key, const std::string& what) {
  throw BadInput(source + ": " + key + ": " + what);
}

using config::toml_type_name;

/// Converts a TOML scalar to a Value of the key's type, checked against the key's registry range.
Value to_value(const CaseKey& key, const toml::node& n, const std::string& source, const std::string& where) {
  std::string why;
  auto v = config::toml_to_key_value(key, n, why);
  if (!v) fail(source, where, why);
  if (auto msg = check_case_value(key, *v); !msg.empty()) fail(source, where, msg);
  return *v;
}

/// Flattens [defaults] (nested tables or dotted keys) into dotted case keys.
void read_defaults(const toml::table& t, const std::string& prefix, CaseParams& out, const std::string& source) {
  for (const auto& [k, node] : t) {
    std::string name = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const auto* sub = node.as_table()) {
      read_defaults(*sub, name, out, source);
      continue;
    }
    const CaseKey* key = find_case_key(name);
    if (!key) fail(source, "[defaults] " + name, "unknown case key (see schemas/campaign_keys.md)");
    out.set(name, to_value(*key, node, source, "[defaults] " + name));
  }
}

std::vector<Value> read_axis(const CaseKey& key, const toml::node& node, const std::string& source,
                             const std::string& where) {
  std::vector<Value> values;
  auto push_unique = [&](Value v) {
    for (const auto& w : values)
      if (w == v) return;
    values.push_back(std::move(v));
  };
  if (const auto* arr = node.as_array()) {
    if (arr->empty()) fail(source, where, "empty list: a grid axis needs at least one value");
    for (std::size_t i = 0; i < arr->size(); ++i) {
      Value v = to_value(key, (*arr)[i], source, where + "[" + std::to_string(i) + "]");
      // Normalise floats through their shortest decimal so 0.1 typed anywhere is the same value.
      if (auto* d = std::get_if<double>(&v)) {
        try {
          v = Decimal::from_double(*d).to_double();
        } catch (const std::exception& e) {
          fail(source, where, e.what());
        }
      }
      push_unique(std::move(v));
    }
  } else if (const auto* tab = node.as_table()) {
    if (key.type != KeyType::kFloat && key.type != KeyType::kInt && key.type != KeyType::kFloatOrAuto)
      fail(source, where, "a {start, stop, step} range needs a numeric key");
    for (const auto& [k, _] : *tab)
      if (k != "start" && k != "stop" && k != "step")
        fail(source, where + "." + std::string(k.str()), "unknown range key (expected start, stop, step)");
    Decimal bounds[3];
    const char* names[3] = {"start", "stop", "step"};
    for (int i = 0; i < 3; ++i) {
      const toml::node* n = tab->get(names[i]);
      if (!n) fail(source, where, std::string("range is missing '") + names[i] + "'");
      double x;
      if (auto f = n->value_exact<double>()) x = *f;
      else if (auto iv = n->value_exact<std::int64_t>()) x = static_cast<double>(*iv);
      else fail(source, where + "." + names[i], "expected a number, got " + toml_type_name(*n));
      try {
        bounds[i] = Decimal::from_double(x);
      } catch (const std::exception& e) {
        fail(source, where + "." + names[i], e.what());
      }
    }
    std::vector<Decimal> pts;
    try {
      pts = expand_decimal_range(bounds[0], bounds[1], bounds[2]);
    } catch (const std::exception& e) {
      fail(source, where, std::string("bad range: ") + e.what());
    }
    for (const auto& d : pts) {
      Value v;
      if (key.type == KeyType::kInt) {
        if (d.scale != 0) fail(source, where, "integer key needs an integer range");
        v = static_cast<std::int64_t>(d.mantissa);
      } else {
        v = d.to_double();
      }
      if (auto msg = check_case_value(key, v); !msg.empty()) fail(source, where, msg);
      push_unique(std::move(v));
    }
  } else {
    fail(source, where, "expected a list of values or a {start, stop, step} table, got " + toml_type_name(node));
  }
  return values;
}

void expect_only(const toml::table& t, const std::set<std::string>& allowed, const std::string& source,
                 const std::string& section) {
  for (const auto& [k, _] : t)
    if (!allowed.count(std::string(k.str())))
      fail(source, section + " " + std::string(k.str()), "unknown key (see schemas/campaign_keys.md)");
}

}  // namespace

CampaignSpec parse_campaign(const std::string& text, const std::string& source) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream os;
    os << source << ":" << e.source().begin.line << ":" << e.source().begin.column
       << ": TOML syntax error: " << e.description();
    throw BadInput(os.str());
  }
  CampaignSpec spec;
  spec.source = source;
  spec.defaults = CaseParams::defaults();
  expect_only(root, {"campaign", "defaults", "grid", "analysis"}, source, "top level:");

  // [campaign]
  const toml::node* camp = root.get("campaign");
  if (!camp || !camp->is_table()) fail(source, "[campaign]", "missing section (it needs at least name = \"...\")");
  const auto& ct = *camp->as_table();
  expect_only(ct, {"name", "description"}, source, "[campaign]");
  if (auto* n = ct.get("name")) {
    auto s = n->value_exact<std::string>();
    if (!s) fail(source, "[campaign] name", "expected a string, got " + toml_type_name(*n));
    if (s->empty()) fail(source, "[campaign] name", "must not be empty");
    spec.name = *s;
  } else {
    fail(source, "[campaign] name", "missing (every campaign needs a name)");
  }
  if (auto* n = ct.get("description")) {
    auto s = n->value_exact<std::string>();
    if (!s) fail(source, "[campaign] description", "expected a string, got " + toml_type_name(*n));
    spec.description = *s;
  }

  // [defaults]
  if (auto* d = root.get("defaults")) {
    if (!d->is_table()) fail(source, "[defaults]", "expected a table");
    read_defaults(*d->as_table(), "", spec.defaults, source);
  }

  // [[grid]]
  const toml::node* grid = root.get("grid");
  if (!grid) fail(source, "[[grid]]", "missing: a campaign needs at least one [[grid]] block");
  const auto* blocks = grid->as_array();
  if (!blocks || !blocks->is_array_of_tables())
    fail(source, "grid", "expected [[grid]] blocks (an array of tables)");
  if (blocks->empty()) fail(source, "[[grid]]", "empty grid: no blocks");
  for (std::size_t b = 0; b < blocks->size(); ++b) {
    const auto& bt = *(*blocks)[b].as_table();
    const std::string where = "[grid][" + std::to_string(b + 1) + "]";
    if (bt.empty()) fail(source, where, "empty grid block: give at least one axis");
    GridBlock block;
    std::set<std::string> seen;
    for (const auto& [k, node] : bt) {
      std::string name(k.str());
      std::string dotted = resolve_axis_name(name);
      if (node.is_table() && dotted.empty()) {
        // A nested table such as flow.capillary_number = [...] parses as [flow] capillary_number.
        const auto& sub = *node.as_table();
        for (const auto& [k2, n2] : sub) {
          std::string full = name + "." + std::string(k2.str());
          const CaseKey* key = find_case_key(full);
          if (!key) fail(source, where + "." + full, "unknown grid axis or case key");
          if (!seen.insert(full).second) fail(source, where + "." + full, "axis given twice");
          block.axes.push_back({full, read_axis(*key, n2, source, where + "." + full)});
        }
        continue;
      }
      if (dotted.empty()) {
        std::string aliases;
        for (const auto& [alias, key] : axis_aliases()) aliases += alias + ", ";
        fail(source, where + "." + name, "unknown grid axis (expected " + aliases + "or a case key)");
      }
      if (!seen.insert(dotted).second) fail(source, where + "." + name, "axis given twice");
      block.axes.push_back({dotted, read_axis(*find_case_key(dotted), node, source, where + "." + name)});
    }
    spec.grids.push_back(std::move(block));
  }

  // [analysis]
  if (auto* a = root.get("analysis")) {
    if (!a->is_table()) fail(source, "[analysis]", "expected a table");
    const auto& at = *a->as_table();
    expect_only(at, {"D12_threshold", "adaptive", "ca_tolerance", "max_cases", "max_rounds", "levels", "dt_check",
                     "check_precision", "stop_for_answer"},
                source, "[analysis]");
    auto number = [&](const char* k, double& out, double lo, double hi) {
      if (auto* n = at.get(k)) {
        std::optional<double> x = n->value_exact<double>();
        if (!x) if (auto i = n->value_exact<std::int64_t>()) x = static_cast<double>(*i);
        if (!x) fail(source, std::string("[analysis] ") + k, "expected a number, got " + toml_type_name(*n));
        if (!(*x > lo && *x < hi))
          fail(source, std::string("[analysis] ") + k,
               "out of range (" + canonical_double(lo) + ", " + canonical_double(hi) + "): " + canonical_double(*x));
        out = *x;
      }
    };
    auto integer = [&](const char* k, int& out, int lo, int hi) {
      if (auto* n = at.get(k)) {
        auto x = n->value_exact<std::int64_t>();
        if (!x) fail(source, std::string("[analysis] ") + k, "expected an integer, got " + toml_type_name(*n));
        if (*x < lo || *x > hi)
          fail(source, std::string("[analysis] ") + k,
               "out of range " + std::to_string(lo) + ".." + std::to_string(hi) + ": " + std::to_string(*x));
        out = static_cast<int>(*x);
      }
    };
    auto boolean = [&](const char* k, bool& out) {
      if (auto* n = at.get(k)) {
        auto b = n->value_exact<bool>();
        if (!b) fail(source, std::string("[analysis] ") + k, "expected true or false, got " + toml_type_name(*n));
        out = *b;
      }
    };
    number("D12_threshold", spec.analysis.d12_threshold, 0.0, 1.0);
    number("ca_tolerance", spec.analysis.ca_tolerance, 0.0, 1e6);
    integer("max_cases", spec.analysis.max_cases, 1, 100000);
    integer("max_rounds", spec.analysis.max_rounds, 1, 1000);
    boolean("adaptive", spec.analysis.adaptive);
    if (auto* n = at.get("levels")) {
      const auto* arr = n->as_array();
      if (!arr) fail(source, "[analysis] levels", "expected a list of 2 or 3 mesh levels, got " + toml_type_name(*n));
      if (arr->size() < 2 || arr->size() > 3)
        fail(source, "[analysis] levels", "expected 2 or 3 mesh levels ([scan, answer] or [scan, answer, check]), got " +
                                              std::to_string(arr->size()));
      for (const auto& e : *arr) {
        auto x = e.value_exact<std::int64_t>();
        if (!x) fail(source, "[analysis] levels", "expected integers, got " + toml_type_name(e));
        if (*x < 0 || *x > 6) fail(source, "[analysis] levels", "mesh level out of range 0..6: " + std::to_string(*x));
        if (!spec.analysis.levels.empty() && *x <= spec.analysis.levels.back())
          fail(source, "[analysis] levels", "levels must increase (scan < answer < check)");
        spec.analysis.levels.push_back(static_cast<int>(*x));
      }
      // The levels are the campaign's: a mesh level set elsewhere would contradict them.
      if (root.at_path("defaults.mesh.level"))
        fail(source, "[defaults] mesh.level", "not allowed with [analysis] levels (the scan level is levels[0])");
      for (std::size_t b = 0; b < spec.grids.size(); ++b)
        for (const auto& ax : spec.grids[b].axes)
          if (ax.key == "mesh.level")
            fail(source, "[grid][" + std::to_string(b + 1) + "] mesh_level", "not allowed with [analysis] levels");
      spec.defaults.set("mesh.level", std::int64_t{spec.analysis.levels[0]});
    }
    boolean("dt_check", spec.analysis.dt_check);
    if (spec.analysis.dt_check && spec.analysis.levels.empty())
      fail(source, "[analysis] dt_check", "needs [analysis] levels (it re-runs a case of the answer level)");
    boolean("stop_for_answer", spec.analysis.stop_for_answer);
    if (spec.analysis.stop_for_answer && spec.analysis.levels.empty())
      fail(source, "[analysis] stop_for_answer",
           "needs [analysis] levels (it sets the stop test of the cases the answer level adds)");
    if (auto* n = at.get("check_precision")) {
      auto v = n->value_exact<std::string>();
      if (!v) fail(source, "[analysis] check_precision", "expected a string, got " + toml_type_name(*n));
      if (spec.analysis.levels.size() != 3)
        fail(source, "[analysis] check_precision", "needs a check level ([analysis] levels = [scan, answer, check])");
      // Its values are those of the case key it sets (the key registry).
      if (const std::string why = check_case_value(*find_case_key("numerics.kernel_precision"), Value{*v}); !why.empty())
        fail(source, "[analysis] check_precision", why);
      spec.analysis.check_precision = *v;
    }
  }
  return spec;
}

CampaignSpec load_campaign_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw BadInput(path + ": cannot open campaign file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_campaign(ss.str(), path);
}

std::string CampaignSpec::to_json() const {
  nlohmann::ordered_json j;
  j["name"] = name;
  j["description"] = description;
  j["defaults"] = nlohmann::json::parse(defaults.to_json());
  j["grid"] = nlohmann::ordered_json::array();
  for (const auto& g : grids) {
    nlohmann::ordered_json b = nlohmann::ordered_json::object();
    for (const auto& ax : g.axes) {
      auto arr = nlohmann::ordered_json::array();
      for (const auto& v : ax.values) std::visit([&](const auto& x) { arr.push_back(x); }, v);
      b[ax.key] = arr;
    }
    j["grid"].push_back(b);
  }
  j["analysis"] = {{"D12_threshold", analysis.d12_threshold}, {"adaptive", analysis.adaptive},
                   {"ca_tolerance", analysis.ca_tolerance}, {"max_cases", analysis.max_cases},
                   {"max_rounds", analysis.max_rounds}};
  // Only when set: the stored JSON of a campaign without them stays what it was.
  if (!analysis.levels.empty()) {
    j["analysis"]["levels"] = analysis.levels;
    j["analysis"]["dt_check"] = analysis.dt_check;
  }
  if (!analysis.check_precision.empty()) j["analysis"]["check_precision"] = analysis.check_precision;
  if (analysis.stop_for_answer) j["analysis"]["stop_for_answer"] = true;
  return j.dump();
}

std::vector<CaseParams> expand_grid(const CampaignSpec& spec) {
  std::vector<CaseParams> out;
  std::set<std::string> seen;
  const std::string version = solver_version();
  for (const auto& block : spec.grids) {
    std::vector<std::size_t> idx(block.axes.size(), 0);
    while (true) {
      CaseParams p = spec.defaults;
      std::string point;
      for (std::size_t a = 0; a < block.axes.size(); ++a) {
        p.set(block.axes[a].key, block.axes[a].values[idx[a]]);
        point += (a ? ", " : "") + block.axes[a].key + "=" + value_to_text(block.axes[a].values[idx[a]]);
      }
      std::string id;
      try {
        id = p.identity(version);
      } catch (const config::ConfigError& e) {
        throw BadInput(spec.source + ": [grid][" + std::to_string(&block - spec.grids.data() + 1) + "] case " +
                       point + ": rejected by the solver: " + e.what());
      }
      if (seen.insert(id).second) out.push_back(std::move(p));
      // Odometer increment, last axis fastest.
      std::size_t a = block.axes.size();
      while (a > 0) {
        --a;
        if (++idx[a] < block.axes[a].values.size()) break;
        idx[a] = 0;
        if (a == 0) goto next_block;
      }
      if (block.axes.empty()) break;
    }
  next_block:;
  }
  return out;
}

}  // namespace capsim::campaign

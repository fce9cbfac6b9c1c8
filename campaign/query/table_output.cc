#include "campaign/query/table_output.h"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "campaign/common/bad_input.h"
#include "campaign/grid/decimal.h"

namespace capsim::campaign {

Format parse_format(const std::string& s) {
  if (s == "md" || s == "markdown") return Format::kMarkdown;
  if (s == "csv") return Format::kCsv;
  if (s == "json") return Format::kJson;
  throw BadInput("--format: expected md, csv or json, got '" + s + "'");
}

std::string cell_text(const SqlValue& v) {
  if (std::holds_alternative<std::nullptr_t>(v)) return "";
  if (auto* i = std::get_if<std::int64_t>(&v)) return std::to_string(*i);
  if (auto* d = std::get_if<double>(&v)) return canonical_double(*d);
  return std::get<std::string>(v);
}

std::string render(const Table& t, Format f) {
  std::string out;
  if (f == Format::kJson) {
    nlohmann::ordered_json arr = nlohmann::ordered_json::array();
    auto is_json = [&](const std::string& c) {
      return std::find(t.json_columns.begin(), t.json_columns.end(), c) != t.json_columns.end();
    };
    for (const auto& row : t.rows) {
      nlohmann::ordered_json o = nlohmann::ordered_json::object();
      for (std::size_t c = 0; c < t.columns.size(); ++c) {
        const auto& v = row[c];
        if (std::holds_alternative<std::nullptr_t>(v)) o[t.columns[c]] = nullptr;
        else if (auto* i = std::get_if<std::int64_t>(&v)) o[t.columns[c]] = *i;
        else if (auto* d = std::get_if<double>(&v)) o[t.columns[c]] = *d;
        else if (auto j = nlohmann::ordered_json::parse(std::get<std::string>(v), nullptr, false);
                 is_json(t.columns[c]) && !j.is_discarded())
          o[t.columns[c]] = std::move(j);
        else o[t.columns[c]] = std::get<std::string>(v);
      }
      arr.push_back(std::move(o));
    }
    return arr.dump(2) + "\n";
  }
  if (f == Format::kCsv) {
    auto quote = [](const std::string& s) {
      if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
      std::string q = "\"";
      for (char c : s) {
        if (c == '"') q.push_back('"');
        q.push_back(c);
      }
      return q + "\"";
    };
    // Appended piece by piece: `"," + std::string` inlines an insert that GCC 12 flags with a false -Wrestrict.
    for (std::size_t c = 0; c < t.columns.size(); ++c) {
      if (c) out += ',';
      out += quote(t.columns[c]);
    }
    out += "\n";
    for (const auto& row : t.rows) {
      for (std::size_t c = 0; c < row.size(); ++c) {
        if (c) out += ',';
        out += quote(cell_text(row[c]));
      }
      out += "\n";
    }
    return out;
  }
  auto esc = [](std::string s) {
    std::string r;
    for (char c : s) {
      if (c == '|') r += "\\|";
      else if (c == '\n') r += " ";
      else r.push_back(c);
    }
    return r;
  };
  out += "|";
  for (const auto& c : t.columns) out.append(" ").append(esc(c)).append(" |");
  out += "\n|";
  for (std::size_t c = 0; c < t.columns.size(); ++c) out += "---|";
  out += "\n";
  for (const auto& row : t.rows) {
    out += "|";
    for (const auto& v : row) out.append(" ").append(esc(cell_text(v))).append(" |");
    out += "\n";
  }
  return out;
}

}  // namespace capsim::campaign

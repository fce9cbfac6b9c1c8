#include "campaign/analysis/group_key.h"

#include <map>
#include <sstream>
#include <variant>

#include "solver/config/case_keys.h"

namespace capsim::campaign {

namespace {
// The registry's default of @p key as JSON (absent keys of a group key are at their default).
nlohmann::json registry_default(const std::string& key) {
  const config::CaseKey* k = config::find_case_key(key);
  if (!k) return nullptr;
  return std::visit([](const auto& v) { return nlohmann::json(v); }, k->default_value);
}
}  // namespace

GroupKey GroupKey::of(const CaseParams& params) {
  // The case identity hashes canonical() ("key=value" lines of the solver's resolved configuration, output keys
  // left out); the group is that text without the keys named in the class comment, so two cases share a group
  // exactly when their identities differ in those keys only.
  nlohmann::json j = nlohmann::json::object();
  std::istringstream lines(params.canonical());
  std::string line;
  while (std::getline(lines, line)) {
    const auto eq = line.find('=');
    if (eq == std::string::npos) continue;
    const std::string k = line.substr(0, eq), v = line.substr(eq + 1);
    if (k == "flow.capillary_number" || k == "numerics.kernel_precision" || k == "time.stop_test") continue;
    auto parsed = nlohmann::json::parse(v, nullptr, false);
    j[k] = (!parsed.is_discarded() && (parsed.is_number() || parsed.is_boolean() || parsed.is_string()))
               ? parsed
               : nlohmann::json(v);
  }
  return GroupKey(std::move(j));
}

std::optional<GroupKey> GroupKey::parse(const std::string& text) {
  auto j = nlohmann::json::parse(text, nullptr, false);
  if (!j.is_object()) return std::nullopt;
  return GroupKey(std::move(j));
}

GroupKey GroupKey::cell() const {
  nlohmann::json j = values_;
  j.erase("mesh.level");
  j.erase("time.dt");
  return GroupKey(std::move(j));
}

std::vector<std::string> GroupKey::keys() const {
  std::vector<std::string> out;
  for (const auto& [k, _] : values_.items()) out.push_back(k);
  return out;
}

std::string GroupKey::json_text(const std::string& key) const {
  return values_.contains(key) ? values_[key].dump() : "unset";
}

std::string GroupKey::text(const std::string& key) const {
  if (values_.contains(key)) {
    const auto& v = values_[key];
    return v.is_string() ? v.get<std::string>() : v.dump();
  }
  const config::CaseKey* k = config::find_case_key(key);
  return k ? config::shortest_text(k->default_value) : "";
}

double GroupKey::number(const std::string& key) const {
  const nlohmann::json v = values_.contains(key) ? values_[key] : registry_default(key);
  return v.is_number() ? v.get<double>() : 0.0;
}

std::string GroupKey::dt() const {
  if (!values_.contains("time.dt")) return "auto";
  const auto& v = values_["time.dt"];
  return v.is_string() ? v.get<std::string>() : v.dump();
}

std::string GroupKey::difference(const GroupKey& other) const {
  std::map<std::string, bool> keys;
  for (const auto& k : this->keys()) keys[k] = true;
  for (const auto& k : other.keys()) keys[k] = true;
  std::string out;
  for (const auto& [k, _] : keys)
    if (json_text(k) != other.json_text(k))
      out += (out.empty() ? "" : ", ") + k + " (" + json_text(k) + " vs " + other.json_text(k) + ")";
  return out;
}

std::string group_difference(const std::string& a, const std::string& b) {
  const auto ka = GroupKey::parse(a), kb = GroupKey::parse(b);
  return ka && kb ? ka->difference(*kb) : "";
}

std::string cell_key(const std::string& group_key) {
  const auto k = GroupKey::parse(group_key);
  return k ? k->cell().str() : group_key;
}

}  // namespace capsim::campaign

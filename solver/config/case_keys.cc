#include "solver/config/case_keys.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <initializer_list>
#include <sstream>
#include <type_traits>

#include "solver/config/case_config.h"

namespace capsim::config {
namespace {

// ---- The vocabulary of case_keys.def -------------------------------------------------------------------

/// Interval with mathematical brackets: range('(', 0.0, 100.0, ']') is 0 < x ≤ 100.
KeyRule range(char open, double lo, double hi, char close) {
  KeyRule r;
  r.has_interval = true;
  r.lo = lo;
  r.hi = hi;
  r.lo_open = open == '(';
  r.hi_open = close == ')';
  return r;
}
KeyRule one_of(std::initializer_list<std::int64_t> values) {
  KeyRule r;
  r.ints = values;
  return r;
}
KeyRule one_of(std::initializer_list<std::string_view> words) {
  KeyRule r;
  for (auto w : words) r.words.emplace_back(w);
  return r;
}
KeyRule one_of_bool() { return {}; }
template <class E>
KeyRule its_words() {
  KeyRule r;
  for (const auto& [value, word] : KeyWords<E>::words) r.words.emplace_back(word);
  return r;
}
KeyRule auto_or(KeyRule numbers) {
  numbers.words = {"auto"};
  return numbers;
}

struct IdentityRole {
  bool in_identity;
  bool omits_default;
  std::string_view unless_key, unless_value;
};
constexpr IdentityRole kInIdentity{true, false, {}, {}};
constexpr IdentityRole kNotInIdentity{false, false, {}, {}};
constexpr IdentityRole kInIdentityUnlessDefault{true, true, {}, {}};
constexpr IdentityRole in_identity_unless(std::string_view key, std::string_view value) {
  return {true, false, key, value};
}
constexpr bool kAlwaysStored = true;
constexpr bool kStoredWhenSet = false;

// ---- Field types <-> KeyValue ---------------------------------------------------------------------------

template <class T>
struct Field;
template <>
struct Field<double> {
  static constexpr KeyType type = KeyType::kFloat;
  static KeyValue to_value(double x) { return x; }
  static double from_value(const KeyValue& v) {
    if (const auto* i = std::get_if<std::int64_t>(&v)) return static_cast<double>(*i);
    return std::get<double>(v);
  }
};
template <>
struct Field<int> {
  static constexpr KeyType type = KeyType::kInt;
  static KeyValue to_value(int x) { return std::int64_t{x}; }
  // Only called after check_case_value accepted the int64 against a rule that lies well inside int.
  static int from_value(const KeyValue& v) { return static_cast<int>(std::get<std::int64_t>(v)); }
};
template <>
struct Field<bool> {
  static constexpr KeyType type = KeyType::kBool;
  static KeyValue to_value(bool x) { return x; }
  static bool from_value(const KeyValue& v) { return std::get<bool>(v); }
};
template <>
struct Field<std::string> {
  static constexpr KeyType type = KeyType::kString;
  static KeyValue to_value(const std::string& x) { return x; }
  static std::string from_value(const KeyValue& v) { return std::get<std::string>(v); }
};
// An enum key: its word outside CaseConfig, parsed once here (check_case_value has accepted the word).
template <class E>
  requires std::is_enum_v<E>
struct Field<E> {
  static constexpr KeyType type = KeyType::kString;
  static KeyValue to_value(E x) { return std::string(word_of(x)); }
  static E from_value(const KeyValue& v) { return from_word<E>(std::get<std::string>(v)).value(); }
};
template <>
struct Field<std::optional<double>> {
  static constexpr KeyType type = KeyType::kFloatOrAuto;
  static KeyValue to_value(const std::optional<double>& x) { return x ? KeyValue{*x} : KeyValue{std::string("auto")}; }
  static std::optional<double> from_value(const KeyValue& v) {
    if (std::holds_alternative<std::string>(v)) return std::nullopt;  // "auto"
    return Field<double>::from_value(v);
  }
};

template <class T, T CaseConfig::*member>
CaseKey make_key(const char* name, KeyRule rule, IdentityRole identity, bool always_stored, const char* doc,
                 const char* reason) {
  CaseKey k{};
  k.name = name;
  k.type = Field<T>::type;
  k.default_value = Field<T>::to_value(CaseConfig{}.*member);
  k.rule = std::move(rule);
  k.in_identity = identity.in_identity;
  k.identity_omits_default = identity.omits_default;
  k.unless_key = identity.unless_key;
  k.unless_value = identity.unless_value;
  k.always_stored = always_stored;
  k.doc = doc;
  k.rule_reason = reason;
  k.get = [](const CaseConfig& c) { return Field<T>::to_value(c.*member); };
  k.set = [](CaseConfig& c, const KeyValue& v) { c.*member = Field<T>::from_value(v); };
  return k;
}

// ---- Text ------------------------------------------------------------------------------------------------

std::string shortest(double x) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

std::string quoted(const std::string& s) { return "\"" + s + "\""; }

std::string join_or(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i)
    out += (i == 0 ? "" : i + 1 == items.size() ? " or " : ", ") + items[i];
  return out;
}

const char* type_text(KeyType t) {
  switch (t) {
    case KeyType::kFloat: return "float";
    case KeyType::kInt: return "int";
    case KeyType::kString: return "string";
    case KeyType::kBool: return "bool";
    case KeyType::kFloatOrAuto: return "\"auto\" or float";
  }
  return "";
}

const char* value_kind(const KeyValue& v) {
  switch (v.index()) {
    case 0: return "an integer";
    case 1: return "a float";
    case 2: return "a string";
    default: return "a boolean";
  }
}

/// The rule as a message phrase: "in (0, 100]", "4, 5 or 6", "\"auto\" or in (0, 1]".
std::string rule_phrase(const CaseKey& key) {
  const std::string text = key.rule.text(key.type);
  if (!key.rule.has_interval) return text;
  const std::string interval = key.rule.words.empty() ? text : text.substr(text.find(" or ") + 4);
  return (key.rule.words.empty() ? "" : quoted(key.rule.words[0]) + " or ") + "in " + interval;
}

bool in_interval(const KeyRule& r, double x) {
  if (!std::isfinite(x)) return false;
  const bool lo_ok = r.lo_open ? x > r.lo : x >= r.lo;
  const bool hi_ok = r.hi_open ? x < r.hi : x <= r.hi;
  return lo_ok && hi_ok;
}

std::string escape_cell(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

}  // namespace

std::string KeyRule::text(KeyType type) const {
  if (type == KeyType::kBool) return "true or false";
  std::vector<std::string> items;
  for (const auto& w : words) items.push_back(quoted(w));
  if (has_interval) {
    if (type == KeyType::kInt)
      items.push_back(shortest(lo) + ".." + shortest(hi));
    else
      items.push_back(std::string(lo_open ? "(" : "[") + shortest(lo) + ", " + shortest(hi) + (hi_open ? ")" : "]"));
  }
  for (auto i : ints) items.push_back(std::to_string(i));
  return join_or(items);
}

const std::vector<CaseKey>& case_keys() {
  static const std::vector<CaseKey> keys = {
#define CAPSIM_CASE_KEY(type, field, name, default_value, rule, identity, stored, doc, reason) \
  make_key<type, &CaseConfig::field>(name, rule, identity, stored, doc, reason),
#include "solver/config/case_keys.def"
#undef CAPSIM_CASE_KEY
  };
  return keys;
}

const CaseKey* find_case_key(std::string_view name) {
  for (const auto& k : case_keys())
    if (k.name == name) return &k;
  return nullptr;
}

std::string check_case_value(const CaseKey& key, const KeyValue& value) {
  const auto* i = std::get_if<std::int64_t>(&value);
  const auto* d = std::get_if<double>(&value);
  const auto* s = std::get_if<std::string>(&value);
  const bool type_ok = [&] {
    switch (key.type) {
      case KeyType::kFloat: return i || d;
      case KeyType::kInt: return i != nullptr;
      case KeyType::kString: return s != nullptr;
      case KeyType::kBool: return std::holds_alternative<bool>(value);
      case KeyType::kFloatOrAuto: return i || d || s;
    }
    return false;
  }();
  const std::string expected = key.type == KeyType::kInt      ? "an integer"
                               : key.type == KeyType::kString ? "a string"
                               : key.type == KeyType::kBool   ? "true or false"
                               : key.type == KeyType::kFloat  ? "a number"
                                                              : "\"auto\" or a number";
  if (!type_ok) return "expected " + expected + ", got " + value_kind(value);
  const KeyRule& r = key.rule;
  bool ok = true;
  if (s) {
    ok = std::find(r.words.begin(), r.words.end(), *s) != r.words.end();
  } else if (i || d) {
    // Integers are compared as int64 (or as the exact double of a float key's integer): a value such as
    // 4294967299 is out of range here, before anything narrows it to int.
    if (r.has_interval) ok = in_interval(r, i ? static_cast<double>(*i) : *d);
    else if (i) ok = std::find(r.ints.begin(), r.ints.end(), *i) != r.ints.end();
  }
  if (ok) return "";
  return "must be " + rule_phrase(key) + ", got " + shortest_text(value);
}

std::string shortest_text(const KeyValue& v) {
  if (const auto* i = std::get_if<std::int64_t>(&v)) return std::to_string(*i);
  if (const auto* d = std::get_if<double>(&v)) {
    std::string s = shortest(*d);
    if (std::isfinite(*d) && s.find_first_of(".e") == std::string::npos) s += ".0";
    return s;
  }
  if (const auto* b = std::get_if<bool>(&v)) return *b ? "true" : "false";
  return quoted(std::get<std::string>(v));
}

std::string identity_text(const KeyValue& v) {
  if (const auto* d = std::get_if<double>(&v)) {
    std::ostringstream os;
    os.precision(17);
    os << *d;
    std::string s = os.str();
    if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
    return s;
  }
  return shortest_text(v);  // integers, booleans and strings have one text
}

std::string case_keys_markdown() {
  std::string out(kMarkdownBegin);
  out += "\n| key | type | default | accepted | in identity | stored by a campaign | meaning |\n";
  out += "|---|---|---|---|---|---|---|\n";
  for (const auto& k : case_keys()) {
    std::string identity = !k.in_identity ? "no (output only)" : k.identity_omits_default ? "yes, when not at its default" : "yes";
    if (!k.unless_key.empty()) identity += ", except when `" + k.unless_key + "` = " + quoted(k.unless_value);
    out += "| `" + k.name + "` | " + escape_cell(type_text(k.type)) + " | " + escape_cell(shortest_text(k.default_value)) +
           " | " + escape_cell(k.rule.text(k.type)) + " | " + identity + " | " +
           (k.always_stored ? "always" : "when set") + " | " + escape_cell(k.doc) + " |\n";
  }
  out += "\nWhy these values are accepted:\n\n";
  for (const auto& k : case_keys()) out += "- `" + k.name + "` " + k.rule.text(k.type) + ": " + k.rule_reason + ".\n";
  out += std::string(kMarkdownEnd) + "\n";
  return out;
}

}  // namespace capsim::config

#include "solver/config/toml_value.h"

namespace capsim::config {

std::string toml_type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "a date/time";
  }
}

std::optional<KeyValue> toml_to_key_value(const CaseKey& key, const toml::node& n, std::string& why) {
  const auto f = n.value_exact<double>();
  const auto i = n.value_exact<std::int64_t>();
  const auto s = n.value_exact<std::string>();
  const auto b = n.value_exact<bool>();
  const char* expected = "";
  switch (key.type) {
    case KeyType::kFloat:
      if (f) return KeyValue{*f};
      if (i) return KeyValue{static_cast<double>(*i)};
      expected = "a number";
      break;
    case KeyType::kInt:
      if (i) return KeyValue{*i};
      expected = "an integer";
      break;
    case KeyType::kString:
      if (s) return KeyValue{*s};
      expected = "a string";
      break;
    case KeyType::kBool:
      if (b) return KeyValue{*b};
      expected = "true or false";
      break;
    case KeyType::kFloatOrAuto:
      if (f) return KeyValue{*f};
      if (i) return KeyValue{static_cast<double>(*i)};
      if (s) return KeyValue{*s};
      expected = "\"auto\" or a number";
      break;
  }
  why = std::string("expected ") + expected + ", got " + toml_type_name(n);
  return std::nullopt;
}

}  // namespace capsim::config

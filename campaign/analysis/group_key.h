#pragma once
/// @file
/// @brief The key of a transition group: every identity key of a case except Ca, as one value type with its
/// stored text (transitions.group_key), its parse, and typed access to the axes the campaign layer reads.

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "campaign/grid/case_params.h"

namespace capsim::campaign {

/// @brief What a group of cases shares: the solver's resolved identity keys (as in CaseParams::canonical())
/// except flow.capillary_number (varies within a group), numerics.kernel_precision (how a case was computed,
/// not what: both precisions agree to ~1e-6 in min D12, results/speed/mixed_ab_case.json) and time.stop_test
/// (which answer its periodic stop waited for; the other carries its period spread). Two cases share a group
/// exactly when their keys are equal.
///
/// The stored form (str()) is the canonical JSON object of those keys, sorted, values JSON numbers / booleans
/// where they parse as such, else strings: committed databases hold it in transitions.group_key, so it must
/// stay bitwise what it is. A key added to the case registry enters by itself (and only where set otherwise
/// than its default: CaseParams::canonical() leaves such keys out), so a new campaign axis (a viscosity ratio,
/// a tilt, an azimuth) needs no change here beyond its typed accessor, one line next to bending_modulus().
class GroupKey {
 public:
  /// @brief The group of a case. @throws capsim::config::ConfigError if the solver rejects the case.
  static GroupKey of(const CaseParams& params);
  /// @brief A stored key; nullopt for text that is not a JSON object (a version-2 transitions row has "").
  static std::optional<GroupKey> parse(const std::string& text);

  /// @brief The stored text: canonical JSON, bitwise what of() always produced.
  [[nodiscard]] std::string str() const { return values_.dump(); }
  bool operator==(const GroupKey& other) const { return values_ == other.values_; }

  /// @brief The cell of the group: the key without mesh.level and time.dt (the levels and the dt/2 checks
  /// of one physical question).
  [[nodiscard]] GroupKey cell() const;
  /// @brief Whether the key holds @p key (a key at its default added after identities were first stored is
  /// absent).
  [[nodiscard]] bool has(const std::string& key) const { return values_.contains(key); }
  /// @brief The dotted keys it holds, sorted.
  [[nodiscard]] std::vector<std::string> keys() const;
  /// @brief The value of @p key as JSON text ("unset" when absent): how messages tell two values apart.
  [[nodiscard]] std::string json_text(const std::string& key) const;
  /// @brief The value of @p key as a reader writes it (strings without quotes); the key registry's default
  /// when absent.
  [[nodiscard]] std::string text(const std::string& key) const;
  /// @brief A numeric key's value; the key registry's default when absent.
  [[nodiscard]] double number(const std::string& key) const;

  /// @brief capsule.law.
  [[nodiscard]] std::string law() const { return text("capsule.law"); }
  /// @brief capsule.aspect_ratio.
  [[nodiscard]] double aspect_ratio() const { return number("capsule.aspect_ratio"); }
  /// @brief capsule.bending_modulus (0, the seed's membrane, when absent).
  [[nodiscard]] double bending_modulus() const { return number("capsule.bending_modulus"); }
  /// @brief flow.viscosity_ratio λ (1, the seed's capsule, when absent).
  [[nodiscard]] double viscosity_ratio() const { return number("flow.viscosity_ratio"); }
  /// @brief mesh.level.
  [[nodiscard]] int mesh_level() const { return static_cast<int>(number("mesh.level")); }
  /// @brief time.dt as text: "auto" (the default), else the step as stored JSON (e.g. "0.01").
  [[nodiscard]] std::string dt() const;

  /// @brief The keys in which two keys differ, as "key (a vs b), ..." (for messages); "" if equal.
  [[nodiscard]] std::string difference(const GroupKey& other) const;

 private:
  explicit GroupKey(nlohmann::json values) : values_(std::move(values)) {}
  nlohmann::json values_;  // object: dotted key -> JSON scalar
};

/// @brief GroupKey::difference of two stored keys; "" if either is not a JSON object (a version-2 row).
std::string group_difference(const std::string& group_key_a, const std::string& group_key_b);

/// @brief The stored text of the cell of a stored group key (GroupKey::cell); text that is not a JSON object
/// is its own cell.
std::string cell_key(const std::string& group_key);

}  // namespace capsim::campaign

#pragma once
/// @file
/// @brief The parameters of one capsule case, read from a TOML case file (schemas/case_keys.md lists every
/// key with its default) with `--set section.key=value` overrides, validated before anything runs.

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace capsim::config {

/// @brief Bad input in a case file or override: the message names the key or the file.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// @brief Everything that defines one case. Defaults are the documented ones.
struct CaseConfig {
  // [capsule]
  double aspect_ratio = 2.0;           ///< a/b of the initial spheroid (1 = sphere)
  std::string law = "skalak";          ///< "neo-hookean" | "skalak"
  double skalak_C = 1.0;               ///< Skalak area-dilation parameter, C > −1/2
  // [flow]
  double capillary_number = 0.3;       ///< Ca = μ γ̇ ℓ / Gs
  // [mesh]
  int level = 3;                       ///< icosahedron subdivisions (0..6)
  std::string spheroid_map = "equal-arc-length";
  // [time]
  double t_end = 60.0;                 ///< hard cap, units of 1/γ̇
  std::string scheme = "rkc";          ///< time integrator: "rkc" (stabilised Runge–Kutta–Chebyshev) | "rk2" (Heun)
  std::optional<double> dt;            ///< fixed time step; unset = automatic (see dynamics::automatic_time_step)
  double dt_factor = 0.25;             ///< stability constant c of the automatic rk2 dt (measured limit ≈ 0.34–0.39)
  double dt_accuracy = 0.02;           ///< automatic dt of rkc (accuracy-limited), never below the rk2 dt
  double period_tolerance = 2e-3;      ///< stop when successive periods agree to this (min D12, max τmin)
  double check_interval = 1.0;         ///< how often (time units) the periodic-regime test runs
  double volume_tolerance = 0.05;      ///< relative volume change that counts as a blow-up
  // [numerics]
  int regular_degree = 4;              ///< triangle rule of the boundary integral (4, 5, 6)
  int duffy_order = 8;                 ///< Gauss points per direction of the singular integrals
  int membrane_degree = 6;             ///< triangle rule of the membrane and mass matrix (4, 5, 6)
  bool volume_correction = true;       ///< remove the discrete flux ∫ v·n dS (see dynamics::CapsuleFlow)
  int far_degree = 0;                  ///< far-field rule of the boundary integral: 0 = off, 1, 2 (see stokes)
  double far_radius = 4.0;             ///< elements beyond far_radius · their radius get the far rule; > 1
  // [output]
  double snapshot_interval = 0.0;      ///< 0 = no snapshots
  double checkpoint_interval = 5.0;    ///< time units between checkpoints (0 = only at the end / interrupt)
  double sample_interval = 0.0;        ///< time-series sampling (0 = every step)

  /// @brief Throws ConfigError naming the first key out of range.
  void validate() const;
  /// @brief The effective configuration as TOML text (every key, defaults included).
  [[nodiscard]] std::string to_toml() const;
  /// @brief Canonical key → value text of every parameter (for HDF5 attributes and identities).
  [[nodiscard]] std::map<std::string, std::string> to_map() const;
};

/// @brief Every accepted case key as "section.key", in file order (the campaign layer checks its own key
/// table against this list, so the two can never drift apart).
std::vector<std::string> case_key_names();

/// @brief Read a case file (may be empty: all defaults) and apply `section.key=value` overrides.
/// @throws ConfigError for a missing/unreadable/unparsable file, an unknown key, a wrong type or a value
/// out of range; the message names the key or file.
CaseConfig load_case_config(const std::string& path, const std::vector<std::string>& overrides);

/// @brief Parse a case from TOML text (same rules as load_case_config; `origin` names it in messages).
CaseConfig parse_case_config(const std::string& toml_text, const std::string& origin,
                             const std::vector<std::string>& overrides = {});

}  // namespace capsim::config

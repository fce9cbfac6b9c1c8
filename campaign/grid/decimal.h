#pragma once
/// @file
/// @brief Exact decimal numbers for grid axes, so that ranges such as 0.01:0.01:0.10 do not drift.

#include <cstdint>
#include <string>
#include <vector>

namespace capsim::campaign {

/// @brief A decimal number mantissa × 10^(-scale), exact for the values people type in campaign files.
struct Decimal {
  std::int64_t mantissa = 0;  ///< signed integer digits
  int scale = 0;              ///< number of digits after the decimal point (>= 0)

  /// @brief The shortest decimal that round-trips to @p x (e.g. 0.1 -> {1, 1}); throws on NaN/inf or
  /// values needing more than 15 significant digits.
  static Decimal from_double(double x);
  /// @brief Canonical text without trailing zeros ("0.07", "2", "-1.5").
  std::string to_string() const;
  /// @brief The double nearest to this decimal (the same double the literal text would give).
  double to_double() const;
  /// @brief The same value expressed with @p new_scale >= scale digits.
  Decimal rescaled(int new_scale) const;
};

/// @brief Expands an inclusive range start, start+step, ..., stop computed exactly in decimal.
/// @throws std::invalid_argument with a message if step <= 0, stop < start, (stop-start) is not a
/// multiple of step, or the range has more than @p max_points values.
std::vector<Decimal> expand_decimal_range(const Decimal& start, const Decimal& stop, const Decimal& step,
                                          std::size_t max_points = 100000);

/// @brief Canonical shortest round-trip text of a double (used for identities and TOML output).
std::string canonical_double(double x);

}  // namespace capsim::campaign

#pragma once
/// @file
/// @brief Numbers of the printed tables to the precision their numerical error supports: a
/// sampled Ca as sampled (shortest decimal), an interpolated value rounded to the leading digit of its error
/// (for CaH: the width of its bracket), a diagnostic (min D12, max tau_min) to 3 significant digits. Until
/// error estimates exist these are the supportable precisions; with them, format_plus_minus. JSON output keeps full precision.

#include <string>

namespace capsim::campaign {

/// @brief A sampled value as it was sampled: the shortest decimal that reads back to @p x (0.175, 0.2).
std::string format_sampled(double x);

/// @brief @p x rounded to the decimal position of the leading digit of @p error (> 0): 0.3512 with error
/// 0.05 prints 0.35, with 0.1 prints 0.4, 123.4 with 20 prints 120. Never more digits than the error supports.
/// A non-positive or non-finite error falls back to format_significant(x, 3).
std::string format_with_error(double x, double error);

/// @brief "x ± e" with the error rounded up to one significant digit (0.047 -> 0.05, 0.012 -> 0.02: never
/// smaller than estimated) and x rounded to that digit: 0.6034 ± 0.047 prints "0.60 ± 0.05". A non-positive
/// or non-finite error prints format_significant(x, 3) alone.
std::string format_plus_minus(double x, double error);

/// @brief @p x to @p digits significant digits (printf %.*g).
std::string format_significant(double x, int digits = 3);

}  // namespace capsim::campaign

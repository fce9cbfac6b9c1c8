#include "campaign/grid/precision.h"

#include <cmath>
#include <cstdio>

#include "campaign/grid/decimal.h"

namespace capsim::campaign {

std::string format_sampled(double x) { return canonical_double(x); }

std::string format_significant(double x, int digits) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", digits, x);
  return buf;
}

std::string format_with_error(double x, double error) {
  if (!(error > 0) || !std::isfinite(error) || !std::isfinite(x)) return format_significant(x, 3);
  // The decimal exponent of the error's leading digit: 0.05 -> -2, 0.1 -> -1, 20 -> 1.
  const int e = static_cast<int>(std::floor(std::log10(error)));
  char buf[48];
  if (e < 0) {
    std::snprintf(buf, sizeof buf, "%.*f", -e, x);
  } else {
    const double q = std::pow(10.0, e);
    std::snprintf(buf, sizeof buf, "%.0f", std::round(x / q) * q);
  }
  std::string s = buf;
  // -0.00 after rounding is 0.00: a sign the digits do not support.
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s = s.substr(1);
  return s;
}

std::string format_plus_minus(double x, double error) {
  if (!(error > 0) || !std::isfinite(error) || !std::isfinite(x)) return format_significant(x, 3);
  int e = static_cast<int>(std::floor(std::log10(error)));
  double q = std::pow(10.0, e);
  // Round the error up to one digit (with a little slack so that 0.05 stays 0.05 despite binary round-off).
  double up = std::ceil(error / q * (1 - 1e-12)) * q;
  if (up >= 10 * q * (1 - 1e-12)) {  // 0.096 -> 0.1: one digit, one place up
    ++e;
    q *= 10;
    up = q;
  }
  const std::string err = format_with_error(up, q);
  return format_with_error(x, q) + " ± " + err;
}

}  // namespace capsim::campaign

#include "campaign/grid/decimal.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace capsim::campaign {

namespace {
std::int64_t pow10i(int n) {
  std::int64_t p = 1;
  for (int i = 0; i < n; ++i) p *= 10;
  return p;
}
}  // namespace

std::string canonical_double(double x) {
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::general);
  std::string s(buf, res.ptr);
  // Prefer plain notation for moderate exponents so identities read naturally.
  if (s.find('e') != std::string::npos && std::fabs(x) >= 1e-6 && std::fabs(x) < 1e15) {
    res = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::fixed);
    s.assign(buf, res.ptr);
  }
  return s;
}

Decimal Decimal::from_double(double x) {
  if (!std::isfinite(x)) throw std::invalid_argument("not a finite number");
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::fixed);
  std::string s(buf, res.ptr);
  // Shortest fixed representation that round-trips.
  bool neg = false;
  std::size_t i = 0;
  if (!s.empty() && s[0] == '-') {
    neg = true;
    i = 1;
  }
  std::string digits;
  int scale = 0;
  bool after_point = false;
  for (; i < s.size(); ++i) {
    if (s[i] == '.') {
      after_point = true;
      continue;
    }
    digits.push_back(s[i]);
    if (after_point) ++scale;
  }
  while (scale > 0 && !digits.empty() && digits.back() == '0') {
    digits.pop_back();
    --scale;
  }
  std::size_t first = digits.find_first_not_of('0');
  std::size_t significant = first == std::string::npos ? 0 : digits.size() - first;
  if (significant > 15 || scale > 15) throw std::invalid_argument("too many significant digits for an exact grid value");
  Decimal d;
  d.scale = scale;
  d.mantissa = digits.empty() ? 0 : std::strtoll(digits.c_str(), nullptr, 10);
  if (neg) d.mantissa = -d.mantissa;
  return d;
}

std::string Decimal::to_string() const {
  std::int64_t m = mantissa < 0 ? -mantissa : mantissa;
  std::string digits = std::to_string(m);
  if (scale > 0) {
    // Concatenation, not std::string::insert: GCC 12 flags insert's inlined copy with a false -Wrestrict.
    if (static_cast<int>(digits.size()) <= scale) digits = std::string(scale - digits.size() + 1, '0') + digits;
    const std::size_t point = digits.size() - static_cast<std::size_t>(scale);
    digits = digits.substr(0, point) + "." + digits.substr(point);
    while (digits.back() == '0') digits.pop_back();
    if (digits.back() == '.') digits.pop_back();
  }
  return (mantissa < 0 ? "-" : "") + digits;
}

double Decimal::to_double() const { return std::strtod(to_string().c_str(), nullptr); }

Decimal Decimal::rescaled(int new_scale) const {
  if (new_scale < scale) throw std::invalid_argument("cannot reduce decimal scale");
  return Decimal{mantissa * pow10i(new_scale - scale), new_scale};
}

std::vector<Decimal> expand_decimal_range(const Decimal& start, const Decimal& stop, const Decimal& step,
                                          std::size_t max_points) {
  int scale = std::max({start.scale, stop.scale, step.scale});
  Decimal a = start.rescaled(scale), b = stop.rescaled(scale), h = step.rescaled(scale);
  if (h.mantissa <= 0) throw std::invalid_argument("step must be > 0");
  if (b.mantissa < a.mantissa) throw std::invalid_argument("stop must be >= start");
  if ((b.mantissa - a.mantissa) % h.mantissa != 0)
    throw std::invalid_argument("stop - start (" + Decimal{b.mantissa - a.mantissa, scale}.to_string() +
                                ") is not a multiple of step (" + step.to_string() + ")");
  std::int64_t n = (b.mantissa - a.mantissa) / h.mantissa + 1;
  if (static_cast<std::uint64_t>(n) > max_points)
    throw std::invalid_argument("range has " + std::to_string(n) + " values (limit " + std::to_string(max_points) + ")");
  std::vector<Decimal> out;
  out.reserve(static_cast<std::size_t>(n));
  for (std::int64_t k = 0; k < n; ++k) {
    Decimal d{a.mantissa + k * h.mantissa, scale};
    // Normalise (strip trailing zeros) so equal values compare equal.
    while (d.scale > 0 && d.mantissa % 10 == 0) {
      d.mantissa /= 10;
      --d.scale;
    }
    out.push_back(d);
  }
  return out;
}

}  // namespace capsim::campaign

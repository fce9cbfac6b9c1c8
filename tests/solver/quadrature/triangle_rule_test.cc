#include "solver/quadrature/triangle_rule.h"

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace capsim::quadrature {
namespace {

// Exact mean of ξ^i η^j over the unit right triangle: 2 i! j! / (i + j + 2)!.
double exact_mean(int i, int j) { return 2.0 * std::tgamma(i + 1.0) * std::tgamma(j + 1.0) / std::tgamma(i + j + 3.0); }

double rule_mean(const TriangleRule& r, int i, int j) {
  double s = 0.0;
  for (int k = 0; k < r.size(); ++k) s += r.weights[k] * std::pow(r.points[k][1], i) * std::pow(r.points[k][2], j);
  return s;
}

class TriangleRuleExactness : public ::testing::TestWithParam<std::pair<int, int>> {};

TEST_P(TriangleRuleExactness, ExactUpToDegreeNotBeyond) {
  const auto [degree, npoints] = GetParam();
  const TriangleRule& r = triangle_rule(degree);
  EXPECT_EQ(r.size(), npoints);
  EXPECT_EQ(r.degree, degree);
  EXPECT_NEAR(std::accumulate(r.weights.begin(), r.weights.end(), 0.0), 1.0, 1e-15);
  for (double w : r.weights) EXPECT_GT(w, 0.0);
  for (const auto& p : r.points) {
    EXPECT_NEAR(p[0] + p[1] + p[2], 1.0, 1e-15);
    for (double l : p) EXPECT_GT(l, 0.0);
  }
  for (int i = 0; i <= degree; ++i)
    for (int j = 0; i + j <= degree; ++j)
      EXPECT_NEAR(rule_mean(r, i, j), exact_mean(i, j), 1e-15) << "monomial xi^" << i << " eta^" << j;  // a few ulps
  // Some monomial of degree + 1 is not integrated exactly.
  double worst = 0.0;
  for (int i = 0; i <= degree + 1; ++i)
    worst = std::max(worst, std::abs(rule_mean(r, i, degree + 1 - i) - exact_mean(i, degree + 1 - i)));
  EXPECT_GT(worst, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Rules, TriangleRuleExactness,
                         ::testing::Values(std::pair{1, 1}, std::pair{2, 3}, std::pair{4, 6}, std::pair{5, 7},
                                           std::pair{6, 12}));

TEST(TriangleRule, UnknownDegreeThrows) {
  EXPECT_THROW(triangle_rule(0), std::invalid_argument);
  EXPECT_THROW(triangle_rule(3), std::invalid_argument);
  EXPECT_THROW(triangle_rule(7), std::invalid_argument);
}

// The message for an unknown degree lists every degree that exists (it once offered "4, 5 or 6" only,
// though 1 and 2 exist for the far-field tier).
TEST(TriangleRule, UnknownDegreeMessageListsEveryAvailableDegree) {
  std::string message;
  try {
    triangle_rule(3);
  } catch (const std::invalid_argument& e) {
    message = e.what();
  }
  ASSERT_FALSE(message.empty());
  const std::string choices = message.substr(message.find("choose"));
  for (int d = 0; d <= 12; ++d) {
    bool exists = true;
    try {
      triangle_rule(d);
    } catch (const std::invalid_argument&) {
      exists = false;
    }
    EXPECT_EQ(choices.find(std::to_string(d)) != std::string::npos, exists) << "degree " << d << ": " << message;
  }
}

TEST(GaussLegendre, ExactToDegree2nMinus1) {
  for (int n = 1; n <= 20; ++n) {
    const LineRule g = gauss_legendre(n);
    for (int d = 0; d <= 2 * n - 1; ++d) {
      double s = 0.0;
      for (int k = 0; k < n; ++k) s += g.weights[k] * std::pow(g.nodes[k], d);
      EXPECT_NEAR(s, 1.0 / (d + 1), 1e-14) << "n=" << n << " degree " << d;
    }
    // Not exact at degree 2n (the error shrinks fast with n, so check where it is measurable).
    if (n <= 6) {
      double s = 0.0;
      for (int k = 0; k < n; ++k) s += g.weights[k] * std::pow(g.nodes[k], 2 * n);
      EXPECT_GT(std::abs(s - 1.0 / (2 * n + 1)), 1e-10) << "n=" << n;
    }
  }
  EXPECT_THROW(gauss_legendre(0), std::invalid_argument);
}

}  // namespace
}  // namespace capsim::quadrature

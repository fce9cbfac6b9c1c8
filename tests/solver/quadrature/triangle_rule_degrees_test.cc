// The message for an unavailable triangle rule lists every degree that is available (issue 12, defect 11:
// it said "choose 4, 5 or 6" although the far-field rules of degree 1 and 2 exist).
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "solver/quadrature/triangle_rule.h"

namespace capsim::quadrature {
namespace {

TEST(TriangleRuleDegrees, MessageListsEveryAvailableDegree) {
  std::string available;
  for (int d = 0; d <= 12; ++d) {
    try {
      EXPECT_EQ(triangle_rule(d).degree, d);
      available += (available.empty() ? "" : " ") + std::to_string(d);
    } catch (const std::invalid_argument&) {
    }
  }
  EXPECT_EQ(available, "1 2 4 5 6");
  try {
    (void)triangle_rule(3);
    FAIL() << "degree 3 has no rule";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("1, 2, 4, 5 or 6"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace capsim::quadrature

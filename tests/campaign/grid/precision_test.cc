// Printed numbers carry the digits their error supports: sampled values as sampled,
// interpolated values to the leading digit of their error, diagnostics to 3 significant digits.
#include <gtest/gtest.h>

#include "campaign/grid/precision.h"

namespace capsim::campaign {
namespace {

TEST(Precision, SampledValuesPrintAsSampled) {
  EXPECT_EQ(format_sampled(0.175), "0.175");
  EXPECT_EQ(format_sampled(0.2), "0.2");
  EXPECT_EQ(format_sampled(0.0275), "0.0275");  // an adaptive refinement's edge, not rounded onto a grid
}

TEST(Precision, InterpolatedValueHasTheDigitsOfItsError) {
  // CaH = 0.351234... interpolated in a bracket [0.3, 0.35]: width 0.05, so two decimals.
  EXPECT_EQ(format_with_error(0.35123456789012345, 0.05), "0.35");
  // Width 0.1 supports one decimal; width 0.25 too (leading digit at 10^-1).
  EXPECT_EQ(format_with_error(0.35123456789012345, 0.1), "0.4");
  EXPECT_EQ(format_with_error(0.35123456789012345, 0.25), "0.4");
  // Width 0.0049: three decimals.
  EXPECT_EQ(format_with_error(0.70123, 0.0049), "0.701");
  // An error of order 10 rounds to tens, never printing digits below it.
  EXPECT_EQ(format_with_error(123.4, 20), "120");
  EXPECT_EQ(format_with_error(-0.001, 0.05), "0.00");  // no sign the digits cannot support
  // Without a usable error: three significant digits.
  EXPECT_EQ(format_with_error(0.35123456789012345, 0), "0.351");
}

TEST(Precision, PlusMinusRoundsTheErrorUpAndTheValueToItsDigit) {
  EXPECT_EQ(format_plus_minus(0.6034, 0.047), "0.60 ± 0.05");
  EXPECT_EQ(format_plus_minus(0.6034, 0.05), "0.60 ± 0.05");   // an exact digit is not rounded up
  EXPECT_EQ(format_plus_minus(0.6034, 0.012), "0.60 ± 0.02");  // up, never below the estimate
  EXPECT_EQ(format_plus_minus(2.4871, 0.096), "2.5 ± 0.1");    // 0.096 rounds up to one digit of 0.1
  EXPECT_EQ(format_plus_minus(0.31234, 0.0031), "0.312 ± 0.004");
  EXPECT_EQ(format_plus_minus(123.4, 20), "120 ± 20");
  EXPECT_EQ(format_plus_minus(0.351, 0), "0.351");              // no usable error: the value alone
}

TEST(Precision, DiagnosticsHaveThreeSignificantDigits) {
  EXPECT_EQ(format_significant(0.044971266940321575), "0.045");
  EXPECT_EQ(format_significant(-0.0123456), "-0.0123");
  EXPECT_EQ(format_significant(1.23456, 3), "1.23");
}

}  // namespace
}  // namespace capsim::campaign

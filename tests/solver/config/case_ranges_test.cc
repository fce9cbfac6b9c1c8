// Every numeric case key is bounded: an absurd value is a typing error, rejected
// with one message naming the key before anything runs, and an integer is range-checked as the 64-bit
// value TOML gives, before anything narrows it to int.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "solver/config/case_config.h"

namespace capsim::config {
namespace {

/// The message of parse_case_config for the overrides, or "" if the case is accepted.
std::string rejection(const std::vector<std::string>& overrides) {
  try {
    (void)parse_case_config("", "case.toml", overrides);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(CaseRanges, AnIntegerThatWrapsAroundIntIsRejected) {
  // 4294967299 = 2^32 + 3: narrowed to int it is level 3, a valid case that would run.
  const std::string why = rejection({"mesh.level=4294967299"});
  EXPECT_NE(why.find("mesh.level"), std::string::npos) << why;
  EXPECT_NE(why.find("4294967299"), std::string::npos) << "the message shows the value given: " << why;
  EXPECT_NE(rejection({"mesh.level=-4294967293"}), "");  // -2^32 + 3
  EXPECT_NE(rejection({"numerics.duffy_order=4294967304"}), "");  // 2^32 + 8
  // The same value in a case file.
  EXPECT_THROW((void)parse_case_config("[mesh]\nlevel = 4294967299\n", "case.toml"), ConfigError);
}

TEST(CaseRanges, AbsurdCapillaryNumberIsRejected) {
  const std::string why = rejection({"flow.capillary_number=1e308"});
  EXPECT_NE(why.find("flow.capillary_number"), std::string::npos) << why;
  EXPECT_EQ(rejection({"flow.capillary_number=3.5"}), "") << "the largest Ca of the presets";
}

TEST(CaseRanges, EveryNumericKeyIsBounded) {
  const CaseConfig defaults;
  for (const auto& [key, text] : defaults.to_map()) {
    const bool is_int = !text.empty() && text.find_first_not_of("-0123456789") == std::string::npos;
    const bool is_float = !is_int && (text == "\"auto\"" || text.find_first_not_of("-0123456789.e+") == std::string::npos);
    if (is_int) {
      EXPECT_NE(rejection({key + "=4294967299"}), "") << key << " accepts 2^32 + 3";
      EXPECT_NE(rejection({key + "=-4294967296"}), "") << key << " accepts -2^32";
    } else if (is_float) {
      EXPECT_NE(rejection({key + "=1e308"}), "") << key << " accepts 1e308";
      EXPECT_NE(rejection({key + "=-1e308"}), "") << key << " accepts -1e308";
      EXPECT_NE(rejection({key + "=inf"}), "") << key << " accepts inf";
      EXPECT_NE(rejection({key + "=nan"}), "") << key << " accepts nan";
    }
  }
}

TEST(CaseRanges, AnOverrideMayCorrectTheFile) {
  // Values are checked once the file and every --set are read: the later value counts.
  EXPECT_NO_THROW((void)parse_case_config("[mesh]\nlevel = 9\n", "case.toml", {"mesh.level=2"}));
}

}  // namespace
}  // namespace capsim::config

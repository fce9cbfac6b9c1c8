// Case configuration: the far-field keys of the boundary integral, the bending modulus and the viscosity ratio
// (parsing, ranges).
#include "solver/config/case_config.h"

#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace capsim::config {
namespace {

// A `--set key=value` that the registry must refuse: a ConfigError whose message names the key.
void expect_refused_naming_its_key(const char* bad) {
  try {
    (void)parse_case_config("", "case.toml", {bad});
    ADD_FAILURE() << bad << " accepted";
  } catch (const ConfigError& e) {
    const std::string key = std::string(bad).substr(0, std::string(bad).find('='));
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
  }
}

TEST(CaseConfig, FarFieldKeysDefaultToOff) {
  const CaseConfig c = parse_case_config("", "empty");
  EXPECT_EQ(c.far_degree, 0);
  EXPECT_EQ(c.far_radius, 4.0);
  const auto map = c.to_map();
  EXPECT_EQ(map.at("numerics.far_degree"), "0");
  EXPECT_EQ(map.at("numerics.far_radius"), "4.0");
  const std::string toml = c.to_toml();
  EXPECT_NE(toml.find("far_degree = 0\n"), std::string::npos) << toml;
  EXPECT_NE(toml.find("far_radius = 4.0\n"), std::string::npos) << toml;
}

TEST(CaseConfig, FarFieldKeysParseFromFileAndOverrides) {
  CaseConfig c = parse_case_config("[numerics]\nfar_degree = 2\nfar_radius = 6\n", "case.toml");
  EXPECT_EQ(c.far_degree, 2);
  EXPECT_EQ(c.far_radius, 6.0);
  c = parse_case_config("", "case.toml", {"numerics.far_degree=1", "numerics.far_radius=2.5"});
  EXPECT_EQ(c.far_degree, 1);
  EXPECT_EQ(c.far_radius, 2.5);
  // The echoed TOML reads back to the same configuration.
  EXPECT_EQ(parse_case_config(c.to_toml(), "echo").to_map(), c.to_map());
}

TEST(CaseConfig, FarFieldKeysAreRangeChecked) {
  auto message = [](const std::vector<std::string>& overrides) {
    try {
      (void)parse_case_config("", "case.toml", overrides);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  for (const char* bad : {"numerics.far_degree=3", "numerics.far_degree=-1"})
    EXPECT_NE(message({bad}).find("numerics.far_degree"), std::string::npos) << bad;
  for (const char* bad : {"numerics.far_radius=1.0", "numerics.far_radius=0.5", "numerics.far_radius=nan"})
    EXPECT_NE(message({bad}).find("numerics.far_radius"), std::string::npos) << bad;
  EXPECT_NE(message({"numerics.far_degree=1.5"}).find("expected an integer"), std::string::npos);
  EXPECT_EQ(message({"numerics.far_degree=2", "numerics.far_radius=1.01"}), "");
}

TEST(CaseConfig, FarFieldKeysAreListed) {
  const auto names = case_key_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "numerics.far_degree"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "numerics.far_radius"), names.end());
}

// numerics.kernel_precision: "double" unless set; "mixed" from a file or --set; anything else refused with the
// key's name (exit 2 at the command line).
TEST(CaseConfig, KernelPrecisionDefaultsToDoubleAndAcceptsOnlyItsTwoValues) {
  const CaseConfig c = parse_case_config("", "empty");
  EXPECT_EQ(c.kernel_precision, "double");
  EXPECT_EQ(c.to_map().at("numerics.kernel_precision"), "\"double\"");
  EXPECT_EQ(parse_case_config("[numerics]\nkernel_precision = \"mixed\"\n", "case.toml").kernel_precision, "mixed");
  const CaseConfig m = parse_case_config("", "case.toml", {"numerics.kernel_precision=mixed"});
  EXPECT_EQ(m.kernel_precision, "mixed");
  EXPECT_EQ(parse_case_config(m.to_toml(), "echo").to_map(), m.to_map());
  for (const char* bad : {"numerics.kernel_precision=single", "numerics.kernel_precision=float"}) {
    try {
      (void)parse_case_config("", "case.toml", {bad});
      ADD_FAILURE() << bad << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("numerics.kernel_precision"), std::string::npos) << e.what();
    }
  }
}

TEST(CaseConfig, BendingModulusDefaultsToNoneAndIsRangeChecked) {
  EXPECT_EQ(parse_case_config("", "empty").bending_modulus, 0.0);
  EXPECT_EQ(parse_case_config("[capsule]\nbending_modulus = 1e-3\n", "case.toml").bending_modulus, 1e-3);
  EXPECT_EQ(parse_case_config("", "case.toml", {"capsule.bending_modulus=0.01"}).bending_modulus, 0.01);
  for (const char* bad : {"capsule.bending_modulus=-1e-3", "capsule.bending_modulus=2", "capsule.bending_modulus=nan"}) {
    try {
      (void)parse_case_config("", "case.toml", {bad});
      ADD_FAILURE() << bad << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("capsule.bending_modulus"), std::string::npos) << e.what();
    }
  }
}

TEST(CaseConfig, ViscosityRatioDefaultsToOneAndIsRangeChecked) {
  EXPECT_EQ(parse_case_config("", "empty").viscosity_ratio, 1.0);
  EXPECT_EQ(parse_case_config("[flow]\nviscosity_ratio = 5\n", "case.toml").viscosity_ratio, 5.0);
  EXPECT_EQ(parse_case_config("", "case.toml", {"flow.viscosity_ratio=0.05"}).viscosity_ratio, 0.05);
  EXPECT_EQ(parse_case_config("", "case.toml", {"flow.viscosity_ratio=20"}).viscosity_ratio, 20.0);
  for (const char* bad : {"flow.viscosity_ratio=0.04", "flow.viscosity_ratio=21", "flow.viscosity_ratio=0",
                          "flow.viscosity_ratio=-1", "flow.viscosity_ratio=nan", "flow.viscosity_ratio=\"five\"",
                          "numerics.viscosity_tolerance=0", "numerics.viscosity_tolerance=0.1"}) {
    expect_refused_naming_its_key(bad);
  }
}

// capsule.tilt and capsule.azimuth: degrees, 0 by default (the in-plane cases, left out of their identities), tilt
// in [0, 90] and azimuth in (−90, 90] (the axis is a line and the flow has the mirror x3 → −x3: case_keys.def).
TEST(CaseConfig, OrientationDefaultsToTheShearPlaneAndIsRangeChecked) {
  const CaseConfig d = parse_case_config("", "empty");
  EXPECT_EQ(d.tilt, 0.0);
  EXPECT_EQ(d.azimuth, 0.0);
  const CaseConfig c = parse_case_config("[capsule]\ntilt = 30\nazimuth = -45.5\n", "case.toml");
  EXPECT_EQ(c.tilt, 30.0);
  EXPECT_EQ(c.azimuth, -45.5);
  EXPECT_EQ(parse_case_config("", "case.toml", {"capsule.tilt=90"}).tilt, 90.0);
  EXPECT_EQ(parse_case_config("", "case.toml", {"capsule.azimuth=90"}).azimuth, 90.0);
  for (const char* bad : {"capsule.tilt=-1", "capsule.tilt=90.5", "capsule.tilt=nan", "capsule.tilt=inf",
                          "capsule.tilt=\"steep\"", "capsule.azimuth=-90", "capsule.azimuth=180",
                          "capsule.azimuth=nan", "capsule.azimuth=\"x1\""}) {
    expect_refused_naming_its_key(bad);
  }
}

}  // namespace
}  // namespace capsim::config

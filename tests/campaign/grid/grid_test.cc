// Grid expansion (exact decimal ranges, unions, duplicates) and case identity stability.
#include <gtest/gtest.h>

#include <set>

#include "campaign/common/bad_input.h"
#include "campaign/grid/campaign_spec.h"
#include "campaign/grid/decimal.h"
#include "campaign/grid/sha256.h"
#include "campaign/grid/case_keys.h"
#include "solver/config/case_config.h"
#include "solver/dynamics/cost_model.h"

namespace capsim::campaign {
namespace {

TEST(Decimal, RangeOfHundredthsHitsTheLiterals) {
  auto pts = expand_decimal_range(Decimal::from_double(0.01), Decimal::from_double(0.10), Decimal::from_double(0.01));
  ASSERT_EQ(pts.size(), 10u);
  const double literals[] = {0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.10};
  for (int i = 0; i < 10; ++i) EXPECT_EQ(pts[i].to_double(), literals[i]) << i;  // exact, no drift
  EXPECT_EQ(pts[6].to_string(), "0.07");
  EXPECT_EQ(pts[9].to_string(), "0.1");
  // The naive floating loop drifts (0.1 + 0.1 + 0.1 != 0.3); the decimal range does not.
  double x = 0.1;
  for (int i = 0; i < 2; ++i) x += 0.1;
  EXPECT_NE(x, 0.3);
  auto tenths = expand_decimal_range(Decimal::from_double(0.1), Decimal::from_double(0.5), Decimal::from_double(0.1));
  EXPECT_EQ(tenths.at(2).to_double(), 0.3);
}

TEST(Decimal, BadRanges) {
  auto d = [](double x) { return Decimal::from_double(x); };
  EXPECT_THROW(expand_decimal_range(d(0.1), d(0.05), d(0.01)), std::invalid_argument);
  EXPECT_THROW(expand_decimal_range(d(0.1), d(0.2), d(0)), std::invalid_argument);
  EXPECT_THROW(expand_decimal_range(d(0.1), d(0.2), d(-0.01)), std::invalid_argument);
  EXPECT_THROW(expand_decimal_range(d(0.1), d(1.0), d(0.2)), std::invalid_argument);  // not a multiple
  EXPECT_THROW(expand_decimal_range(d(0), d(1), d(1e-6)), std::invalid_argument);     // too many points
  EXPECT_EQ(expand_decimal_range(d(0.5), d(0.5), d(0.1)).size(), 1u);
  EXPECT_EQ(expand_decimal_range(d(1), d(3), d(1)).back().to_string(), "3");
}

TEST(Sha256, KnownVectors) {
  // FIPS 180-2, appendix B: one block, two blocks, one million 'a'; and the empty message.
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex(std::string(1000, 'a')).substr(0, 16), "41edece42d63e8d9");
}

const char* kSeedLike = R"(
[campaign]
name = "table1-quick"
[defaults]
mesh.level = 2
capsule.skalak_C = 1.0
[[grid]]
aspect_ratio = [0.5]
law = ["neo-hookean", "skalak"]
capillary_number = { start = 0.01, stop = 0.10, step = 0.01 }
[[grid]]
aspect_ratio = [2.0]
law = ["neo-hookean", "skalak"]
capillary_number = [0.1, 0.2, 0.25, 0.3, 0.35, 0.5]
[analysis]
D12_threshold = 0.05
)";

TEST(Grid, ExpandsTheIssueExample) {
  auto spec = parse_campaign(kSeedLike, "example.toml");
  auto cases = expand_grid(spec);
  EXPECT_EQ(cases.size(), 2u * 10 + 2u * 6);
  std::set<std::string> ids;
  for (const auto& c : cases) {
    ids.insert(c.identity("v1"));
    EXPECT_EQ(c.mesh_level(), 2);
  }
  EXPECT_EQ(ids.size(), cases.size());
  std::set<double> nh_oblate;
  for (const auto& c : cases)
    if (c.law() == "neo-hookean" && c.aspect_ratio() == 0.5) nh_oblate.insert(c.capillary_number());
  EXPECT_EQ(nh_oblate, (std::set<double>{0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.10}));
  EXPECT_EQ(spec.analysis.d12_threshold, 0.05);
}

TEST(Grid, UnionRemovesDuplicatesAcrossBlocks) {
  auto spec = parse_campaign(R"(
[campaign]
name = "dups"
[[grid]]
capillary_number = [0.1, 0.2, 0.1]
[[grid]]
capillary_number = { start = 0.2, stop = 0.4, step = 0.1 }
aspect_ratio = [2]
)", "dups.toml");
  // Default a/b is 2.0, so block 2's 0.2 duplicates block 1's 0.2 (and "2" equals "2.0").
  EXPECT_EQ(expand_grid(spec).size(), 4u);
}

CaseParams base() {
  auto spec = parse_campaign(R"(
[campaign]
name = "one"
[[grid]]
capillary_number = [0.3]
)", "one.toml");
  return expand_grid(spec).at(0);
}

TEST(Identity, StableAndSensitiveToWhatMatters) {
  const CaseParams p = base();
  EXPECT_EQ(p.identity("abc"), base().identity("abc"));
  EXPECT_EQ(p.identity("abc").size(), 16u);
  // The canonical form is the solver's resolved configuration: every result-changing key, no output keys.
  const std::string canon = p.canonical();
  for (const char* k : {"capsule.aspect_ratio=", "capsule.law=", "capsule.skalak_C=", "flow.capillary_number=",
                        "mesh.level=3\n", "time.t_end=", "time.dt=", "time.dt_factor="})
    EXPECT_NE(canon.find(k), std::string::npos) << k << " in " << canon;
  EXPECT_EQ(canon.find("output.snapshot_interval"), std::string::npos) << canon;
  EXPECT_EQ(canon.find("output.checkpoint_interval"), std::string::npos) << canon;
  // An explicit default is the same case as an unset key.
  CaseParams explicit_default = p;
  explicit_default.set("time.dt_factor", 0.25);
  explicit_default.set("numerics.regular_degree", std::int64_t{4});
  EXPECT_EQ(explicit_default.identity("abc"), p.identity("abc"));
  // A key added later (capsule.bending_modulus) at its default is not in the identity at all:
  // every case stored before it keeps its identity (committed_identity_test checks the databases).
  explicit_default.set("capsule.bending_modulus", 0.0);
  EXPECT_EQ(explicit_default.identity("abc"), p.identity("abc"));
  EXPECT_EQ(explicit_default.canonical().find("bending"), std::string::npos);
  explicit_default.set("numerics.kernel_precision", std::string("double"));  // so is numerics.kernel_precision
  EXPECT_EQ(explicit_default.identity("abc"), p.identity("abc"));
  explicit_default.set("flow.viscosity_ratio", 1.0);  // and the viscosity ratio with its solve's tolerance
  explicit_default.set("numerics.viscosity_tolerance", 1e-8);
  EXPECT_EQ(explicit_default.identity("abc"), p.identity("abc"));
  EXPECT_EQ(explicit_default.canonical().find("viscosity"), std::string::npos);
  // Changes that matter.
  for (auto [k, v] : std::vector<std::pair<std::string, Value>>{{"flow.capillary_number", 0.31},
                                                                {"capsule.aspect_ratio", 0.5},
                                                                {"capsule.law", std::string("neo-hookean")},
                                                                {"capsule.skalak_C", 2.0},
                                                                {"mesh.level", std::int64_t{2}},
                                                                {"time.t_end", 30.0},
                                                                {"time.dt", 0.01},
                                                                {"time.dt_factor", 0.2},
                                                                {"time.scheme", std::string("rk2")},
                                                                {"numerics.regular_degree", std::int64_t{6}},
                                                                {"capsule.bending_modulus", 1e-3},
                                                                {"flow.viscosity_ratio", 5.0},
                                                                {"numerics.kernel_precision", std::string("mixed")}}) {
    CaseParams q = p;
    q.set(k, v);
    EXPECT_NE(q.identity("abc"), p.identity("abc")) << k;
  }
  EXPECT_NE(p.identity("abc"), p.identity("abd"));  // solver version
  // Changes that do not: output settings, how a number was typed.
  CaseParams q = p;
  q.set("output.snapshot_interval", 5.0);
  EXPECT_EQ(q.identity("abc"), p.identity("abc"));
  q.set("capsule.aspect_ratio", std::int64_t{2});
  EXPECT_EQ(q.identity("abc"), p.identity("abc"));
  // skalak_C is irrelevant for the neo-Hookean law.
  CaseParams nh1 = p, nh2 = p;
  nh1.set("capsule.law", std::string("neo-hookean"));
  nh2.set("capsule.law", std::string("neo-hookean"));
  nh2.set("capsule.skalak_C", 3.0);
  EXPECT_EQ(nh1.identity("abc"), nh2.identity("abc"));
}

TEST(Identity, SameCaseInTwoCampaignsIsTheSameCase) {
  auto a = expand_grid(parse_campaign("[campaign]\nname='a'\n[defaults]\nflow.capillary_number=0.2\n"
                                      "[[grid]]\naspect_ratio=[0.5]\n", "a.toml"));
  auto b = expand_grid(parse_campaign("[campaign]\nname='b'\n[defaults.capsule]\naspect_ratio=0.5\n"
                                      "[[grid]]\ncapillary_number={start=0.1, stop=0.2, step=0.1}\n", "b.toml"));
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(a[0].identity(solver_version()), b[1].identity(solver_version()));
}

TEST(Grid, CasesTheSolverRejectsAreBadInput) {
  try {
    expand_grid(parse_campaign("[campaign]\nname='x'\n[defaults]\nmesh.spheroid_map='bogus'\n"
                               "[[grid]]\ncapillary_number=[0.1]\n", "x.toml"));
    FAIL() << "expected BadInput";
  } catch (const BadInput& e) {
    EXPECT_NE(std::string(e.what()).find("x.toml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("spheroid_map"), std::string::npos) << e.what();
  }
}

// The bending modulus is a grid axis like the others (alias bending_modulus); 0 is the same case as unset.
// The physical axes beyond the seed's: the first value is the key's default (that case keeps the identity it has
// without the axis), the others give new cases; a value outside the key's range is bad input naming the axis.
struct PhysicalAxis {
  const char* axis;
  const char* values;        // the grid's list, default first
  const char* toml_of_last;  // what the last case's case file says
  const char* out_of_range;
};

void expect_physical_axes(std::initializer_list<PhysicalAxis> axes) {
  for (const PhysicalAxis& a : axes) {
    SCOPED_TRACE(a.axis);
    const auto spec = parse_campaign(std::string("[campaign]\nname='b'\n[defaults]\nflow.capillary_number=0.05\n"
                                                 "[[grid]]\n") + a.axis + "=" + a.values + "\n",
                                     "b.toml");
    const auto cases = expand_grid(spec);
    ASSERT_EQ(cases.size(), 3u);
    CaseParams unset = CaseParams::defaults();
    unset.set("flow.capillary_number", 0.05);
    EXPECT_EQ(cases[0].identity("v"), unset.identity("v"));
    EXPECT_NE(cases[1].identity("v"), cases[0].identity("v"));
    EXPECT_NE(cases[2].identity("v"), cases[1].identity("v"));
    EXPECT_NE(cases[2].to_toml().find(a.toml_of_last), std::string::npos) << cases[2].to_toml();
    try {
      (void)parse_campaign(std::string("[campaign]\nname='b'\n[[grid]]\n") + a.axis + "=" + a.out_of_range + "\n",
                           "b.toml");
      ADD_FAILURE() << "an out-of-range " << a.axis << " was accepted";
    } catch (const BadInput& e) {
      EXPECT_NE(std::string(e.what()).find(a.axis), std::string::npos) << e.what();
    }
  }
}

TEST(Grid, BendingModulusAndViscosityRatioAreAxes) {
  expect_physical_axes({PhysicalAxis{"bending_modulus", "[0, 1e-3, 1e-2]", "bending_modulus = 0.01", "[-1]"},
                        PhysicalAxis{"viscosity_ratio", "[1, 0.2, 5]", "viscosity_ratio = 5", "[25]"}});
}

// The initial orientation (alias tilt: capsule.tilt, azimuth: capsule.azimuth), the axes of a stability study.
TEST(Grid, TiltAndAzimuthAreAxes) {
  expect_physical_axes({PhysicalAxis{"tilt", "[0, 5, 90]", "tilt = 90", "[91]"},
                        PhysicalAxis{"azimuth", "[0, 30, -45]", "azimuth = -45", "[-90]"}});
}

// [analysis] levels: the grid runs on the scan level; a mesh level given elsewhere contradicts it.
TEST(Grid, MultiFidelityLevelsSetTheScanLevel) {
  const std::string head = "[campaign]\nname='mf'\n[[grid]]\ncapillary_number=[0.1, 0.2]\n[analysis]\n";
  const auto spec = parse_campaign(head + "levels = [2, 3, 4]\ndt_check = true\n", "mf.toml");
  EXPECT_EQ(spec.analysis.levels, (std::vector<int>{2, 3, 4}));
  EXPECT_TRUE(spec.analysis.dt_check);
  for (const auto& p : expand_grid(spec)) EXPECT_EQ(p.mesh_level(), 2);
  EXPECT_NE(spec.to_json().find("\"levels\":[2,3,4]"), std::string::npos) << spec.to_json();
  // Without levels the stored JSON is what it was before they existed.
  EXPECT_EQ(parse_campaign(head, "mf.toml").to_json().find("levels"), std::string::npos);
  auto bad = [&](const std::string& text, const std::string& needle) {
    try {
      (void)parse_campaign(text, "mf.toml");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const BadInput& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  bad(head + "levels = [3]\n", "2 or 3 mesh levels");
  bad(head + "levels = [3, 2]\n", "must increase");
  bad(head + "levels = [2, 9]\n", "out of range");
  bad(head + "levels = [2, 3.5]\n", "integers");
  bad(head + "dt_check = true\n", "needs [analysis] levels");
  // check_precision: the check level's numerics.kernel_precision, values from the key registry.
  const auto mixed = parse_campaign(head + "levels = [2, 3, 4]\ncheck_precision = 'mixed'\n", "mf.toml");
  EXPECT_EQ(mixed.analysis.check_precision, "mixed");
  EXPECT_NE(mixed.to_json().find("\"check_precision\":\"mixed\""), std::string::npos) << mixed.to_json();
  EXPECT_EQ(spec.to_json().find("check_precision"), std::string::npos) << "stored only when set";
  bad(head + "levels = [2, 3]\ncheck_precision = 'mixed'\n", "needs a check level");
  bad(head + "levels = [2, 3, 4]\ncheck_precision = 'half'\n", "check_precision");
  bad(head + "levels = [2, 3, 4]\ncheck_precision = 1\n", "expected a string");
  // stop_for_answer: the answer level's cases stop on their answer (analysis/multi_fidelity.h).
  const auto stop = parse_campaign(head + "levels = [2, 3]\nstop_for_answer = true\n", "mf.toml");
  EXPECT_TRUE(stop.analysis.stop_for_answer);
  EXPECT_FALSE(spec.analysis.stop_for_answer) << "off by default";
  EXPECT_NE(stop.to_json().find("\"stop_for_answer\":true"), std::string::npos) << stop.to_json();
  EXPECT_EQ(spec.to_json().find("stop_for_answer"), std::string::npos) << "stored only when set";
  bad(head + "stop_for_answer = true\n", "needs [analysis] levels");
  bad(head + "levels = [2, 3]\nstop_for_answer = 'yes'\n", "expected true or false");
  bad("[campaign]\nname='mf'\n[defaults]\nmesh.level = 3\n[[grid]]\ncapillary_number=[0.1]\n[analysis]\nlevels = [2, 3]\n",
      "[defaults] mesh.level");
  bad("[campaign]\nname='mf'\n[[grid]]\ncapillary_number=[0.1]\nmesh_level=[2]\n[analysis]\nlevels = [2, 3]\n",
      "mesh_level");
}

TEST(Identity, JsonRoundTripKeepsIdentity) {
  CaseParams p = base();
  p.set("mesh.spheroid_map", std::string("equal-arc-length"));
  EXPECT_EQ(CaseParams::from_json(p.to_json()).identity("x"), p.identity("x"));
  EXPECT_THROW(CaseParams::from_json("{\"mesh.lvl\": 2}"), BadInput);
}

// The estimate is the cost model's (solver/dynamics/cost_model.h): mixed precision scales a case by the ratio of
// the model's mixed to double evaluation, and the central symmetry by its evaluation on a quarter of the nodes
// and half the membrane; neither touches the step rule, so the evaluations per unit time cancel.
TEST(CostEstimate, PrecisionAndSymmetryScaleTheEstimateByTheEvaluationModel) {
  using dynamics::CostModel;
  using dynamics::SceneSymmetry;
  for (int level : {2, 3, 4}) {
    CaseParams d = base(), m = base(), c = base();
    d.set("mesh.level", std::int64_t{level});
    m.set("mesh.level", std::int64_t{level});
    c.set("mesh.level", std::int64_t{level});
    m.set("numerics.kernel_precision", std::string("mixed"));
    c.set("numerics.central_symmetry", true);
    EXPECT_NEAR(m.estimated_cost() / d.estimated_cost(),
                CostModel::evaluation_ms(level, SceneSymmetry::kMirror, true) /
                    CostModel::evaluation_ms(level, SceneSymmetry::kMirror, false),
                1e-12);
    EXPECT_NEAR(c.estimated_cost() / d.estimated_cost(),
                CostModel::evaluation_ms(level, SceneSymmetry::kMirrorAndCentral, false) /
                    CostModel::evaluation_ms(level, SceneSymmetry::kMirror, false),
                1e-12);
  }
}

TEST(Grid, CaseTomlHasSections) {
  std::string t = base().to_toml();
  EXPECT_NE(t.find("[flow]\ncapillary_number = 0.3\n"), std::string::npos) << t;
  EXPECT_NE(t.find("[mesh]\nlevel = 3\n"), std::string::npos) << t;
}

}  // namespace
}  // namespace capsim::campaign

namespace capsim::campaign {
namespace {
// The campaign's defaults are the registry's: a case that sets nothing reads the solver's defaults, and
// the keys stored in every case are exactly those the registry marks always_stored.
TEST(CaseKeys, CampaignDefaultsAreTheRegistrys) {
  const CaseParams p = CaseParams::defaults();
  const config::CaseConfig solver;
  EXPECT_EQ(p.capillary_number(), solver.capillary_number);
  EXPECT_EQ(p.aspect_ratio(), solver.aspect_ratio);
  EXPECT_EQ(p.skalak_C(), solver.skalak_C);
  EXPECT_EQ(p.law(), config::word_of(solver.law));
  EXPECT_EQ(p.mesh_level(), solver.level);
  EXPECT_EQ(p.t_end(), solver.t_end);
  for (const auto& k : case_keys()) EXPECT_EQ(p.values().count(k.name) == 1, k.always_stored) << k.name;
  // An empty case (nothing stored at all) falls back to the same defaults.
  const CaseParams empty = CaseParams::from_json("{}");
  EXPECT_EQ(empty.capillary_number(), solver.capillary_number);
  EXPECT_EQ(empty.mesh_level(), solver.level);
}
}  // namespace
}  // namespace capsim::campaign

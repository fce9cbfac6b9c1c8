// The typed group key: the stored text of committed databases, its parse, the cell, the typed axes.
#include "campaign/analysis/group_key.h"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>

#include "campaign/grid/case_params.h"
#include "campaign/store/sqlite_db.h"
#include "campaign/store/store.h"

namespace capsim::campaign {
namespace {

CaseParams a_case(double ca, int level) {
  CaseParams p = CaseParams::defaults();
  p.set("flow.capillary_number", ca);
  p.set("mesh.level", std::int64_t{level});
  p.set("capsule.law", std::string("skalak"));
  p.set("capsule.aspect_ratio", 2.0);
  return p;
}

// Database compatibility: every group key a committed database stores is, bitwise, the key GroupKey::of gives
// one of that campaign's cases, and reads back to the same text. The databases cover a bending axis
// (capsule.bending_modulus in the key), the central symmetry and mixed precision, and several campaigns in one
// file (the certified table).
TEST(GroupKey, TheStoredKeysOfTheCommittedDatabasesAreBitwiseWhatACaseGives) {
  int checked = 0;
  for (const char* name : {"results/table1/table1_mf_mixed.sqlite", "results/bending/table1_bending.sqlite",
                           "results/table1_certified/table1_certified.sqlite"}) {
    auto store = Store::open_readonly(std::string(CAPSIM_SOURCE_DIR) + "/" + name);
    std::map<std::int64_t, std::set<std::string>> of_cases;  // campaign -> keys of its cases
    Stmt cases(store->db(),
               "SELECT cc.campaign_id, c.params_json FROM campaign_cases cc JOIN cases c ON c.case_id=cc.case_id");
    while (cases.step()) of_cases[cases.integer(0)].insert(GroupKey::of(CaseParams::from_json(cases.text(1))).str());
    Stmt stored(store->db(), "SELECT campaign_id, group_key FROM transitions WHERE group_key != ''");
    while (stored.step()) {
      const std::string key = stored.text(1);
      EXPECT_EQ(of_cases[stored.integer(0)].count(key), 1u) << name << ": " << key;
      const auto parsed = GroupKey::parse(key);
      ASSERT_TRUE(parsed) << key;
      EXPECT_EQ(parsed->str(), key);
      ++checked;
    }
  }
  EXPECT_GE(checked, 100);
}

TEST(GroupKey, CasesDifferingInCaPrecisionOrStopTestShareTheKeyOthersDoNot) {
  const CaseParams a = a_case(0.2, 2);
  CaseParams b = a_case(0.35, 2);
  b.set("numerics.kernel_precision", std::string("mixed"));
  b.set("time.stop_test", std::string("min_D12"));
  EXPECT_EQ(GroupKey::of(a), GroupKey::of(b));
  CaseParams c = a_case(0.2, 2);
  c.set("capsule.bending_modulus", 0.01);
  EXPECT_FALSE(GroupKey::of(a) == GroupKey::of(c));
  EXPECT_EQ(GroupKey::of(a).difference(GroupKey::of(c)), "capsule.bending_modulus (unset vs 0.01)");
  EXPECT_EQ(group_difference(GroupKey::of(a).str(), GroupKey::of(c).str()), "capsule.bending_modulus (unset vs 0.01)");
  EXPECT_EQ(GroupKey::of(a).difference(GroupKey::of(a)), "");
}

TEST(GroupKey, TheTypedAxesReadTheKeyOrTheRegistryDefault) {
  CaseParams p = a_case(0.2, 3);
  const GroupKey plain = GroupKey::of(p);
  EXPECT_EQ(plain.law(), "skalak");
  EXPECT_EQ(plain.aspect_ratio(), 2.0);
  EXPECT_EQ(plain.mesh_level(), 3);
  EXPECT_EQ(plain.dt(), "auto");
  EXPECT_FALSE(plain.has("capsule.bending_modulus"));  // at its default: left out, as when it did not exist
  EXPECT_EQ(plain.bending_modulus(), 0.0);
  p.set("capsule.bending_modulus", 0.001);
  p.set("time.dt", 0.01);
  const GroupKey bent = GroupKey::of(p);
  EXPECT_EQ(bent.bending_modulus(), 0.001);
  EXPECT_EQ(bent.dt(), "0.01");
  EXPECT_EQ(bent.text("capsule.law"), "skalak");
  EXPECT_EQ(bent.json_text("capsule.law"), "\"skalak\"");
  EXPECT_EQ(bent.json_text("no.such_key"), "unset");
}

// The cell is the physical question: the levels and the dt/2 checks of one law, a/b and C share it.
TEST(GroupKey, TheCellLeavesOutTheLevelAndTheTimeStep) {
  CaseParams fine = a_case(0.2, 3);
  fine.set("time.dt", 0.01);
  const GroupKey coarse = GroupKey::of(a_case(0.3, 2)), finer = GroupKey::of(fine);
  EXPECT_FALSE(coarse == finer);
  EXPECT_EQ(coarse.cell(), finer.cell());
  EXPECT_FALSE(coarse.cell().has("mesh.level"));
  EXPECT_FALSE(coarse.cell().has("time.dt"));
  EXPECT_EQ(cell_key(finer.str()), coarse.cell().str());
  EXPECT_FALSE(GroupKey::of(a_case(0.3, 2)).cell() == GroupKey::of([] {
    CaseParams p = a_case(0.3, 2);
    p.set("capsule.aspect_ratio", 0.5);
    return p;
  }()).cell());
}

// A version-2 transitions row has no group key (""): no key, its own cell, no difference to name.
TEST(GroupKey, TextThatIsNotAnObjectIsNoKey) {
  EXPECT_FALSE(GroupKey::parse(""));
  EXPECT_FALSE(GroupKey::parse("[1, 2]"));
  EXPECT_EQ(cell_key(""), "");
  EXPECT_EQ(group_difference("", GroupKey::of(a_case(0.2, 2)).str()), "");
}

}  // namespace
}  // namespace capsim::campaign

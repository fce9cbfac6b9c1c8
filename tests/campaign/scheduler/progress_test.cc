// The campaign's ETA (EtaModel): per-level ratios of wall time to estimated cost, so that cheap cases run
// first do not make the expensive rest look cheap.
#include "campaign/scheduler/progress.h"

#include <gtest/gtest.h>

namespace capsim::campaign {
namespace {

TEST(EtaModel, UnknownBeforeAnyCaseFinished) {
  EtaModel m;
  EXPECT_LT(m.expected_s(3, 10.0), 0);
  EXPECT_LT(m.remaining_s({{3, 10.0}}, {}, 2), 0);
}

TEST(EtaModel, EachLevelKeepsItsOwnRatio) {
  // Level 2 costs 1 s per unit of estimate, level 3 0.25 s (the estimate's level law over-counts level 3).
  EtaModel m;
  m.add_done(2, 10.0, 10.0);
  m.add_done(3, 40.0, 10.0);
  EXPECT_DOUBLE_EQ(m.expected_s(2, 5.0), 5.0);
  EXPECT_DOUBLE_EQ(m.expected_s(3, 80.0), 20.0);
  // A level with no finished case borrows the nearest level's ratio (level 3: 0.25 s per unit), corrected from
  // the estimate's 32x per level to the measured 9x: a level-4 case estimated at 32x a level-3 one of 10 s.
  EXPECT_DOUBLE_EQ(m.expected_s(4, 1280.0), 1280.0 * 0.25 * 9.0 / 32.0);
  EXPECT_DOUBLE_EQ(m.expected_s(4, 1280.0), EtaModel::kMeasuredPerLevel * 10.0);
  EXPECT_DOUBLE_EQ(m.expected_s(1, 1.0), 1.0 * 32.0 / 9.0);  // coarser: the other way
}

// Found on a level-2/3 scan run cheapest first: with the level-2 cases done, the first level-3 cases were
// expected to cost 32x their level-2 twins (the estimate's law) where whole cases measure ≈ 9x, and the ETA
// read 8 h for about 1.5 h of work.
TEST(EtaModel, TheFirstCasesOfAFinerLevelAreExpectedAtTheMeasuredFactorPerLevel) {
  EtaModel m;
  for (int i = 0; i < 8; ++i) m.add_done(2, 1.0, 60.0);  // eight level-2 cases of a minute each
  EXPECT_DOUBLE_EQ(m.expected_s(3, 32.0), 9.0 * 60.0);
  EXPECT_DOUBLE_EQ(m.remaining_s(std::vector<std::pair<int, double>>(8, {3, 32.0}), {}, 1), 8 * 9.0 * 60.0);
}

TEST(EtaModel, RemainingCountsThePendingWorkNotTheMeanOfWhatFinished) {
  // Ten cheap level-2 cases done (1 s each), two expensive level-3 cases queued: the remaining time is theirs
  // (the mean finished case, 1 s, would say 2 s).
  EtaModel m;
  for (int i = 0; i < 10; ++i) m.add_done(2, 1.0, 1.0);
  m.add_done(3, 100.0, 50.0);
  EXPECT_DOUBLE_EQ(m.remaining_s({{3, 100.0}, {3, 100.0}}, {}, 2), 50.0);
  // A running case counts what it still needs; one long case does not split between two workers.
  EXPECT_DOUBLE_EQ(m.remaining_s({}, {{3, 400.0, 50.0}}, 2), 150.0);
  EXPECT_DOUBLE_EQ(m.remaining_s({{2, 10.0}}, {{3, 400.0, 250.0}}, 2), 10.0);
  // Only a case past its estimate left: unknown ("?"), not "0s" while it still runs.
  EXPECT_LT(m.remaining_s({}, {{3, 400.0, 250.0}}, 2), 0);
  EXPECT_EQ(format_duration(m.remaining_s({}, {{3, 400.0, 250.0}}, 2)), "?");
}

}  // namespace
}  // namespace capsim::campaign

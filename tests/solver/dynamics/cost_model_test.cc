// The one cost model: its limits (what each part of an evaluation scales as), the symmetry a scene uses, the
// features that change a case's cost. How near it is to measured evaluations is in its header's constants and
// results/benchmarks.md; EtaModel.TheCostModelCarriesACaseAcrossLevels checks it on whole committed cases.
#include "solver/dynamics/cost_model.h"

#include <cstdio>

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "solver/dynamics/capsule_flow.h"
#include "solver/mesh/mesh.h"

namespace capsim::dynamics {
namespace {

constexpr SceneSymmetry kAll[] = {SceneSymmetry::kNone, SceneSymmetry::kMirror, SceneSymmetry::kMirrorAndCentral};

// Per level finer the all-pairs sum grows 16× (targets × sources) and everything else 4× (per node): the
// model's growth lies between, tends to 16 on fine meshes and to 4 on coarse ones, and grows with the level.
TEST(CostModel, AnEvaluationGrowsBetweenFourAndSixteenTimesPerLevel) {
  for (const auto sym : kAll)
    for (const bool mixed : {false, true}) {
      double previous = 4.0;
      for (int level = -4; level < 12; ++level) {
        const double growth = CostModel::evaluation_ms(level + 1, sym, mixed) / CostModel::evaluation_ms(level, sym, mixed);
        EXPECT_GT(growth, previous) << level;
        EXPECT_LT(growth, 16.0) << level;
        previous = growth;
      }
      EXPECT_NEAR(CostModel::evaluation_ms(13, sym, mixed) / CostModel::evaluation_ms(12, sym, mixed), 16.0, 1e-3);
      EXPECT_NEAR(CostModel::evaluation_ms(-7, sym, mixed) / CostModel::evaluation_ms(-8, sym, mixed), 4.0, 1e-3);
    }
}

// The mirror halves the boundary integral's targets, the point symmetry halves them again and the membrane's
// elements too; the layout and the volume correction stay whole. On fine meshes, where the boundary integral is
// all, each symmetry halves an evaluation; on coarse ones less.
TEST(CostModel, EachSymmetryHalvesTheBoundaryIntegral) {
  for (const bool mixed : {false, true})
    for (int level = 0; level <= 6; ++level) {
      const double none = CostModel::evaluation_ms(level, SceneSymmetry::kNone, mixed);
      const double mirror = CostModel::evaluation_ms(level, SceneSymmetry::kMirror, mixed);
      const double central = CostModel::evaluation_ms(level, SceneSymmetry::kMirrorAndCentral, mixed);
      EXPECT_GT(none / mirror, 1.0);
      EXPECT_LT(none / mirror, 2.0);
      EXPECT_GT(mirror / central, 1.0);
      EXPECT_LT(mirror / central, 2.0);
    }
  for (const auto& [finer, coarser] : {std::pair{SceneSymmetry::kNone, SceneSymmetry::kMirror},
                                       std::pair{SceneSymmetry::kMirror, SceneSymmetry::kMirrorAndCentral}})
    EXPECT_NEAR(CostModel::evaluation_ms(12, finer, false) / CostModel::evaluation_ms(12, coarser, false), 2.0, 1e-4);
}

// Mixed precision speeds up the all-pairs sum only: its saving grows with the level, towards kMixedSumSpeedup.
TEST(CostModel, MixedPrecisionSavesMoreOnFinerMeshes) {
  for (const auto sym : kAll) {
    double previous = 1.0;
    for (int level = 0; level <= 8; ++level) {
      const double factor = CostModel::evaluation_ms(level, sym, true) / CostModel::evaluation_ms(level, sym, false);
      EXPECT_LT(factor, previous) << level;
      previous = factor;
    }
    EXPECT_NEAR(CostModel::evaluation_ms(14, sym, true) / CostModel::evaluation_ms(14, sym, false),
                1.0 / CostModel::kMixedSumSpeedup, 1e-3);
  }
}

// The scene's symmetry is what the solver uses: the mirror where the axis starts in the shear plane, the point
// symmetry where numerics.central_symmetry asks for it.
TEST(CostModel, TheSceneUsesTheSymmetryItsKeysAskFor) {
  config::CaseConfig c;
  EXPECT_EQ(CostModel::symmetry(c), SceneSymmetry::kMirror);
  c.central_symmetry = true;
  EXPECT_EQ(CostModel::symmetry(c), SceneSymmetry::kMirrorAndCentral);
  EXPECT_EQ(CostModel::evaluation_ms(c), CostModel::evaluation_ms(c.level, SceneSymmetry::kMirrorAndCentral, false));
  c.kernel_precision = "mixed";
  EXPECT_EQ(CostModel::evaluation_ms(c), CostModel::evaluation_ms(c.level, SceneSymmetry::kMirrorAndCentral, true));
  // An axis out of the shear plane loses the mirror, keeps the point symmetry.
  c.tilt = 30.0;
  EXPECT_EQ(CostModel::symmetry(c), SceneSymmetry::kCentral);
  EXPECT_GT(CostModel::evaluation_ms(c), CostModel::evaluation_ms(c.level, SceneSymmetry::kMirrorAndCentral, true));
  c.central_symmetry = false;
  EXPECT_EQ(CostModel::symmetry(c), SceneSymmetry::kNone);
}

// A case: t_end × the step rule's evaluations per unit time × an evaluation (λ = 1: no double layer). Bending
// stiffness costs through the step rule alone (more RKC stages), not through the evaluation.
TEST(CostModel, ACaseIsItsEvaluationsTimesAnEvaluation) {
  config::CaseConfig c;
  c.level = 2;
  c.capillary_number = 0.1;
  const auto m = mesh::make_capsule_mesh(c.level, c.aspect_ratio);
  const double h = mesh::min_node_spacing(m, m.nodes);
  EXPECT_EQ(CostModel::double_layer_applications(c), 0.0);
  EXPECT_NEAR(CostModel::case_cost(c, h), c.t_end * evaluations_per_unit_time(c, h) * CostModel::evaluation_ms(c) / 1000,
              1e-12 * CostModel::case_cost(c, h));
  config::CaseConfig bent = c;
  bent.bending_modulus = 0.01;
  EXPECT_EQ(CostModel::evaluation_ms(bent), CostModel::evaluation_ms(c));
  EXPECT_GT(CostModel::case_cost(bent, h), 1.5 * CostModel::case_cost(c, h));
  config::CaseConfig longer = c;
  longer.t_end = 2 * c.t_end;
  EXPECT_NEAR(CostModel::case_cost(longer, h), 2 * CostModel::case_cost(c, h), 1e-12 * CostModel::case_cost(c, h));
}

// A viscosity ratio: each evaluation adds the double layer's applications (about 1.1 per decade of the
// tolerance), and the softer membrane takes fewer evaluations (stiffness × 2/(1 + λ)). Checked against the
// measured whole-case ratio of results/benchmarks.md, "The viscosity-ratio evaluation by phase": λ = 5 costs
// 2.7× λ = 1 at the default tolerance and 2.2× at 1e-4 (level 2, a/b = 2, Ca = 0.3, the main preset's numerics,
// the double layer in mixed precision); the model must hold both to within 40 % (it is a cost for ordering and
// the ETA, from constants measured elsewhere). The double layer in double costs more.
TEST(CostModel, AViscosityRatioAddsTheDoubleLayersIterations) {
  config::CaseConfig c;
  c.level = 2;
  c.aspect_ratio = 2.0;
  c.capillary_number = 0.3;
  c.kernel_precision = "mixed";
  c.central_symmetry = true;
  c.rkc_safety = 1.0;
  const auto m = mesh::make_capsule_mesh(c.level, c.aspect_ratio);
  const double h = mesh::min_node_spacing(m, m.nodes);
  config::CaseConfig five = c;
  five.viscosity_ratio = 5.0;
  const double in_double = CostModel::case_cost(five, h);
  five.double_layer_precision = "mixed";
  EXPECT_LT(CostModel::case_cost(five, h), in_double);
  EXPECT_NEAR(CostModel::double_layer_applications(five), 8.8, 1e-12);
  EXPECT_LT(evaluations_per_unit_time(five, h), evaluations_per_unit_time(c, h));
  const double ratio = CostModel::case_cost(five, h) / CostModel::case_cost(c, h);
  EXPECT_GT(ratio, 2.7 / 1.4);
  EXPECT_LT(ratio, 2.7 * 1.4);
  five.viscosity_tolerance = 1e-4;
  const double loose = CostModel::case_cost(five, h) / CostModel::case_cost(c, h);
  EXPECT_GT(loose, 2.2 / 1.4);
  EXPECT_LT(loose, 2.2 * 1.4);
  std::printf("model: λ = 5 case / λ = 1 case = %.2f at tolerance 1e-8 (measured 2.7), %.2f at 1e-4 (2.2)\n", ratio,
              loose);
}

}  // namespace
}  // namespace capsim::dynamics

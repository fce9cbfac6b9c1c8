#include "solver/dynamics/cost_model.h"

#include <cmath>

#include "solver/dynamics/capsule_flow.h"

namespace capsim::dynamics {

SceneSymmetry CostModel::symmetry(const config::CaseConfig& config) {
  return config.central_symmetry ? SceneSymmetry::kMirrorAndCentral : SceneSymmetry::kMirror;
}

double CostModel::evaluation_ms(int level, SceneSymmetry symmetry, bool mixed_precision) {
  const double targets = symmetry == SceneSymmetry::kNone ? 1.0 : symmetry == SceneSymmetry::kMirror ? 2.0 : 4.0;
  const double membrane = symmetry == SceneSymmetry::kMirrorAndCentral ? 2.0 : 1.0;
  const double sum = kRegularSumMs * std::pow(16.0, level - 3) / (mixed_precision ? kMixedSumSpeedup : 1.0);
  const double per_node = std::pow(4.0, level - 3);
  return sum / targets + (kCorrectionsMs / targets + kMembraneMs / membrane + kRestMs) * per_node;
}

double CostModel::evaluation_ms(const config::CaseConfig& config) {
  return evaluation_ms(config.level, symmetry(config), config.kernel_precision == "mixed");
}

double CostModel::solves_per_evaluation(const config::CaseConfig&) { return 1.0; }

double CostModel::case_cost(const config::CaseConfig& config, double h_min) {
  return config.t_end * evaluations_per_unit_time(config, h_min) * evaluation_ms(config) *
         solves_per_evaluation(config) / 1000.0;
}

}  // namespace capsim::dynamics

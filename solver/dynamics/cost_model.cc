#include "solver/dynamics/cost_model.h"

#include <cmath>

#include "solver/dynamics/capsule_flow.h"

namespace capsim::dynamics {

SceneSymmetry CostModel::symmetry(const config::CaseConfig& config) {
  if (config.tilt != 0.0) return config.central_symmetry ? SceneSymmetry::kCentral : SceneSymmetry::kNone;
  return config.central_symmetry ? SceneSymmetry::kMirrorAndCentral : SceneSymmetry::kMirror;
}

namespace {
// The boundary integral's targets and the membrane's elements, as fractions of the whole surface's.
double target_reduction(SceneSymmetry s) {
  return s == SceneSymmetry::kNone ? 1.0 : s == SceneSymmetry::kMirrorAndCentral ? 4.0 : 2.0;
}
double membrane_reduction(SceneSymmetry s) {
  return s == SceneSymmetry::kMirrorAndCentral || s == SceneSymmetry::kCentral ? 2.0 : 1.0;
}
}  // namespace

double CostModel::evaluation_ms(int level, SceneSymmetry symmetry, bool mixed_precision) {
  const double targets = target_reduction(symmetry);
  const double membrane = membrane_reduction(symmetry);
  const double sum = kRegularSumMs * std::pow(16.0, level - 3) / (mixed_precision ? kMixedSumSpeedup : 1.0);
  const double per_node = std::pow(4.0, level - 3);
  return sum / targets + (kCorrectionsMs / targets + kMembraneMs / membrane + kRestMs) * per_node;
}

double CostModel::evaluation_ms(const config::CaseConfig& config) {
  const double single = evaluation_ms(config.level, symmetry(config), config.kernel_precision == "mixed");
  const double applications = double_layer_applications(config);
  if (applications == 0.0) return single;  // λ = 1: the single layer alone
  return single +
         applications * double_layer_ms(config.level, symmetry(config), config.double_layer_precision == "mixed");
}

double CostModel::double_layer_applications(const config::CaseConfig& config) {
  if (config.viscosity_ratio == 1.0) return 0.0;
  return kGmresIterationsPerDecade * -std::log10(config.viscosity_tolerance);
}

double CostModel::double_layer_ms(int level, SceneSymmetry symmetry, bool mixed_precision) {
  const double targets = target_reduction(symmetry);
  const double sum = kRegularSumMs * std::pow(16.0, level - 3) / (mixed_precision ? kMixedSumSpeedup : 1.0);
  return kDoubleLayerPerSingleLayer * (sum + kCorrectionsMs * std::pow(4.0, level - 3)) / targets;
}

double CostModel::case_cost(const config::CaseConfig& config, double h_min) {
  return config.t_end * evaluations_per_unit_time(config, h_min) * evaluation_ms(config) / 1000.0;
}

}  // namespace capsim::dynamics

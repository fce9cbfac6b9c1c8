#include "solver/mesh/p2_tabulation.h"

namespace capsim::mesh {

P2Tabulation::P2Tabulation(const quadrature::TriangleRule& rule) {
  points_.reserve(static_cast<std::size_t>(rule.size()));
  // Barycentric (l0, l1, l2) → parametric (ξ, η) = (l1, l2); ∫_T f dξ dη = ½ Σ w_i f.
  for (int k = 0; k < rule.size(); ++k) points_.push_back(p2_point(rule.points[k][1], rule.points[k][2], 0.5 * rule.weights[k]));
}

P2Tabulation P2Tabulation::at_nodes() {
  static constexpr double local[6][2] = {{0, 0}, {1, 0}, {0, 1}, {0.5, 0}, {0.5, 0.5}, {0, 0.5}};
  std::vector<P2Point> p;
  for (const auto& l : local) p.push_back(p2_point(l[0], l[1], 0.0));
  return P2Tabulation(std::move(p));
}

}  // namespace capsim::mesh

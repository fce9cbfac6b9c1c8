// Wrinkle indicators on states whose answer is known exactly: uniform dilation/compression of a sphere,
// a smooth load (roughness O(h²), falling with refinement) and a mesh-scale checkerboard.
#include "solver/diagnostics/wrinkle.h"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "solver/membrane/membrane_law.h"
#include "solver/membrane/membrane_mechanics.h"
#include "solver/mesh/mesh.h"

namespace capsim::diagnostics {
namespace {

TEST(Wrinkle, CompressedFractionIsZeroWhenInflatedAndOneWhenShrunk) {
  const auto m = mesh::make_capsule_mesh(2, 2.0);
  const membrane::SkalakLaw law(1.0);
  const membrane::MembraneMechanics mech(m, m.nodes, law);  // degree 6
  const Eigen::Matrix3Xd inflated = 1.05 * m.nodes, shrunk = 0.95 * m.nodes;
  EXPECT_EQ(compressed_area_fraction(m, inflated, mech.principal_tensions(inflated), 6), 0.0);
  EXPECT_EQ(compressed_area_fraction(m, shrunk, mech.principal_tensions(shrunk), 6), 1.0);
}

TEST(Wrinkle, CompressedFractionFollowsTheShrunkCap) {
  // Radially stretch the sphere above the plane x1 = c and shrink it below (5%, smooth tanh step). Far from
  // the plane the tensions are isotropic and their sign is that of the radial strain; in the band the plane
  // cuts, the meridional stretch of the step makes the hoop tension of the shrunk side positive over a
  // width ~ 1/20, so the compressed share is a little below the shrunk cap's share of the area (0.45 for
  // c = 0). It must grow with c as the shrunk cap does.
  const auto m = mesh::make_sphere_mesh(3);
  const membrane::NeoHookeanLaw law;
  const membrane::MembraneMechanics mech(m, m.nodes, law);
  double previous = -1;
  for (double c : {-0.5, 0.0, 0.5}) {
    Eigen::Matrix3Xd x = m.nodes;
    for (int i = 0; i < x.cols(); ++i) x.col(i) *= 1.0 + 0.05 * std::tanh(20.0 * (m.nodes(0, i) - c));
    const double f = compressed_area_fraction(m, x, mech.principal_tensions(x), 6);
    // Shrunk cap x1 < c: area share 2π(1 + c)·0.95² over the total (the stretched cap has (1 − c)·1.05²).
    const double cap = (1 + c) * 0.9025 / ((1 + c) * 0.9025 + (1 - c) * 1.1025);
    std::printf("c = %+.1f: compressed fraction %.3f, shrunk-cap share %.3f\n", c, f, cap);
    EXPECT_LT(f, cap);
    EXPECT_GT(f, cap - 0.06);
    EXPECT_GT(f, previous);
    previous = f;
  }
}

TEST(Wrinkle, RoughnessOfSmoothLoadFallsWithRefinementAndCheckerboardIsOrderOne) {
  double previous = 0;
  for (int level = 2; level <= 4; ++level) {
    const auto m = mesh::make_capsule_mesh(level, 2.0);
    // Smooth load: a pressure varying over the surface, q = (1 + x1 x2) n.
    const Eigen::Matrix3Xd n = mesh::node_normals(m, m.nodes);
    Eigen::Matrix3Xd q(3, m.num_nodes());
    for (int i = 0; i < m.num_nodes(); ++i) q.col(i) = (1.0 + m.nodes(0, i) * m.nodes(1, i)) * n.col(i);
    const double r = load_roughness(m, m.nodes, q);
    std::printf("level %d: smooth-load roughness %.3e\n", level, r);
    if (level > 2) {
      EXPECT_GT(previous / r, 3.0) << "O(h²): each level should divide it by ≈ 4";
    }
    previous = r;
    if (level == 4) {
      // Mesh-scale noise of 10% on the same load.
      for (int i = 0; i < m.num_nodes(); ++i) q.col(i) *= 1.0 + 0.1 * ((i * 7919 % 13) % 2 ? 1.0 : -1.0);
      const double noisy = load_roughness(m, m.nodes, q);
      std::printf("level 4 with ±10%% node noise: %.3e\n", noisy);
      EXPECT_GT(noisy, 0.05);
      EXPECT_GT(noisy, 20.0 * r);
    }
  }
}

TEST(Wrinkle, RejectsMismatchedSizes) {
  const auto m = mesh::make_sphere_mesh(1);
  const Eigen::Matrix3Xd q = Eigen::Matrix3Xd::Zero(3, 3);
  EXPECT_THROW((void)load_roughness(m, m.nodes, q), std::invalid_argument);
  std::vector<std::array<double, 2>> t(5);
  EXPECT_THROW((void)compressed_area_fraction(m, m.nodes, t, 6), std::invalid_argument);
  EXPECT_EQ(load_roughness(m, m.nodes, Eigen::Matrix3Xd::Zero(3, m.num_nodes())), 0.0);
}

}  // namespace
}  // namespace capsim::diagnostics

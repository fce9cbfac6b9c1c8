// Choice of the material point P (seed fig. 1: initially on the short axis in the shear plane).
#include "solver/diagnostics/material_point.h"

#include <gtest/gtest.h>

#include "solver/diagnostics/time_series.h"
#include "solver/mesh/mesh.h"

namespace capsim::diagnostics {
namespace {

// Nearest in-plane node to `target`, by brute force, for comparison.
double nearest_in_plane_distance(const mesh::SurfaceMesh& m, const Eigen::Vector3d& target) {
  double best = 1e300;
  for (int i = 0; i < m.num_nodes(); ++i)
    if (m.nodes(2, i) == 0.0) best = std::min(best, (m.nodes.col(i) - target).norm());
  return best;
}

TEST(MaterialPoint, ProlateTakesTheNodeNearestZeroBZero) {
  const auto m = mesh::make_capsule_mesh(3, 2.0);
  const auto [a, b] = mesh::spheroid_semi_axes(2.0);
  const int p = choose_material_point(m, m.nodes);
  const Eigen::Vector3d target(0, b, 0);
  EXPECT_EQ(m.nodes(2, p), 0.0);
  EXPECT_NEAR((m.nodes.col(p) - target).norm(), nearest_in_plane_distance(m, target), 1e-12);
  EXPECT_LT((m.nodes.col(p) - target).norm(), mesh::mesh_quality(m).max_edge);
}

TEST(MaterialPoint, OblateTakesTheNodeNearestAZeroZero) {
  const auto m = mesh::make_capsule_mesh(3, 0.5);
  const auto [a, b] = mesh::spheroid_semi_axes(0.5);
  const int p = choose_material_point(m, m.nodes);
  const Eigen::Vector3d target(a, 0, 0);
  EXPECT_EQ(m.nodes(2, p), 0.0);
  EXPECT_NEAR((m.nodes.col(p) - target).norm(), nearest_in_plane_distance(m, target), 1e-12);
  EXPECT_GT(m.nodes(0, p), 0.0);
}

TEST(MaterialPoint, SphereTakesTheInPlaneNodeNearestPlusX2) {
  const auto m = mesh::make_sphere_mesh(2);
  const int p = choose_material_point(m, m.nodes);
  const Eigen::Vector3d target(0, 1, 0);
  EXPECT_EQ(m.nodes(2, p), 0.0);
  EXPECT_NEAR((m.nodes.col(p) - target).norm(), nearest_in_plane_distance(m, target), 1e-12);
}

TEST(MaterialPoint, MeasureStepRecordsItsPosition) {
  const auto m = mesh::make_capsule_mesh(2, 2.0);
  const int p = choose_material_point(m, m.nodes);
  const StepRecord r = measure_step(m, m.nodes, 1.5, p, -0.25);
  EXPECT_EQ(r.t, 1.5);
  EXPECT_EQ(r.tau_min, -0.25);
  EXPECT_EQ(r.P[0], m.nodes(0, p));
  EXPECT_EQ(r.P[1], m.nodes(1, p));
  EXPECT_EQ(r.P[2], m.nodes(2, p));
  EXPECT_NEAR(r.D12, 1.0 / 3.0, 1e-3);
  EXPECT_GE(r.L1, r.L2);
  EXPECT_THROW(measure_step(m, m.nodes, 0, m.num_nodes(), 0), std::out_of_range);
}

}  // namespace
}  // namespace capsim::diagnostics

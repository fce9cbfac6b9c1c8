// Snapshot node fields: the principal tensions brought to the nodes, and what a snapshot holds.
#include "solver/driver/snapshot_fields.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "solver/driver/case_driver.h"
#include "solver/io/case_file.h"
#include "solver/membrane/membrane_law.h"
#include "solver/membrane/membrane_mechanics.h"
#include "solver/mesh/mesh.h"
#include "solver/quadrature/triangle_rule.h"

namespace capsim::driver {
namespace {

// A uniform tension is reproduced exactly at every node, and the pair order does not matter.
TEST(NodalPrincipalTensions, UniformTensionsAreExactInEitherOrder) {
  const auto mesh = mesh::make_capsule_mesh(1, 2.0);
  const int degree = 6;
  const std::size_t n = static_cast<std::size_t>(mesh.num_elements()) * quadrature::triangle_rule(degree).size();
  std::vector<std::array<double, 2>> tau(n);
  for (std::size_t i = 0; i < n; ++i) tau[i] = (i % 2) ? std::array{0.7, -0.2} : std::array{-0.2, 0.7};
  const NodalTensions t = nodal_principal_tensions(mesh, mesh.nodes, tau, degree);
  ASSERT_EQ(t.tau_min.size(), mesh.num_nodes());
  EXPECT_LT((t.tau_min.array() + 0.2).abs().maxCoeff(), 1e-14);
  EXPECT_LT((t.tau_max.array() - 0.7).abs().maxCoeff(), 1e-14);
}

// An inflated sphere x = 1.1 X is under a uniform isotropic tension (τ1 = τ2 > 0 at every quadrature point,
// up to the P2 geometry error): both nodal fields reproduce it. 1e-3 relative: the discrete sphere is not
// exactly uniform (the mesh maps the sphere with a small spread of element shapes).
TEST(NodalPrincipalTensions, InflatedSphereIsUniformlyStretched) {
  const auto mesh = mesh::make_capsule_mesh(2, 1.0);
  const auto law = membrane::make_law(config::MembraneLawKind::NeoHookean, 1.0);
  const membrane::MembraneMechanics mech(mesh, mesh.nodes, *law, membrane::MembraneMechanics::Options{6});
  const Eigen::Matrix3Xd x = 1.1 * mesh.nodes;
  const auto qp = mech.principal_tensions(x);
  const NodalTensions t = nodal_principal_tensions(mesh, x, qp, 6);
  const double tau = qp.front()[0];
  EXPECT_GT(tau, 0.0);
  EXPECT_LT((t.tau_min.array() - tau).abs().maxCoeff(), 1e-3 * tau);
  EXPECT_LT((t.tau_max.array() - tau).abs().maxCoeff(), 1e-3 * tau);
}

// §3: snapshots hold tau_min and tau_max beside q, q·n and v; tau_min ≤ tau_max everywhere.
TEST(Snapshots, HoldThePrincipalTensions) {
  config::CaseConfig c;
  c.aspect_ratio = 2.0;
  c.capillary_number = 0.3;
  c.level = 1;
  c.t_end = 0.5;
  c.snapshot_interval = 0.2;
  const auto dir = std::filesystem::path(CAPSIM_TEST_TMP) / "driver" / "snapshot_tensions";
  std::filesystem::remove_all(dir);
  RunOptions o;
  o.out_dir = dir;
  ASSERT_EQ(run_case(c, o).status, "done");
  const io::Snapshot s = io::read_snapshot(dir / "case.h5", 2);  // t = 0.4: sheared, compressed somewhere
  const Eigen::MatrixXd* lo = nullptr;
  const Eigen::MatrixXd* hi = nullptr;
  for (const auto& f : s.fields) {
    if (f.name == "tau_min") lo = &f.values;
    if (f.name == "tau_max") hi = &f.values;
  }
  ASSERT_NE(lo, nullptr);
  ASSERT_NE(hi, nullptr);
  ASSERT_EQ(lo->cols(), s.positions.cols());
  EXPECT_TRUE((lo->array() <= hi->array()).all());
  EXPECT_GT(hi->maxCoeff(), 0.0);
  const std::string xmf = [&] {
    std::ifstream in(dir / "case.xmf");
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  EXPECT_NE(xmf.find("Name=\"tau_min\""), std::string::npos);
  EXPECT_NE(xmf.find("Name=\"tau_max\""), std::string::npos);
}

}  // namespace
}  // namespace capsim::driver

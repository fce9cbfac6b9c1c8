// The membrane's spin about the material axis (solver/diagnostics/membrane_spin.h): rigid motions give the rotation's
// component along the axis (α for a turn about it, 0 for a turn about a perpendicular), in any frame; degenerate
// states give NaN; the summary's rate is the mean slope over a window.
#include "solver/diagnostics/membrane_spin.h"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "solver/mesh/mesh.h"

namespace capsim::diagnostics {
namespace {

constexpr double kPi = std::numbers::pi;

// A capsule in a general orientation, off the origin: nothing may depend on the coordinate axes.
mesh::SurfaceMesh oriented_capsule() {
  mesh::SurfaceMesh m = mesh::make_capsule_mesh(1, 2.0);
  mesh::orient_capsule_mesh(m, 30.0, 40.0);
  m.nodes.colwise() += Eigen::Vector3d(0.3, -1.2, 0.7);
  return m;
}

// x turned rigidly by R about the point c.
Eigen::Matrix3Xd turned(const Eigen::Matrix3Xd& x, const Eigen::Matrix3d& R, const Eigen::Vector3d& c) {
  return (R * (x.colwise() - c)).colwise() + c;
}

// The spin accumulated along a sequence of states.
double spin_along(const mesh::SurfaceMesh& m, const std::vector<Eigen::Matrix3Xd>& states) {
  double spin = 0.0;
  for (std::size_t i = 1; i < states.size(); ++i) spin = advance_spin(spin, m, states[i - 1], states[i]);
  return spin;
}

TEST(MembraneSpin, ATurnAboutTheAxisIsItsAngle) {
  const auto m = oriented_capsule();
  const SpinFrame f = spin_frame(m, m.nodes);
  ASSERT_TRUE(f.valid());
  const Eigen::Vector3d c = 0.5 * (m.nodes.col(m.pole_node[0]) + m.nodes.col(m.pole_node[1]));
  // One step (|α| < π), then several turns in steps: the sum is unwrapped, so 2.7 revolutions read as 2.7 · 2π.
  for (const double alpha : {0.3, -1.1, 3.0, -3.0}) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(alpha, f.axis).toRotationMatrix();
    EXPECT_NEAR(spin_along(m, {m.nodes, turned(m.nodes, R, c)}), alpha, 1e-13) << alpha;
  }
  for (const double total : {2.7 * 2 * kPi, -1.4 * 2 * kPi}) {
    std::vector<Eigen::Matrix3Xd> states{m.nodes};
    const int n = 40;
    for (int i = 1; i <= n; ++i)
      states.push_back(turned(m.nodes, Eigen::AngleAxisd(total * i / n, f.axis).toRotationMatrix(), c));
    EXPECT_NEAR(spin_along(m, states), total, 1e-12) << total;
  }
}

TEST(MembraneSpin, ATurnOfTheAxisWithoutSpinIsZero) {
  // Turns about axes perpendicular to the material axis, through any point (a translation is no spin either): the
  // axis moves, the membrane does not turn about it. Large single steps too: the transport is exact, not only in
  // the limit of small steps.
  const auto m = oriented_capsule();
  const SpinFrame f = spin_frame(m, m.nodes);
  const Eigen::Vector3d e1 = f.axis.unitOrthogonal(), e2 = f.axis.cross(e1);
  for (const double psi : {0.0, 0.9, 2.0, -2.6}) {
    const Eigen::Vector3d k = std::cos(psi) * e1 + std::sin(psi) * e2;  // ⟂ the axis
    for (const double beta : {0.2, 1.3, -2.5}) {
      const Eigen::Matrix3d R = Eigen::AngleAxisd(beta, k).toRotationMatrix();
      const Eigen::Vector3d centre(1.0, 2.0, -0.5);
      EXPECT_NEAR(spin_along(m, {m.nodes, turned(m.nodes, R, centre)}), 0.0, 1e-13) << psi << " " << beta;
      std::vector<Eigen::Matrix3Xd> states{m.nodes};
      for (int i = 1; i <= 10; ++i)
        states.push_back(turned(m.nodes, Eigen::AngleAxisd(beta * i / 10, k).toRotationMatrix(), centre));
      EXPECT_NEAR(spin_along(m, states), 0.0, 1e-12) << psi << " " << beta;
    }
  }
}

TEST(MembraneSpin, ARigidRotationSpinsAtItsAngularVelocityAlongTheAxis) {
  // A rigid body turning at a constant ω: the axis runs round a cone about ω, and the spin rate is ω·p (constant on
  // the cone). The step sum converges to ω·p T as the steps shrink; turning the whole history by a fixed rotation
  // (another frame) changes nothing.
  const auto m = oriented_capsule();
  const Eigen::Vector3d omega = 0.8 * Eigen::Vector3d(1.0, 2.0, 2.0).normalized();
  const Eigen::Vector3d c(0.3, -1.2, 0.7);
  const double T = 3.0;
  const double exact = omega.dot(spin_frame(m, m.nodes).axis) * T;
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(1.0, Eigen::Vector3d(-1.0, 0.5, 0.2).normalized()).toRotationMatrix();
  double prev_err = INFINITY;
  for (const int n : {10, 100, 1000}) {
    std::vector<Eigen::Matrix3Xd> states, in_other_frame;
    for (int i = 0; i <= n; ++i) {
      const double t = T * i / n;
      states.push_back(turned(m.nodes, Eigen::AngleAxisd(omega.norm() * t, omega.normalized()).toRotationMatrix(), c));
      in_other_frame.push_back(Q * states.back());
    }
    const double spin = spin_along(m, states);
    const double err = std::abs(spin - exact);
    std::printf("rigid rotation, %d steps: spin %.12f, exact %.12f, error %.2e\n", n, spin, exact, err);
    // Second order in the step: each step's δ is the exact twist about p of a finite turn by θ = |ω| dt,
    // 2 atan(tan(θ/2) ω̂·p), which differs from ω·p dt by O(dt³).
    if (std::isfinite(prev_err)) {
      EXPECT_GT(prev_err / err, 50.0) << n << " steps";
    }
    prev_err = err;
    EXPECT_NEAR(spin_along(m, in_other_frame), spin, 1e-12) << "frame independence";
  }
  EXPECT_LT(prev_err, 1e-4 * std::abs(exact));
}

TEST(MembraneSpin, DegenerateStatesGiveNaNAndStayNaN) {
  const auto m = oriented_capsule();
  // No pole or equator node: no frame.
  for (int which = 0; which < 2; ++which) {
    mesh::SurfaceMesh bare = m;
    if (which == 0) bare.pole_node = {-1, -1};
    if (which == 1) bare.equator_node = -1;
    EXPECT_FALSE(spin_frame(bare, bare.nodes).valid());
    EXPECT_TRUE(std::isnan(advance_spin(0.0, bare, bare.nodes, bare.nodes)));
  }
  // Poles that coincide.
  Eigen::Matrix3Xd x = m.nodes;
  x.col(m.pole_node[1]) = x.col(m.pole_node[0]);
  EXPECT_FALSE(spin_frame(m, x).valid());
  // The equator node on the axis.
  x = m.nodes;
  x.col(m.equator_node) = 0.25 * x.col(m.pole_node[0]) + 0.75 * x.col(m.pole_node[1]);
  EXPECT_FALSE(spin_frame(m, x).valid());
  EXPECT_TRUE(std::isnan(advance_spin(0.0, m, m.nodes, x)));
  // An axis reversed in one step (a half-turn about a perpendicular): the transport is undefined.
  const SpinFrame f = spin_frame(m, m.nodes);
  const Eigen::Matrix3d half = Eigen::AngleAxisd(kPi, f.axis.unitOrthogonal()).toRotationMatrix();
  EXPECT_TRUE(std::isnan(advance_spin(0.0, m, m.nodes, turned(m.nodes, half, Eigen::Vector3d::Zero()))));
  // NaN stays NaN through later, measurable steps.
  EXPECT_TRUE(std::isnan(advance_spin(std::nan(""), m, m.nodes, m.nodes)));
  // A valid step that does not move gives exactly 0.
  EXPECT_EQ(advance_spin(1.5, m, m.nodes, m.nodes), 1.5);
  EXPECT_THROW(spin_frame(m, Eigen::Matrix3Xd::Zero(3, 4)), std::invalid_argument);
}

TEST(MembraneSpin, FinalSpinRateIsTheMeanSlopeOverTheWindow) {
  TimeSeries s;
  for (int i = 0; i <= 100; ++i) {
    StepRecord r;
    r.t = 0.1 * i;
    r.spin = -0.5 * r.t + 0.2 * std::sin(3.0 * r.t);  // a mean rate with a wobble, as a tank-treading node
    s.push_back(r);
  }
  auto spin = [](double t) { return -0.5 * t + 0.2 * std::sin(3.0 * t); };
  EXPECT_NEAR(final_spin_rate(s, 2.0, 8.0), (spin(8.0) - spin(2.0)) / 6.0, 1e-12);
  // Bounds between samples: the spin linear between them.
  const double a = 0.5 * (spin(2.0) + spin(2.1)), b = 0.5 * (spin(7.9) + spin(8.0));
  EXPECT_NEAR(final_spin_rate(s, 2.05, 7.95), (b - a) / 5.9, 1e-12);
  // Clipped to the series; an empty window is no rate.
  EXPECT_NEAR(final_spin_rate(s, -5.0, 20.0), (spin(10.0) - spin(0.0)) / 10.0, 1e-12);
  EXPECT_TRUE(std::isnan(final_spin_rate(s, 10.0, 10.0)));
  EXPECT_TRUE(std::isnan(final_spin_rate(s, std::nan(""), std::nan(""))));
  EXPECT_TRUE(std::isnan(final_spin_rate(TimeSeries{}, 0.0, 1.0)));
  // A NaN inside the window (a step that could not be measured) leaves the rate unknown; outside it, not.
  s.spin[50] = std::nan("");
  EXPECT_TRUE(std::isnan(final_spin_rate(s, 2.0, 8.0)));
  EXPECT_NEAR(final_spin_rate(s, 6.0, 8.0), (spin(8.0) - spin(6.0)) / 2.0, 1e-12);
}

}  // namespace
}  // namespace capsim::diagnostics

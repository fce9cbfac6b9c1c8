// Shape moments and ellipsoid of inertia on meshed spheres and spheroids (solver/README.md §5).
#include "solver/diagnostics/shape_moments.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <numbers>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "solver/mesh/mesh.h"

namespace capsim::diagnostics {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(ShapeMoments, SphereVolumeAndAreaConvergeAtHighOrder) {
  // Each level halves h: the order is log2 of the error ratio.
  std::vector<double> ev, ea;
  for (int level = 1; level <= 4; ++level) {
    const auto m = mesh::make_sphere_mesh(level);
    const auto s = shape_moments(m, m.nodes);
    ev.push_back(std::abs(s.volume - 4.0 * kPi / 3.0));
    ea.push_back(std::abs(s.area - 4.0 * kPi));
    std::printf("level %d: |V − 4π/3| = %.3e, |A − 4π| = %.3e\n", level, ev.back(), ea.back());
  }
  for (std::size_t i = 1; i < ev.size(); ++i) {
    const double pv = std::log2(ev[i - 1] / ev[i]), pa = std::log2(ea[i - 1] / ea[i]);
    std::printf("order level %zu→%zu: volume %.2f, area %.2f\n", i, i + 1, pv, pa);
    // P2 interpolation of the sphere: position error O(h^3), volume and area superconverge to O(h^4).
    EXPECT_GT(pv, 3.7);
    EXPECT_GT(pa, 3.7);
  }
  EXPECT_LT(ev.back() / (4.0 * kPi / 3.0), 1e-5);
  EXPECT_LT(ea.back() / (4.0 * kPi), 1e-5);
}

TEST(ShapeMoments, SphereIsCentredAndIsotropic) {
  // The subdivided icosahedron keeps the icosahedral symmetry, under which a second-order tensor is
  // isotropic: M = m I and c = 0 to round-off at every level, and m → 4π/15 (unit ball) at O(h^4).
  std::vector<double> err;
  for (int level = 2; level <= 4; ++level) {
    const auto m = mesh::make_sphere_mesh(level);
    const auto s = shape_moments(m, m.nodes);
    EXPECT_LT(s.centroid.norm(), 1e-14);
    const double mean = s.second_moment.trace() / 3;
    EXPECT_LT((s.second_moment - mean * Eigen::Matrix3d::Identity()).norm(), 1e-13);
    const auto el = ellipsoid_of_inertia(s);
    EXPECT_NEAR(el.L1, el.L2, 1e-13);
    EXPECT_NEAR(el.L1, el.L3, 1e-13);
    EXPECT_LT(el.D12, 1e-13);
    err.push_back(std::abs(mean - 4.0 * kPi / 15.0));
    std::printf("sphere level %d: |M_ii − 4π/15| = %.2e, |L − 1| = %.2e\n", level, err.back(), std::abs(el.L1 - 1));
  }
  EXPECT_GT(std::log2(err[1] / err[2]), 3.7);
  EXPECT_LT(err.back(), 2e-6);
}

// Spheroids a/b = 2 (prolate) and 0.5 (oblate), both D12 = 1/3 in the shear plane (solver/README.md §1).
class SpheroidMoments : public ::testing::TestWithParam<double> {};

TEST_P(SpheroidMoments, EllipsoidOfInertiaRecoversSemiAxesAndD12) {
  const double r = GetParam();
  const auto [a, b] = mesh::spheroid_semi_axes(r);
  // In the shear plane: semi-axis a along x1, b along x2; the longer is L1.
  const double L1 = std::max(a, b), L2 = std::min(a, b);
  const double theta = a >= b ? 0.0 : kPi / 2;
  double prev_D12 = 1, prev_L = 1, prev_V = 1;
  for (int level = 1; level <= 4; ++level) {
    const auto m = mesh::make_capsule_mesh(level, r);
    const auto s = shape_moments(m, m.nodes);
    const auto el = ellipsoid_of_inertia(s);
    const double eV = std::abs(s.volume - 4.0 * kPi / 3.0);  // a b² = 1
    const double eL = std::max({std::abs(el.L1 - L1), std::abs(el.L2 - L2), std::abs(el.L3 - b)});
    const double eD = std::abs(el.D12 - 1.0 / 3.0);
    std::printf("a/b = %.1f level %d: |V − 4π/3| = %.2e, max|L − exact| = %.2e, |D12 − 1/3| = %.2e, θ = %.6f\n",
                r, level, eV, eL, eD, el.theta);
    EXPECT_LT(eD, prev_D12) << "D12 error must decrease with level";
    EXPECT_LT(eL, prev_L);
    EXPECT_LT(eV, prev_V);
    prev_D12 = eD, prev_L = eL, prev_V = eV;
    // θ modulo π: the oblate long axis is x2, θ = π/2 up to round-off (which may give −π/2 + ε).
    EXPECT_LT(std::abs(std::remainder(el.theta - theta, kPi)), 1e-10);
    EXPECT_LE(el.theta, kPi / 2);
    EXPECT_GT(el.theta, -kPi / 2);
  }
  EXPECT_LT(prev_D12, 1e-4);
  EXPECT_LT(prev_L, 1e-4);
}

INSTANTIATE_TEST_SUITE_P(AspectRatios, SpheroidMoments, ::testing::Values(2.0, 0.5));

TEST(ShapeMoments, RotatedAndTranslatedSpheroidGivesItsInclination) {
  const auto m = mesh::make_capsule_mesh(3, 2.0);
  const auto ref = ellipsoid_of_inertia(shape_moments(m, m.nodes));
  const Eigen::Vector3d shift(3.0, -7.0, 0.5);
  for (double alpha : {0.3, -1.0, 1.4, -1.5, 1.5707, 2.5}) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix3Xd x = (R * m.nodes).colwise() + shift;
    const auto s = shape_moments(m, x);
    const auto el = ellipsoid_of_inertia(s);
    // Expected inclination: alpha brought into (−π/2, π/2].
    double expected = std::remainder(alpha, kPi);
    if (expected <= -kPi / 2) expected += kPi;
    EXPECT_NEAR(el.theta, expected, 1e-10) << "alpha = " << alpha;
    EXPECT_NEAR(el.L1, ref.L1, 1e-12);
    EXPECT_NEAR(el.L2, ref.L2, 1e-12);
    EXPECT_NEAR(el.D12, ref.D12, 1e-12);
    EXPECT_LT((s.centroid - shift).norm(), 1e-12);
  }
}

TEST(ShapeMoments, AffineMapTransformsMomentsExactly) {
  // P2 geometry commutes with affine maps and the volume integrand is of degree 4 (exact for the rule):
  // V' = det(A) V to round-off, and the centred moments transform as det(A) A M Aᵀ.
  const auto m = mesh::make_capsule_mesh(2, 0.5);
  Eigen::Matrix3d A;
  A << 1.3, 0.2, -0.1, 0.05, 0.8, 0.3, -0.2, 0.1, 1.1;
  const Eigen::Matrix3Xd x = (A * m.nodes).colwise() + Eigen::Vector3d(0.4, 0.1, -2.0);
  const auto s0 = shape_moments(m, m.nodes);
  const auto s1 = shape_moments(m, x);
  const double detA = A.determinant();
  EXPECT_NEAR(s1.volume, detA * s0.volume, 1e-13);
  EXPECT_LT((s1.centroid - (A * s0.centroid + Eigen::Vector3d(0.4, 0.1, -2.0))).norm(), 1e-13);
  EXPECT_LT((s1.second_moment - detA * A * s0.second_moment * A.transpose()).norm(), 1e-13);
}

TEST(ShapeMoments, RuleDegreeOnlyAffectsSecondMomentsBelowTheGeometricError) {
  const auto m = mesh::make_capsule_mesh(2, 2.0);
  const auto s4 = shape_moments(m, m.nodes, 4);
  const auto s5 = shape_moments(m, m.nodes, 5);
  const auto s6 = shape_moments(m, m.nodes, 6);
  // Volume: exact with any rule of degree ≥ 4, so equal up to the round-off of summing 320 × 12 terms.
  EXPECT_NEAR(s4.volume, s6.volume, 1e-13 * s6.volume);
  EXPECT_NEAR(s5.volume, s6.volume, 1e-13 * s6.volume);
  // Second moments: the quadrature differences are far below the level-2 geometric error of L (≈1e-4).
  const double d4 = (s4.second_moment - s6.second_moment).norm();
  const double d5 = (s5.second_moment - s6.second_moment).norm();
  std::printf("level 2, a/b = 2: |M(deg 4) − M(deg 6)| = %.2e, |M(deg 5) − M(deg 6)| = %.2e\n", d4, d5);
  EXPECT_LT(d4, 1e-6);
  EXPECT_LT(d5, 1e-6);
}

TEST(ShapeMoments, RejectsMismatchedPositions) {
  const auto m = mesh::make_sphere_mesh(1);
  EXPECT_THROW(shape_moments(m, Eigen::Matrix3Xd::Zero(3, 5)), std::invalid_argument);
}

// The expected direction of an axis under the sign rule of EllipsoidOfInertia3D (x1 component positive, else x2,
// else x3), for a direction whose x1 component is clearly nonzero or exactly zero.
Eigen::Vector3d oriented(Eigen::Vector3d e) {
  const double decider = std::abs(e.x()) > 1e-9 ? e.x() : std::abs(e.y()) > 1e-9 ? e.y() : e.z();
  return decider < 0 ? (-e).eval() : e;
}

TEST(EllipsoidOfInertia3D, RotatedTriaxialEllipsoidGivesItsSemiAxesAndTheRotationsColumns) {
  // The a/b = 2 spheroid mesh (semi-axes a, b, b; nodes placed along meridians of x1 by the equal-arc-length map)
  // squeezed along x3 to c = 0.6 b: every node on the exact ellipsoid (a, b, c), three distinct semi-axes. Then
  // turned by a rotation about an oblique axis and shifted: the ellipsoid of inertia must give (a, b, c) along
  // R e1, R e2, R e3.
  const auto [a, b] = mesh::spheroid_semi_axes(2.0);
  const double c = 0.6 * b;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  const Eigen::Vector3d shift(-2.0, 0.5, 1.5);
  double prev = 1.0;
  for (int level = 1; level <= 4; ++level) {
    const auto m = mesh::make_capsule_mesh(level, 2.0);
    Eigen::Matrix3Xd x = m.nodes;
    x.row(2) *= 0.6;
    x = ((R * x).colwise() + shift).eval();
    const auto el = ellipsoid_of_inertia_3d(shape_moments(m, x));
    const double err = std::max({std::abs(el.La - a), std::abs(el.Lb - b), std::abs(el.Lc - c)});
    std::printf("triaxial level %d: La %.8f Lb %.8f Lc %.8f, max|L − exact| = %.2e\n", level, el.La, el.Lb, el.Lc, err);
    EXPECT_LT(err, prev) << "the semi-axes converge under refinement";
    prev = err;
    EXPECT_GE(el.La, el.Lb);
    EXPECT_GE(el.Lb, el.Lc);
    // The mesh keeps the sign symmetries of the coordinate axes, so the principal directions are the rotation's
    // columns at every level, to round-off, each oriented by the sign rule.
    for (int k = 0; k < 3; ++k) {
      EXPECT_LT((el.axes[k] - oriented(R.col(k))).norm(), 1e-10) << "level " << level << " axis " << k;
      EXPECT_NEAR(el.axes[k].norm(), 1.0, 1e-14);
    }
  }
  EXPECT_LT(prev, 1e-4);
}

TEST(EllipsoidOfInertia3D, InThePlaneItIsTheInPlaneEllipsoidAndX3) {
  // A shape symmetric under x3 → −x3 has x3 as a principal direction and the other two in the shear plane: the 3D
  // ellipsoid must be the in-plane one (L1, L2 at θ) plus L3 along x3, whatever order the three semi-axes take.
  // The seed's spheroids at several inclinations, and a sheared and squeezed one (three distinct semi-axes).
  Eigen::Matrix3d shear;
  shear << 1.0, 0.35, 0.0, 0.1, 0.9, 0.0, 0.0, 0.0, 0.8;
  for (double r : {2.0, 0.5}) {
    for (double alpha : {0.0, 0.4, -1.2, kPi / 2}) {
      for (bool sheared : {false, true}) {
        const auto m = mesh::make_capsule_mesh(3, r);
        Eigen::Matrix3d A = Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitZ()).toRotationMatrix();
        if (sheared) A = (shear * A).eval();
        const ShapeMoments s = shape_moments(m, A * m.nodes);
        const EllipsoidOfInertia in_plane = ellipsoid_of_inertia(s);
        const EllipsoidOfInertia3D el = ellipsoid_of_inertia_3d(s);
        const std::string what = "a/b " + std::to_string(r) + " alpha " + std::to_string(alpha) +
                                 (sheared ? " sheared" : "");
        // The same three semi-axes.
        std::array<double, 3> expected{in_plane.L1, in_plane.L2, in_plane.L3};
        std::sort(expected.rbegin(), expected.rend());
        EXPECT_NEAR(el.La, expected[0], 1e-12) << what;
        EXPECT_NEAR(el.Lb, expected[1], 1e-12) << what;
        EXPECT_NEAR(el.Lc, expected[2], 1e-12) << what;
        // The in-plane axes where the semi-axis is not shared with another (a spheroid's two equal ones have no
        // defined directions): L1 along (cos θ, sin θ, 0), L2 perpendicular in the plane, L3 along +x3.
        const Eigen::Vector3d e1(std::cos(in_plane.theta), std::sin(in_plane.theta), 0.0);
        const Eigen::Vector3d e2(-std::sin(in_plane.theta), std::cos(in_plane.theta), 0.0);
        const std::array<std::pair<double, Eigen::Vector3d>, 3> in{
            std::pair{in_plane.L1, e1}, std::pair{in_plane.L2, e2}, std::pair{in_plane.L3, Eigen::Vector3d::UnitZ().eval()}};
        const std::array<double, 3> L{el.La, el.Lb, el.Lc};
        for (const auto& [Lk, ek] : in) {
          int distinct = 0;
          for (const auto& [Lj, ej] : in) distinct += std::abs(Lj - Lk) > 1e-6;
          if (distinct != 2) continue;
          const int k = static_cast<int>(std::min_element(L.begin(), L.end(), [&](double p, double q) {
                                           return std::abs(p - Lk) < std::abs(q - Lk);
                                         }) - L.begin());
          EXPECT_LT((el.axes[k] - oriented(ek)).norm(), 1e-9) << what << " semi-axis " << Lk;
        }
      }
    }
  }
}

TEST(EllipsoidOfInertia3D, DirectionsFollowTheSignRuleThroughAHalfTurn) {
  // A triaxial body turning about x3 (tumbling in the plane): the long axis is (cos θ, sin θ, 0) with θ in
  // (−π/2, π/2], the same line the in-plane θ names, and the third axis stays +x3 (never flipped by round-off).
  const auto m = mesh::make_capsule_mesh(2, 2.0);
  Eigen::Matrix3Xd x0 = m.nodes;
  x0.row(2) *= 0.7;
  for (int i = -8; i <= 8; ++i) {
    const double alpha = i * kPi / 16;
    const Eigen::Matrix3Xd x = Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitZ()).toRotationMatrix() * x0;
    const ShapeMoments s = shape_moments(m, x);
    const auto el = ellipsoid_of_inertia_3d(s);
    const auto in_plane = ellipsoid_of_inertia(s);
    EXPECT_LT((el.axes[0] - Eigen::Vector3d(std::cos(in_plane.theta), std::sin(in_plane.theta), 0.0)).norm(), 1e-12)
        << "alpha " << alpha;
    EXPECT_GT(el.axes[0].x(), i == 8 || i == -8 ? -1e-9 : 0.0);
    EXPECT_EQ(el.axes[2].z() > 0.0, true) << "alpha " << alpha;
    EXPECT_NEAR(el.axes[2].z(), 1.0, 1e-12);
  }
}

TEST(EllipsoidOfInertia3D, RejectsAnEmptyVolume) {
  EXPECT_THROW(ellipsoid_of_inertia_3d(ShapeMoments{}), std::invalid_argument);
}

}  // namespace
}  // namespace capsim::diagnostics

// The orientation diagnostics: the material axis through the pole nodes, its tilt out of the shear plane and the
// azimuth of its projection (solver/README.md, Orientation), and the summary's final_tilt.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "solver/diagnostics/time_series.h"
#include "solver/mesh/mesh.h"

namespace capsim::diagnostics {
namespace {

TEST(MaterialAxis, ReadsBackTheOrientationOfARotatedCapsule) {
  for (const double tilt : {0.0, 10.0, 45.0, 89.0, 90.0})
    for (const double azimuth : {-80.0, -30.0, 0.0, 60.0, 90.0}) {
      mesh::SurfaceMesh m = mesh::make_capsule_mesh(1, 2.0);
      mesh::orient_capsule_mesh(m, tilt, azimuth);
      const MaterialAxis ax = material_axis(m, m.nodes);
      EXPECT_NEAR(ax.tilt, tilt, 1e-12) << tilt << " " << azimuth;
      if (tilt < 90.0) {
        EXPECT_NEAR(ax.azimuth, azimuth, 1e-12) << tilt << " " << azimuth;
      }
      const Eigen::Vector3d p = mesh::axis_of_orientation(tilt, azimuth);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(ax.axis[k], p(k), 1e-15);
      const StepRecord r = measure_step(m, m.nodes, 0.0, 0, 0.0);
      EXPECT_EQ(r.axis_tilt, ax.tilt);
      EXPECT_EQ(r.axis_azimuth, ax.azimuth);
    }
}

// The axis is a line: turned by 180° (the material vector reversed) the tilt and azimuth are the same; the azimuth
// is folded into (−90, 90] as the inclination θ is.
TEST(MaterialAxis, TiltAndAzimuthAreThoseOfALine) {
  mesh::SurfaceMesh m = mesh::make_capsule_mesh(1, 2.0);
  mesh::orient_capsule_mesh(m, 20.0, 50.0);
  const Eigen::Matrix3Xd flipped = -m.nodes;  // x → −x swaps the poles: the vector reverses, the line does not
  const MaterialAxis a = material_axis(m, m.nodes), b = material_axis(m, flipped);
  EXPECT_NEAR(b.tilt, a.tilt, 1e-12);
  EXPECT_NEAR(b.azimuth, a.azimuth, 1e-12);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(b.axis[k], -a.axis[k], 1e-15);
  // Mirror image x3 → −x3: same tilt (unsigned) and azimuth.
  Eigen::Matrix3Xd mirrored = m.nodes;
  mirrored.row(2) *= -1.0;
  EXPECT_NEAR(material_axis(m, mirrored).tilt, 20.0, 1e-12);
  EXPECT_NEAR(material_axis(m, mirrored).azimuth, 50.0, 1e-12);
  // Projection at 100° from x1 reads as −80°.
  mesh::SurfaceMesh n = mesh::make_capsule_mesh(1, 2.0);
  const double t = 100.0 * std::numbers::pi / 180.0;
  Eigen::Matrix3d rz;
  rz << std::cos(t), -std::sin(t), 0, std::sin(t), std::cos(t), 0, 0, 0, 1;
  const Eigen::Matrix3Xd turned = rz * n.nodes;
  EXPECT_NEAR(material_axis(n, turned).azimuth, -80.0, 1e-12);
}

TEST(MaterialAxis, FinalTiltIsTheMeanOverTheLastPeriodElseTheLastValue) {
  TimeSeries s;
  for (int i = 0; i <= 100; ++i) {
    StepRecord r;
    r.t = 0.1 * i;
    r.axis_tilt = 2.0 * r.t;  // linear: its mean over [a, b] is a + b
    s.push_back(r);
  }
  EXPECT_NEAR(final_tilt(s, 4.0, 8.0), 12.0, 1e-12);
  EXPECT_NEAR(final_tilt(s, 4.05, 7.95), 12.0, 1e-12) << "bounds between samples";
  EXPECT_EQ(final_tilt(s, 10.0, 10.0), 20.0) << "no period: the last value";
  EXPECT_EQ(final_tilt(s, std::nan(""), std::nan("")), 20.0);
  EXPECT_TRUE(std::isnan(final_tilt(TimeSeries{}, 0.0, 1.0)));
}

}  // namespace
}  // namespace capsim::diagnostics

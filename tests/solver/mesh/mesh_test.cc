#include "solver/mesh/mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <numbers>
#include <set>

#include <gtest/gtest.h>

namespace capsim::mesh {
namespace {

TEST(SphereMesh, CountsFollowTheIcosahedronSubdivision) {
  const int elements[] = {20, 80, 320, 1280, 5120};
  const int nodes[] = {42, 162, 642, 2562, 10242};
  for (int level = 0; level <= 4; ++level) {
    const SurfaceMesh m = make_sphere_mesh(level);
    EXPECT_EQ(m.num_elements(), elements[level]);
    EXPECT_EQ(m.num_nodes(), nodes[level]);
    int vertices = 0;
    for (auto k : m.kind) vertices += k == NodeKind::Vertex;
    EXPECT_EQ(vertices, 10 * (1 << (2 * level)) + 2);
  }
}

TEST(SphereMesh, NodesOnUnitSphereAndElementsOutward) {
  const SurfaceMesh m = make_sphere_mesh(3);
  // Exact geometry: nodes are normalised, so |x| = 1 up to the rounding of a normalisation (a few ulps).
  for (int i = 0; i < m.num_nodes(); ++i) EXPECT_NEAR(m.nodes.col(i).norm(), 1.0, 1e-15);
  for (const auto& e : m.elements) {
    const Eigen::Vector3d n = (m.nodes.col(e[1]) - m.nodes.col(e[0])).cross(m.nodes.col(e[2]) - m.nodes.col(e[0]));
    EXPECT_GT(n.dot(m.nodes.col(e[0])), 0.0);
  }
}

TEST(SphereMesh, EveryEdgeSharedByTwoElements) {
  const SurfaceMesh m = make_sphere_mesh(2);
  std::vector<int> count(m.num_nodes(), 0);
  for (const auto& e : m.elements)
    for (int a = 3; a < 6; ++a) ++count[e[a]];
  for (int i = 0; i < m.num_nodes(); ++i)
    if (m.kind[i] == NodeKind::MidSide) {
      EXPECT_EQ(count[i], 2);
    }
  // Node → element adjacency agrees with the element list.
  for (int i = 0; i < m.num_nodes(); ++i)
    for (int k = m.node_element_offsets[i]; k < m.node_element_offsets[i + 1]; ++k) {
      const auto& e = m.elements[m.node_elements[k]];
      EXPECT_NE(std::find(e.begin(), e.end(), i), e.end());
    }
}

class CapsuleMeshMaps : public ::testing::TestWithParam<std::tuple<double, SpheroidMap>> {};

TEST_P(CapsuleMeshMaps, NodesOnSpheroidAndExactlyMirrorSymmetric) {
  const auto [r, map] = GetParam();
  const SurfaceMesh m = make_capsule_mesh(3, r, map);
  const auto [a, b] = spheroid_semi_axes(r);
  // Exact identities (volume of the unit sphere, aspect ratio) up to the rounding of a cube root (a few ulps).
  EXPECT_NEAR(a * b * b, 1.0, 1e-15);
  EXPECT_NEAR(a / b, r, 1e-14);
  std::set<int> seen;
  for (int i = 0; i < m.num_nodes(); ++i) {
    const Eigen::Vector3d x = m.nodes.col(i);
    // On the spheroid up to the rounding of the map (trigonometric functions of the node's angles).
    EXPECT_NEAR(x(0) * x(0) / (a * a) + (x(1) * x(1) + x(2) * x(2)) / (b * b), 1.0, 1e-13);
    const int j = m.mirror_node[i];
    ASSERT_GE(j, 0);
    EXPECT_EQ(m.mirror_node[j], i);
    EXPECT_EQ(m.nodes(0, j), x(0));
    EXPECT_EQ(m.nodes(1, j), x(1));
    EXPECT_EQ(m.nodes(2, j), -x(2));
    seen.insert(j);
    // The central image: built on the sphere, so on the spheroid −x only to the rounding of the map (the
    // polar angles θ and π − θ are mapped separately).
    const int p = m.central_node[i];
    ASSERT_GE(p, 0);
    EXPECT_NE(p, i);
    EXPECT_EQ(m.central_node[p], i);
    EXPECT_LT((m.nodes.col(p) + x).norm(), 1e-14);
  }
  EXPECT_EQ(static_cast<int>(seen.size()), m.num_nodes());
}

// The sphere is centrally symmetric bitwise, and x → −x maps elements onto elements (as node sets), which is
// what lets the flow evaluate one node of each pair: the discrete operator commutes with the symmetry.
TEST(SphereMesh, CentralImagesAreNegatedNodesAndElements) {
  for (int level = 0; level <= 3; ++level) {
    const SurfaceMesh m = make_sphere_mesh(level);
    ASSERT_EQ(static_cast<int>(m.central_node.size()), m.num_nodes());
    std::set<std::array<int, 6>> elements;
    for (auto e : m.elements) {
      std::sort(e.begin(), e.end());
      elements.insert(e);
    }
    for (int i = 0; i < m.num_nodes(); ++i) {
      const int p = m.central_node[i];
      EXPECT_EQ(m.central_node[p], i);
      EXPECT_NE(p, i);
      for (int k = 0; k < 3; ++k) EXPECT_EQ(m.nodes(k, p), -m.nodes(k, i)) << "level " << level << " node " << i;
    }
    for (const auto& e : m.elements) {
      std::array<int, 6> image{};
      for (int a = 0; a < 6; ++a) image[a] = m.central_node[e[a]];
      std::sort(image.begin(), image.end());
      EXPECT_TRUE(elements.count(image)) << "level " << level;
    }
  }
}

// The element orbits under the mirror, the point reflection and both: every element is a representative or the
// image of one exactly once, each image is its representative's nodes mapped by the group element (local
// permutation included), and the orbits have the group's size except for the elements across the mirror plane,
// which are their own mirror images (so a quarter of the elements, plus those, are evaluated with both).
TEST(CapsuleMesh, ElementOrbitsCoverEveryElementOnce) {
  const SurfaceMesh m = make_capsule_mesh(3, 2.0);
  for (const auto& [mirror, central] : {std::pair{true, false}, std::pair{false, true}, std::pair{true, true}}) {
    const ElementOrbits o = element_orbits(m, mirror, central);
    ASSERT_FALSE(o.empty());
    std::vector<int> seen(static_cast<std::size_t>(m.num_elements()), 0);
    for (int e : o.representatives) ++seen[e];
    for (const ElementOrbits::Image& im : o.images) {
      ++seen[im.element];
      EXPECT_LT(im.from, im.element);  // the representative is the orbit's smallest element
      const bool is_mirror = im.sign == kMirrorSigns, is_central = im.sign == kCentralSigns;
      for (int a = 0; a < 6; ++a) {
        const int i = m.elements[im.from][a];
        const int expected = is_mirror ? m.mirror_node[i] : is_central ? m.central_node[i] : m.central_node[m.mirror_node[i]];
        EXPECT_EQ(m.elements[im.element][im.local[a]], expected);
      }
    }
    for (int e = 0; e < m.num_elements(); ++e) EXPECT_EQ(seen[e], 1) << e;
    const int group = (mirror ? 2 : 1) * (central ? 2 : 1);
    // Orbits of full size, except the elements across the plane (their own mirror images: 32 at level 3).
    const int across = static_cast<int>(o.representatives.size()) * group - m.num_elements();
    std::printf("  mirror %d central %d: %zu representatives of %d elements\n", mirror, central,
                o.representatives.size(), m.num_elements());
    if (!mirror) EXPECT_EQ(across, 0);
    if (mirror) EXPECT_GT(across, 0);
    EXPECT_LT(across, m.num_elements() / 10);
  }
  SurfaceMesh no_map = m;
  no_map.mirror_node.clear();
  EXPECT_TRUE(element_orbits(no_map, true, false).empty());
  EXPECT_TRUE(element_orbits(no_map, true, true).empty());
  EXPECT_FALSE(element_orbits(no_map, false, true).empty());
}

INSTANTIATE_TEST_SUITE_P(AspectRatios, CapsuleMeshMaps,
                         ::testing::Combine(::testing::Values(0.5, 2.0),
                                            ::testing::Values(SpheroidMap::AxisScaling, SpheroidMap::EqualArcLength,
                                                              SpheroidMap::Conformal)));

// Measures the element quality of the three maps. The default (equal arc length) must beat the plain
// axis scaling on angles, anisotropy and size spread; conformal must give near-sphere angles.
TEST(CapsuleMesh, RedistributionImprovesElementShapes) {
  const SurfaceMesh sphere = make_sphere_mesh(3);
  const MeshQuality qs = mesh_quality(sphere);
  std::printf("%-6s %-18s %10s %12s %12s %10s\n", "a/b", "map", "min angle", "max edge r.", "mean edge r.", "size r.");
  std::printf("%-6s %-18s %10.2f %12.3f %12.3f %10.3f\n", "1", "sphere", qs.min_angle_deg, qs.max_edge_ratio,
              qs.mean_edge_ratio, qs.size_ratio);
  for (double r : {2.0, 0.5}) {
    MeshQuality q[3];
    const SpheroidMap maps[3] = {SpheroidMap::AxisScaling, SpheroidMap::EqualArcLength, SpheroidMap::Conformal};
    const char* names[3] = {"axis-scaling", "equal-arc-length", "conformal"};
    for (int k = 0; k < 3; ++k) {
      q[k] = mesh_quality(make_capsule_mesh(3, r, maps[k]));
      std::printf("%-6.1f %-18s %10.2f %12.3f %12.3f %10.3f\n", r, names[k], q[k].min_angle_deg, q[k].max_edge_ratio,
                  q[k].mean_edge_ratio, q[k].size_ratio);
    }
    EXPECT_GT(q[1].min_angle_deg, q[0].min_angle_deg + 5.0) << "a/b=" << r;
    EXPECT_LT(q[1].max_edge_ratio, q[0].max_edge_ratio - 0.2) << "a/b=" << r;
    EXPECT_LT(q[1].size_ratio, q[0].size_ratio) << "a/b=" << r;
    EXPECT_GT(q[2].min_angle_deg, q[1].min_angle_deg) << "a/b=" << r;
    // Conformal keeps the sphere mesh's angles up to the discretisation of the map.
    EXPECT_GT(q[2].min_angle_deg, qs.min_angle_deg - 5.0) << "a/b=" << r;
  }
}

TEST(CapsuleMesh, BadParametersThrowClearly) {
  EXPECT_THROW(make_sphere_mesh(-1), std::invalid_argument);
  EXPECT_THROW(make_sphere_mesh(7), std::invalid_argument);
  EXPECT_THROW(make_capsule_mesh(2, 0.0), std::invalid_argument);
  EXPECT_THROW(make_capsule_mesh(2, -2.0), std::invalid_argument);
  EXPECT_THROW(make_capsule_mesh(2, std::nan("")), std::invalid_argument);
  EXPECT_THROW(parse_spheroid_map("stretched"), std::invalid_argument);
  try {
    make_sphere_mesh(9);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mesh.level"), std::string::npos);
  }
}

// symmetrise is the projection onto mirror-symmetric states: its output is exactly symmetric, an exactly
// symmetric input comes back bitwise unchanged, and an asymmetric one moves to the mean of it and its image
// (by half the asymmetry, no more).
TEST(CapsuleMesh, SymmetriseProjectsOntoExactlyMirrorSymmetricStates) {
  const SurfaceMesh m = make_capsule_mesh(2, 2.0, SpheroidMap::EqualArcLength);
  ASSERT_TRUE(is_mirror_symmetric(m, m.nodes, 0.0));
  Eigen::Matrix3Xd x = m.nodes;
  for (int i = 0; i < x.cols(); ++i) x(0, i) += 0.3 * x(1, i);  // a shear keeps the symmetry
  const Eigen::Matrix3Xd sym = x;
  symmetrise(m, x);
  EXPECT_EQ((x - sym).cwiseAbs().maxCoeff(), 0.0);
  // Break it: an out-of-plane tilt (x3 += ε x1) is odd under the mirror's expectations.
  Eigen::Matrix3Xd y = sym;
  for (int i = 0; i < y.cols(); ++i) y(2, i) += 1e-6 * y(0, i) + 1e-7 * y(1, i) * y(1, i);
  EXPECT_FALSE(is_mirror_symmetric(m, y, 1e-10));
  EXPECT_TRUE(is_mirror_symmetric(m, y, 1e-5));
  const Eigen::Matrix3Xd before = y;
  symmetrise(m, y);
  EXPECT_TRUE(is_mirror_symmetric(m, y, 0.0));
  // The x3 → −x3 even part of the perturbation (1e-6 x1 + 1e-7 x2² added to x3) is removed: x3 returns to
  // the sheared state's x3 up to rounding.
  EXPECT_LT((y - sym).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_GT((before - sym).cwiseAbs().maxCoeff(), 1e-7);
  Eigen::Matrix3Xd z = y;
  symmetrise(m, z);
  EXPECT_EQ((z - y).cwiseAbs().maxCoeff(), 0.0);  // idempotent
}

// With the central symmetry symmetrise projects onto states symmetric under the whole group (mirror, x → −x,
// half-turn about x3): exact afterwards, bitwise idempotent, the even part of a perturbation removed, nodes on
// the mirror plane at x3 = 0 and nodes on the x3 axis at x1 = x2 = 0 exactly. Central alone keeps the mirror
// asymmetry that is odd under x → −x.
TEST(CapsuleMesh, SymmetriseWithCentralProjectsOntoTheSymmetryGroup) {
  const SurfaceMesh m = make_capsule_mesh(2, 0.5, SpheroidMap::EqualArcLength);
  // An odd map of the reference keeps both symmetries: a shear and a cubic stretch along x1.
  Eigen::Matrix3Xd x = m.nodes;
  for (int i = 0; i < x.cols(); ++i) x(0, i) += 0.3 * x(1, i) + 0.1 * x(0, i) * x(0, i) * x(0, i);
  EXPECT_FALSE(is_centrally_symmetric(m, x, 0.0));  // the spheroid map's rounding
  EXPECT_TRUE(is_centrally_symmetric(m, x, 1e-14));
  const Eigen::Matrix3Xd sym = x;
  symmetrise(m, x, true, true);
  EXPECT_TRUE(is_centrally_symmetric(m, x, 0.0));
  EXPECT_TRUE(is_mirror_symmetric(m, x, 0.0));
  // Moved by no more than the input's own asymmetry (the spheroid map's rounding): the projection takes each
  // node half-way to its image's negative.
  double asymmetry = 0.0;
  for (int i = 0; i < sym.cols(); ++i)
    asymmetry = std::max(asymmetry, (sym.col(i) + sym.col(m.central_node[i])).cwiseAbs().maxCoeff());
  EXPECT_GT(asymmetry, 0.0);
  EXPECT_LE((x - sym).cwiseAbs().maxCoeff(), asymmetry);
  Eigen::Matrix3Xd again = x;
  symmetrise(m, again, true, true);
  EXPECT_EQ((again - x).cwiseAbs().maxCoeff(), 0.0);  // idempotent
  int on_plane = 0, on_axis = 0;
  for (int i = 0; i < x.cols(); ++i) {
    if (m.mirror_node[i] == i) {
      ++on_plane;
      EXPECT_EQ(x(2, i), 0.0);
    }
    if (m.mirror_node[m.central_node[i]] == i) {
      ++on_axis;
      EXPECT_EQ(x(0, i), 0.0);
      EXPECT_EQ(x(1, i), 0.0);
    }
  }
  EXPECT_GT(on_plane, 0);
  EXPECT_GT(on_axis, 0);
  // An even perturbation (x1 += ε x2², invariant under x → −x) is removed; so is one that breaks the mirror.
  Eigen::Matrix3Xd y = x;
  for (int i = 0; i < y.cols(); ++i) y(0, i) += 1e-6 * y(1, i) * y(1, i), y(2, i) += 1e-6 * y(0, i);
  EXPECT_FALSE(is_centrally_symmetric(m, y, 1e-10));
  symmetrise(m, y, true, true);
  EXPECT_LT((y - x).cwiseAbs().maxCoeff(), 1e-15);
  // Central alone: the mirror-breaking tilt x3 += ε x1 is odd under x → −x and stays; the even part goes.
  Eigen::Matrix3Xd z = x;
  for (int i = 0; i < z.cols(); ++i) z(0, i) += 1e-6 * z(1, i) * z(1, i), z(2, i) += 1e-6 * z(0, i);
  symmetrise(m, z, false, true);
  EXPECT_TRUE(is_centrally_symmetric(m, z, 0.0));
  EXPECT_FALSE(is_mirror_symmetric(m, z, 1e-10));
  for (int i = 0; i < z.cols(); ++i) EXPECT_NEAR(z(2, i), x(2, i) + 1e-6 * x(0, i), 1e-15);
}

// The poles: one node exactly at each end of the revolution axis, on every level and for every shape.
TEST(CapsuleMesh, PoleNodesSitOnTheRevolutionAxis) {
  for (int level = 0; level <= 3; ++level)
    for (const double r : {0.5, 1.0, 2.0}) {
      const SurfaceMesh m = make_capsule_mesh(level, r);
      const double a = spheroid_semi_axes(r)[0];
      ASSERT_GE(m.pole_node[0], 0);
      ASSERT_GE(m.pole_node[1], 0);
      EXPECT_EQ(m.nodes(1, m.pole_node[0]), 0.0);
      EXPECT_EQ(m.nodes(2, m.pole_node[0]), 0.0);
      EXPECT_NEAR(m.nodes(0, m.pole_node[0]), a, 1e-15);
      EXPECT_EQ(m.nodes.col(m.pole_node[1]), (-m.nodes.col(m.pole_node[0])).eval()) << "level " << level << " r " << r;
    }
}

// The equator node (the spin's material point): on the revolution axis's equator at +x2, on every level and shape,
// and carried by the orientation's rotation to R e2 (in the shear plane: the rotation keeps e2 there).
TEST(CapsuleMesh, EquatorNodeSitsOnTheEquatorAtPlusX2) {
  for (int level = 0; level <= 3; ++level)
    for (const double r : {0.5, 1.0, 2.0}) {
      const SurfaceMesh m = make_capsule_mesh(level, r);
      const double b = spheroid_semi_axes(r)[1];
      ASSERT_GE(m.equator_node, 0);
      EXPECT_NE(m.equator_node, m.pole_node[0]);
      // x1 = a cos θ′ with θ′ the spheroid map's image of π/2, found by bisection: 0 to round-off.
      EXPECT_NEAR(m.nodes(0, m.equator_node), 0.0, 1e-14) << "level " << level << " r " << r;
      EXPECT_EQ(m.nodes(2, m.equator_node), 0.0);
      EXPECT_NEAR(m.nodes(1, m.equator_node), b, 1e-15);
      if (r == 1.0) {
        EXPECT_EQ(m.nodes(1, m.equator_node), 1.0) << "exactly (0, 1, 0) on the sphere";
      }
    }
  SurfaceMesh m = make_capsule_mesh(2, 2.0);
  const int e = m.equator_node;
  orient_capsule_mesh(m, 30.0, 40.0);
  EXPECT_EQ(m.equator_node, e);
  const Eigen::Vector3d expected = spheroid_semi_axes(2.0)[1] * orientation_rotation(30.0, 40.0).col(1);
  EXPECT_LT((m.nodes.col(e) - expected).norm(), 1e-14);
}

// tilt = azimuth = 0 leaves the mesh bitwise alone (every in-plane case keeps its results bit for bit).
TEST(CapsuleMesh, ZeroOrientationIsBitwiseTheUnrotatedMesh) {
  const SurfaceMesh ref = make_capsule_mesh(2, 2.0);
  SurfaceMesh m = make_capsule_mesh(2, 2.0);
  orient_capsule_mesh(m, 0.0, 0.0);
  ASSERT_EQ(m.nodes.cols(), ref.nodes.cols());
  EXPECT_EQ(std::memcmp(m.nodes.data(), ref.nodes.data(), sizeof(double) * ref.nodes.size()), 0);
  EXPECT_EQ(m.mirror_node, ref.mirror_node);
  EXPECT_EQ(m.central_node, ref.central_node);
}

// A rotation puts the +x1 pole at a · (cos t cos φ, cos t sin φ, sin t), is rigid, keeps the point symmetry to the
// unrotated mesh's round-off, keeps the mirror map only at tilt 0 (where it still holds bitwise) and clears it
// otherwise.
TEST(CapsuleMesh, OrientationRotatesThePoleWhereExpected) {
  const double deg = std::numbers::pi / 180.0;
  const double a = spheroid_semi_axes(2.0)[0];
  const SurfaceMesh ref = make_capsule_mesh(2, 2.0);
  struct Case {
    double tilt, azimuth;
  };
  for (const Case c : {Case{30.0, 0.0}, Case{30.0, 40.0}, Case{0.0, 45.0}, Case{90.0, 0.0}, Case{90.0, 90.0},
                       Case{12.5, -70.0}, Case{0.0, 90.0}}) {
    SurfaceMesh m = make_capsule_mesh(2, 2.0);
    orient_capsule_mesh(m, c.tilt, c.azimuth);
    const Eigen::Vector3d expected(std::cos(c.tilt * deg) * std::cos(c.azimuth * deg),
                                   std::cos(c.tilt * deg) * std::sin(c.azimuth * deg), std::sin(c.tilt * deg));
    const Eigen::Vector3d pole = m.nodes.col(m.pole_node[0]);
    EXPECT_LT((pole - a * expected).norm(), 1e-14) << c.tilt << " " << c.azimuth << ": " << pole.transpose();
    EXPECT_LT((axis_of_orientation(c.tilt, c.azimuth) - expected).norm(), 1e-15);
    EXPECT_EQ(m.nodes.col(m.pole_node[1]), (-m.nodes.col(m.pole_node[0])).eval());
    // Rigid: every distance from the centre and between neighbours kept to round-off.
    for (int i = 0; i < m.num_nodes(); ++i) {
      EXPECT_NEAR(m.nodes.col(i).norm(), ref.nodes.col(i).norm(), 1e-15);
      const int j = (i + 7) % m.num_nodes();
      EXPECT_NEAR((m.nodes.col(i) - m.nodes.col(j)).norm(), (ref.nodes.col(i) - ref.nodes.col(j)).norm(), 1e-14);
    }
    EXPECT_TRUE(is_centrally_symmetric(m, m.nodes, 1e-12));
    EXPECT_EQ(m.central_node, ref.central_node);
    if (c.tilt == 0.0) {
      EXPECT_TRUE(is_mirror_symmetric(m, m.nodes, 0.0)) << "a turn about x3 keeps x3 bitwise";
    } else {
      EXPECT_TRUE(m.mirror_node.empty()) << "tilt " << c.tilt;
      EXPECT_FALSE(is_mirror_symmetric(m, m.nodes, 1e-12));
    }
  }
  // Exact at the multiples of 90°: the axis of a tilt-90 capsule is e3 with no round-off.
  EXPECT_EQ(axis_of_orientation(90.0, 0.0), Eigen::Vector3d(0.0, 0.0, 1.0));
  EXPECT_EQ(axis_of_orientation(0.0, 90.0), Eigen::Vector3d(0.0, 1.0, 0.0));
  EXPECT_THROW(orient_capsule_mesh(*std::make_unique<SurfaceMesh>(make_capsule_mesh(0, 2.0)), std::nan(""), 0.0),
               std::invalid_argument);
}

// symmetrise on a tilted mesh imposes the point symmetry only (it has no mirror map), and changes a centrally
// symmetric state at round-off level only: it does not drag the tilted capsule back into the plane.
TEST(CapsuleMesh, SymmetriseLeavesATiltedCapsuleTilted) {
  SurfaceMesh m = make_capsule_mesh(2, 2.0);
  orient_capsule_mesh(m, 30.0, 20.0);
  Eigen::Matrix3Xd x = m.nodes;
  symmetrise(m, x, /*mirror=*/true, /*central=*/true);
  // The unrotated spheroid is centrally symmetric only to round-off (the map places θ and π − θ separately), so
  // the projection moves it by that much; the rotated one by no more.
  const SurfaceMesh ref = make_capsule_mesh(2, 2.0);
  Eigen::Matrix3Xd y = ref.nodes;
  symmetrise(ref, y, /*mirror=*/false, /*central=*/true);
  const double ref_change = (y - ref.nodes).cwiseAbs().maxCoeff();
  EXPECT_LE((x - m.nodes).cwiseAbs().maxCoeff(), 2.0 * ref_change + 1e-15) << "unrotated: " << ref_change;
  EXPECT_TRUE(is_centrally_symmetric(m, x, 0.0));
}

}  // namespace
}  // namespace capsim::mesh

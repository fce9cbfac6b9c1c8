#include "solver/mesh/mesh.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "solver/mesh/p2_element.h"
#include "solver/mesh/p2_tabulation.h"

namespace capsim::mesh {
namespace {

using Vec3 = Eigen::Vector3d;

std::uint64_t edge_key(int i, int j) {
  const auto lo = static_cast<std::uint64_t>(std::min(i, j));
  const auto hi = static_cast<std::uint64_t>(std::max(i, j));
  return (hi << 32) | lo;
}

// Flat vertex triangulation of the unit sphere.
struct FlatSphere {
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> t;
};

FlatSphere icosahedron() {
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  FlatSphere s;
  // Symmetric under each coordinate reflection, so every subdivision is mirror-symmetric in x3.
  const double raw[12][3] = {{-1, p, 0}, {1, p, 0},  {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                             {0, -1, -p}, {0, 1, -p}, {p, 0, -1},  {p, 0, 1},  {-p, 0, -1}, {-p, 0, 1}};
  for (const auto& r : raw) s.v.push_back(Vec3(r[0], r[1], r[2]).normalized());
  s.t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
         {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
         {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& tri : s.t) {
    const Vec3 n = (s.v[tri[1]] - s.v[tri[0]]).cross(s.v[tri[2]] - s.v[tri[0]]);
    if (n.dot(s.v[tri[0]] + s.v[tri[1]] + s.v[tri[2]]) < 0) std::swap(tri[1], tri[2]);
  }
  return s;
}

int midpoint(FlatSphere& s, std::unordered_map<std::uint64_t, int>& cache, int i, int j) {
  const auto key = edge_key(i, j);
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  s.v.push_back((s.v[i] + s.v[j]).normalized());
  const int id = static_cast<int>(s.v.size()) - 1;
  cache.emplace(key, id);
  return id;
}

FlatSphere subdivide(const FlatSphere& in) {
  FlatSphere out;
  out.v = in.v;
  std::unordered_map<std::uint64_t, int> cache;
  for (const auto& t : in.t) {
    const int a = midpoint(out, cache, t[0], t[1]);
    const int b = midpoint(out, cache, t[1], t[2]);
    const int c = midpoint(out, cache, t[2], t[0]);
    out.t.push_back({t[0], a, c});
    out.t.push_back({t[1], b, a});
    out.t.push_back({t[2], c, b});
    out.t.push_back({a, b, c});
  }
  return out;
}

void build_adjacency(SurfaceMesh& m) {
  const int n = m.num_nodes();
  m.node_element_offsets.assign(n + 1, 0);
  for (const auto& e : m.elements)
    for (int a : e) ++m.node_element_offsets[a + 1];
  for (int i = 0; i < n; ++i) m.node_element_offsets[i + 1] += m.node_element_offsets[i];
  m.node_elements.assign(m.node_element_offsets[n], 0);
  std::vector<int> fill(m.node_element_offsets.begin(), m.node_element_offsets.end() - 1);
  for (int e = 0; e < m.num_elements(); ++e)
    for (int a : m.elements[e]) m.node_elements[fill[a]++] = e;
}

void build_mirror(SurfaceMesh& m) {
  // The construction is sign-symmetric, so mirror images are bitwise equal with x3 negated.
  std::map<std::array<double, 3>, int> where;
  for (int i = 0; i < m.num_nodes(); ++i) where[{m.nodes(0, i), m.nodes(1, i), m.nodes(2, i)}] = i;
  m.mirror_node.assign(m.num_nodes(), -1);
  for (int i = 0; i < m.num_nodes(); ++i) {
    const double z = m.nodes(2, i) == 0.0 ? 0.0 : -m.nodes(2, i);
    auto it = where.find({m.nodes(0, i), m.nodes(1, i), z});
    if (it == where.end()) throw std::logic_error("mesh: node without mirror image under x3 -> -x3");
    m.mirror_node[i] = it->second;
  }
}

void build_central(SurfaceMesh& m) {
  // The icosahedron and the normalised mid-points are sign-symmetric, so images are bitwise negated.
  std::map<std::array<double, 3>, int> where;
  for (int i = 0; i < m.num_nodes(); ++i) where[{m.nodes(0, i), m.nodes(1, i), m.nodes(2, i)}] = i;
  m.central_node.assign(m.num_nodes(), -1);
  const auto neg = [](double v) { return v == 0.0 ? 0.0 : -v; };
  for (int i = 0; i < m.num_nodes(); ++i) {
    auto it = where.find({neg(m.nodes(0, i)), neg(m.nodes(1, i)), neg(m.nodes(2, i))});
    if (it == where.end() || it->second == i) throw std::logic_error("mesh: node without image under x -> -x");
    m.central_node[i] = it->second;
  }
}

// Meridian speed of the spheroid, ds/dθ' = sqrt(a² sin²θ' + b² cos²θ').
double meridian_speed(double a, double b, double t) {
  const double s = std::sin(t), c = std::cos(t);
  return std::sqrt(a * a * s * s + b * b * c * c);
}

// Integral of f over [lo, hi] with a fixed 24-point Gauss rule on 8 panels (smooth integrands only).
template <class F>
double integrate(F f, double lo, double hi) {
  static const quadrature::LineRule g = quadrature::gauss_legendre(24);
  const int panels = 8;
  const double h = (hi - lo) / panels;
  double sum = 0.0;
  for (int p = 0; p < panels; ++p)
    for (std::size_t k = 0; k < g.nodes.size(); ++k) sum += g.weights[k] * f(lo + h * (p + g.nodes[k]));
  return sum * h;
}

// Solves F(θ') = target for θ' in [0, π] by bisection, F increasing.
template <class F>
double invert(F f, double target) {
  double lo = 0.0, hi = std::numbers::pi;
  for (int it = 0; it < 200 && hi - lo > 1e-15; ++it) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) < target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// New polar angle (from the x1 axis) on the spheroid for sphere polar angle θ.
double mapped_polar_angle(SpheroidMap map, double a, double b, double theta) {
  const double pi = std::numbers::pi;
  switch (map) {
    case SpheroidMap::AxisScaling:
      return theta;
    case SpheroidMap::EqualArcLength: {
      const double half = integrate([&](double t) { return meridian_speed(a, b, t); }, 0.0, pi);
      return invert([&](double tp) { return integrate([&](double t) { return meridian_speed(a, b, t); }, 0.0, tp); },
                    half * theta / pi);
    }
    case SpheroidMap::Conformal: {
      // Isothermal latitude ψ(θ') = ln tan(θ'/2) + g(θ'), g regular, ψ(π/2) = 0; ψ_sphere(θ) = ln tan(θ/2).
      if (theta <= 0.0) return 0.0;
      if (theta >= pi) return pi;
      auto g = [&](double tp) {
        return -integrate([&](double t) { return (meridian_speed(a, b, t) - b) / (b * std::sin(t)); }, tp, pi / 2);
      };
      auto psi = [&](double tp) {
        if (tp <= 0.0) return -1e300;
        if (tp >= pi) return 1e300;
        return std::log(std::tan(tp / 2)) + g(tp);
      };
      return invert(psi, std::log(std::tan(theta / 2)));
    }
  }
  return theta;
}

}  // namespace

SurfaceMesh make_sphere_mesh(int level) {
  if (level < 0 || level > 6)
    throw std::invalid_argument("mesh.level = " + std::to_string(level) + " is out of range (0..6)");
  FlatSphere s = icosahedron();
  for (int l = 0; l < level; ++l) s = subdivide(s);

  SurfaceMesh m;
  m.level = level;
  std::unordered_map<std::uint64_t, int> mid;
  std::vector<Vec3> pts = s.v;
  auto mid_node = [&](int i, int j) {
    const auto key = edge_key(i, j);
    if (auto it = mid.find(key); it != mid.end()) return it->second;
    pts.push_back((s.v[i] + s.v[j]).normalized());
    const int id = static_cast<int>(pts.size()) - 1;
    mid.emplace(key, id);
    return id;
  };
  for (const auto& t : s.t)
    m.elements.push_back({t[0], t[1], t[2], mid_node(t[0], t[1]), mid_node(t[1], t[2]), mid_node(t[2], t[0])});
  m.nodes.resize(3, static_cast<Eigen::Index>(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i) m.nodes.col(static_cast<Eigen::Index>(i)) = pts[i];
  m.kind.assign(pts.size(), NodeKind::MidSide);
  std::fill(m.kind.begin(), m.kind.begin() + static_cast<long>(s.v.size()), NodeKind::Vertex);
  build_adjacency(m);
  build_mirror(m);
  build_central(m);
  // The poles: the two nodes exactly on the x1 axis (normalised mid-points of (±φ, 0, ±1), bitwise (±1, 0, 0)).
  for (int i = 0; i < m.num_nodes(); ++i)
    if (m.nodes(1, i) == 0.0 && m.nodes(2, i) == 0.0) m.pole_node[m.nodes(0, i) > 0.0 ? 0 : 1] = i;
  if (m.pole_node[0] < 0 || m.pole_node[1] < 0) throw std::logic_error("mesh: no node on the x1 axis");
  // The equator node: the normalised mid-point of (±1, φ, 0), bitwise (0, 1, 0) (a single nonzero component
  // divided by its own norm).
  for (int i = 0; i < m.num_nodes(); ++i)
    if (m.nodes(0, i) == 0.0 && m.nodes(2, i) == 0.0 && m.nodes(1, i) > 0.0) m.equator_node = i;
  if (m.equator_node < 0) throw std::logic_error("mesh: no node on the +x2 axis");
  return m;
}

std::array<double, 2> spheroid_semi_axes(double aspect_ratio) {
  if (!(aspect_ratio > 0.0) || !std::isfinite(aspect_ratio))
    throw std::invalid_argument("capsule.aspect_ratio = " + std::to_string(aspect_ratio) +
                                " is out of range (must be > 0)");
  return {std::cbrt(aspect_ratio * aspect_ratio), 1.0 / std::cbrt(aspect_ratio)};
}

SurfaceMesh make_capsule_mesh(int level, double aspect_ratio, SpheroidMap map) {
  const auto [a, b] = spheroid_semi_axes(aspect_ratio);
  SurfaceMesh m = make_sphere_mesh(level);
  if (aspect_ratio == 1.0) return m;
  // The map depends on the polar angle only; cache it per distinct x1 (many nodes share a latitude).
  std::map<double, double> cache;
  for (int i = 0; i < m.num_nodes(); ++i) {
    const double X1 = std::clamp(m.nodes(0, i), -1.0, 1.0);
    auto it = cache.find(X1);
    if (it == cache.end()) it = cache.emplace(X1, mapped_polar_angle(map, a, b, std::acos(X1))).first;
    const double tp = it->second;
    const double rho = std::hypot(m.nodes(1, i), m.nodes(2, i));
    const double s = rho > 0.0 ? b * std::sin(tp) / rho : 0.0;
    m.nodes(0, i) = a * std::cos(tp);
    m.nodes(1, i) *= s;
    m.nodes(2, i) *= s;
  }
  return m;
}

namespace {
// sin and cos of an angle in degrees, exact at the multiples of 90° (std::sin(π/2 rad) is fine, but std::cos of
// it is 6e-17, which would tilt an axis meant to lie along x3 or in the plane by that much).
std::array<double, 2> sin_cos_deg(double deg) {
  const double q = deg / 90.0;
  if (q == std::round(q)) {
    static constexpr double kSin[4] = {0.0, 1.0, 0.0, -1.0};
    const int k = static_cast<int>(((static_cast<long long>(q) % 4) + 4) % 4);
    return {kSin[k], kSin[(k + 1) % 4]};
  }
  const double r = deg * std::numbers::pi / 180.0;
  return {std::sin(r), std::cos(r)};
}
}  // namespace

Eigen::Vector3d axis_of_orientation(double tilt_deg, double azimuth_deg) {
  return orientation_rotation(tilt_deg, azimuth_deg).col(0);
}

Eigen::Matrix3d orientation_rotation(double tilt_deg, double azimuth_deg) {
  if (!std::isfinite(tilt_deg) || !std::isfinite(azimuth_deg))
    throw std::invalid_argument("mesh: orientation angles must be finite");
  const auto [st, ct] = sin_cos_deg(tilt_deg);
  const auto [sp, cp] = sin_cos_deg(azimuth_deg);
  Eigen::Matrix3d r;
  r << ct * cp, -sp, -st * cp,  //
      ct * sp, cp, -st * sp,    //
      st, 0.0, ct;
  return r;
}

void orient_capsule_mesh(SurfaceMesh& m, double tilt_deg, double azimuth_deg) {
  if (!std::isfinite(tilt_deg) || !std::isfinite(azimuth_deg))
    throw std::invalid_argument("mesh: orientation angles must be finite");
  if (tilt_deg == 0.0 && azimuth_deg == 0.0) return;  // the unrotated mesh, bitwise
  const Eigen::Matrix3d r = orientation_rotation(tilt_deg, azimuth_deg);
  // Written out per component, in one fixed order, so that a node and its central image (bitwise −x on the
  // sphere, −x to round-off on the spheroid) get images that are negated in the same way.
  for (int i = 0; i < m.num_nodes(); ++i) {
    const double x = m.nodes(0, i), y = m.nodes(1, i), z = m.nodes(2, i);
    for (int k = 0; k < 3; ++k) m.nodes(k, i) = r(k, 0) * x + r(k, 1) * y + r(k, 2) * z;
  }
  if (tilt_deg != 0.0) m.mirror_node.clear();
}

MeshQuality mesh_quality(const SurfaceMesh& m) {
  MeshQuality q;
  q.min_angle_deg = 180.0;
  q.min_edge = 1e300;
  double min_area = 1e300, max_area = 0.0, sum_ratio = 0.0;
  for (const auto& e : m.elements) {
    const Vec3 p[3] = {m.nodes.col(e[0]), m.nodes.col(e[1]), m.nodes.col(e[2])};
    double len[3];
    for (int k = 0; k < 3; ++k) len[k] = (p[(k + 1) % 3] - p[k]).norm();
    for (int k = 0; k < 3; ++k) {
      const Vec3 u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
      const double ang = std::atan2(u.cross(v).norm(), u.dot(v)) * 180.0 / std::numbers::pi;
      q.min_angle_deg = std::min(q.min_angle_deg, ang);
    }
    const double lo = std::min({len[0], len[1], len[2]}), hi = std::max({len[0], len[1], len[2]});
    q.max_edge_ratio = std::max(q.max_edge_ratio, hi / lo);
    sum_ratio += hi / lo;
    q.min_edge = std::min(q.min_edge, lo);
    q.max_edge = std::max(q.max_edge, hi);
    const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    min_area = std::min(min_area, area);
    max_area = std::max(max_area, area);
  }
  q.mean_edge_ratio = sum_ratio / std::max(1, m.num_elements());
  q.size_ratio = max_area / min_area;
  return q;
}

double min_node_spacing(const SurfaceMesh& m, const Eigen::Matrix3Xd& x) {
  // Mid-side to vertex distances: about half an edge.
  static constexpr int pairs[6][2] = {{0, 3}, {3, 1}, {1, 4}, {4, 2}, {2, 5}, {5, 0}};
  double h = 1e300;
  for (const auto& e : m.elements)
    for (const auto& p : pairs) h = std::min(h, (x.col(e[p[0]]) - x.col(e[p[1]])).norm());
  return h;
}

Eigen::Matrix3Xd node_normals(const SurfaceMesh& m, const Eigen::Matrix3Xd& x) {
  Eigen::Matrix3Xd n, moments;
  std::vector<double> scratch;
  node_normals_and_flux_moments(m, x, n, moments, scratch);
  return n;
}

void node_normals_and_flux_moments(const SurfaceMesh& m, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& normals,
                                   Eigen::Matrix3Xd& moments, std::vector<double>& scratch) {
  node_normals_and_flux_moments(m.elements, x, normals, moments, scratch);
}

void node_normals_and_flux_moments(std::span<const std::array<int, 6>> elements, const Eigen::Matrix3Xd& x,
                                   Eigen::Matrix3Xd& normals, Eigen::Matrix3Xd& moments, std::vector<double>& scratch) {
  static const P2Tabulation nodes = P2Tabulation::at_nodes();
  static const P2Tabulation rule = P2Tabulation::of_degree(4);
  // Per element in parallel: the unit normals at its six nodes and its six moments (36 numbers), from the
  // geometry in monomial form; then summed into the nodes serially in element order.
  const int ne = static_cast<int>(elements.size()), nq = rule.size();
  scratch.resize(static_cast<std::size_t>(ne) * 36);
  double* out = scratch.data();
#pragma omp parallel for schedule(static)
  for (int e = 0; e < ne; ++e) {
    const auto& el = elements[e];
    double X[6][3], C[6][3];
    for (int a = 0; a < 6; ++a)
      for (int c = 0; c < 3; ++c) X[a][c] = x(c, el[a]);
    p2_monomials3(X, C);
    double* o = out + static_cast<std::size_t>(e) * 36;
    for (int a = 0; a < 6; ++a) {
      double p[3], g1[3], g2[3];
      p2_monomial_geometry(C, nodes[a].xi, nodes[a].eta, p, g1, g2);
      const double nx = g1[1] * g2[2] - g1[2] * g2[1], ny = g1[2] * g2[0] - g1[0] * g2[2],
                   nz = g1[0] * g2[1] - g1[1] * g2[0];
      const double inv = 1.0 / std::sqrt(nx * nx + ny * ny + nz * nz);
      o[3 * a] = nx * inv;
      o[3 * a + 1] = ny * inv;
      o[3 * a + 2] = nz * inv;
    }
    double mom[6][3] = {};
    for (int k = 0; k < nq; ++k) {
      double p[3], g1[3], g2[3];
      p2_monomial_geometry(C, rule[k].xi, rule[k].eta, p, g1, g2);
      const double w = rule.weight(k);
      const double nda[3] = {w * (g1[1] * g2[2] - g1[2] * g2[1]), w * (g1[2] * g2[0] - g1[0] * g2[2]),
                             w * (g1[0] * g2[1] - g1[1] * g2[0])};
      for (int a = 0; a < 6; ++a)
        for (int c = 0; c < 3; ++c) mom[a][c] += rule[k].n[a] * nda[c];
    }
    for (int a = 0; a < 6; ++a)
      for (int c = 0; c < 3; ++c) o[18 + 3 * a + c] = mom[a][c];
  }
  normals.setZero(3, x.cols());
  moments.setZero(3, x.cols());
  for (int e = 0; e < ne; ++e) {
    const double* o = out + static_cast<std::size_t>(e) * 36;
    for (int a = 0; a < 6; ++a) {
      const int i = elements[e][a];
      for (int c = 0; c < 3; ++c) {
        normals(c, i) += o[3 * a + c];
        moments(c, i) += o[18 + 3 * a + c];
      }
    }
  }
  normals.colwise().normalize();
}

bool symmetric_under(std::span<const int> image, const std::array<double, 3>& signs, const Eigen::Matrix3Xd& v,
                     double tol) {
  if (static_cast<Eigen::Index>(image.size()) != v.cols()) return false;
  for (Eigen::Index i = 0; i < v.cols(); ++i) {
    const int j = image[static_cast<std::size_t>(i)];
    const double e = std::abs(v(0, j) - signs[0] * v(0, i)) + std::abs(v(1, j) - signs[1] * v(1, i)) +
                     std::abs(v(2, j) - signs[2] * v(2, i));
    if (!(e <= tol)) return false;  // also false for NaN
  }
  return true;
}

namespace {
// tol relative to the extent of x (the diagonal of its bounding box).
double relative_to_extent(const Eigen::Matrix3Xd& x, double tol) {
  return tol * (x.rowwise().maxCoeff() - x.rowwise().minCoeff()).norm();
}
}  // namespace

bool is_mirror_symmetric(const SurfaceMesh& m, const Eigen::Matrix3Xd& x, double tol) {
  return x.cols() > 0 && symmetric_under(m.mirror_node, kMirrorSigns, x, relative_to_extent(x, tol));
}

std::vector<NodeSymmetry> symmetry_group(const SurfaceMesh& m, bool mirror, bool central) {
  const int n = m.num_nodes();
  if ((!mirror && !central) || (mirror && static_cast<int>(m.mirror_node.size()) != n) ||
      (central && static_cast<int>(m.central_node.size()) != n))
    return {};
  std::vector<NodeSymmetry> group;
  if (mirror) group.push_back({m.mirror_node, kMirrorSigns});
  if (central) group.push_back({m.central_node, kCentralSigns});
  if (mirror && central) {
    NodeSymmetry h{std::vector<int>(static_cast<std::size_t>(n)), {}};
    for (int i = 0; i < n; ++i) h.map[i] = m.central_node[m.mirror_node[i]];
    for (int c = 0; c < 3; ++c) h.sign[c] = kMirrorSigns[c] * kCentralSigns[c];
    group.push_back(std::move(h));
  }
  return group;
}

ElementOrbits element_orbits(const SurfaceMesh& m, bool mirror, bool central) {
  ElementOrbits out;
  const int ne = m.num_elements();
  const std::vector<NodeSymmetry> group = symmetry_group(m, mirror, central);
  if (ne == 0 || group.empty()) return out;
  // Elements are found by their node sets.
  std::map<std::array<int, 6>, int> by_nodes;
  for (int e = 0; e < ne; ++e) {
    auto key = m.elements[e];
    std::sort(key.begin(), key.end());
    by_nodes.emplace(key, e);
  }
  std::vector<char> done(static_cast<std::size_t>(ne), 0);
  for (int e = 0; e < ne; ++e) {
    if (done[e]) continue;
    done[e] = 1;
    out.representatives.push_back(e);
    for (const NodeSymmetry& g : group) {
      std::array<int, 6> key{};
      for (int a = 0; a < 6; ++a) key[a] = g.map[m.elements[e][a]];
      std::sort(key.begin(), key.end());
      const auto it = by_nodes.find(key);
      if (it == by_nodes.end()) return ElementOrbits{};  // the map does not map elements onto elements
      const int p = it->second;
      if (done[p]) continue;  // e itself (an element across the mirror plane), or an image already listed
      done[p] = 1;
      ElementOrbits::Image im;
      im.element = p;
      im.from = e;
      im.sign = g.sign;
      const auto& to = m.elements[p];
      for (int a = 0; a < 6; ++a)
        im.local[a] = static_cast<int>(std::find(to.begin(), to.end(), g.map[m.elements[e][a]]) - to.begin());
      out.images.push_back(im);
    }
  }
  return out;
}

bool is_centrally_symmetric(const SurfaceMesh& m, const Eigen::Matrix3Xd& x, double tol) {
  return x.cols() > 0 && symmetric_under(m.central_node, kCentralSigns, x, relative_to_extent(x, tol));
}

void symmetrise(const SurfaceMesh& m, Eigen::Matrix3Xd& x, bool mirror, bool central) {
  const int n = static_cast<int>(x.cols());
  mirror = mirror && static_cast<int>(m.mirror_node.size()) == n;
  central = central && static_cast<int>(m.central_node.size()) == n;
  if (!mirror && !central) return;
  // The group elements as sign patterns: identity, mirror M, point reflection P, half-turn R = M P.
  using Signs = std::array<double, 3>;
  constexpr Signs kM = kMirrorSigns, kP = kCentralSigns, kR{-1.0, -1.0, 1.0};
  const auto image = [&](const Signs& g, int j) {
    return Eigen::Vector3d(g[0] * x(0, j), g[1] * x(1, j), g[2] * x(2, j));
  };
  for (int i = 0; i < n; ++i) {
    const int mi = mirror ? m.mirror_node[i] : i;
    const int pi = central ? m.central_node[i] : i;
    const int ri = mirror && central ? m.mirror_node[pi] : i;
    if (std::min({mi, pi, ri}) < i) continue;  // the orbit is written from its smallest index
    // Pairs first, so a member fixed by a group element (on the plane, on the x3 axis) cancels exactly:
    // (x + g x) is bitwise g-invariant, and so is the sum of two such pairs.
    Eigen::Vector3d mean;
    if (mirror && central)
      mean = ((x.col(i) + image(kM, mi)) + (image(kP, pi) + image(kR, ri))) * 0.25;
    else if (mirror)
      mean = 0.5 * (x.col(i) + image(kM, mi));
    else
      mean = 0.5 * (x.col(i) + image(kP, pi));
    // Images before the node itself: where a member is fixed by a group element, the value written last is
    // the mean (the images differ from it at most in the sign of a zero).
    const auto put = [&](const Signs& g, int j) {
      for (int k = 0; k < 3; ++k) x(k, j) = g[k] * mean[k];
    };
    if (mirror && central) put(kR, ri);
    if (central) put(kP, pi);
    if (mirror) put(kM, mi);
    x.col(i) = mean;
  }
}

SpheroidMap parse_spheroid_map(const std::string& name) {
  if (name == "conformal") return SpheroidMap::Conformal;
  if (name == "equal-arc-length") return SpheroidMap::EqualArcLength;
  if (name == "axis-scaling") return SpheroidMap::AxisScaling;
  throw std::invalid_argument("mesh.spheroid_map = \"" + name +
                              "\" is not known (choose \"conformal\", \"equal-arc-length\" or \"axis-scaling\")");
}

}  // namespace capsim::mesh

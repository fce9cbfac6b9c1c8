#include "solver/stokes/singular_rules.h"

#include <cmath>

#include "solver/quadrature/triangle_rule.h"

namespace capsim::stokes {
namespace {

// Reference coordinates of the 6 local nodes.
constexpr double kRefNode[6][2] = {{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}, {0.5, 0.0}, {0.5, 0.5}, {0.0, 0.5}};

// Sub-triangles of the Duffy map for each local node, as (A, B) in reference coordinates: the triangle
// (P, A, B) with P the node at the apex (see the file comment).
struct SubTriangle {
  double ax, ay, bx, by;
};
const std::vector<SubTriangle>& sub_triangles(int local) {
  static const std::vector<SubTriangle> table[6] = {
      {{1, 0, 0, 1}},                                                     // vertex 0
      {{0, 1, 0, 0}},                                                     // vertex 1
      {{0, 0, 1, 0}},                                                     // vertex 2
      {{1, 0, 0.5, 0.5}, {0.5, 0.5, 0, 1}, {0, 1, 0, 0.5}, {0, 0.5, 0, 0}},  // mid-side 3 on edge 0–1
      {{0, 1, 0, 0.5}, {0, 0.5, 0, 0}, {0, 0, 0.5, 0}, {0.5, 0, 1, 0}},      // mid-side 4 on edge 1–2
      {{0, 0, 0.5, 0}, {0.5, 0, 1, 0}, {1, 0, 0.5, 0.5}, {0.5, 0.5, 0, 1}},  // mid-side 5 on edge 2–0
  };
  return table[local];
}

}  // namespace

std::vector<mesh::P2Point> duffy_rule(int local, int order) {
  const auto gl = quadrature::gauss_legendre(order);
  const double px = kRefNode[local][0], py = kRefNode[local][1];
  std::vector<mesh::P2Point> rule;
  for (const auto& st : sub_triangles(local)) {
    const double ax = st.ax - px, ay = st.ay - py;
    const double bx = st.bx - px, by = st.by - py;
    const double det = std::abs(ax * by - ay * bx);
    for (int i = 0; i < order; ++i) {
      const double s = gl.nodes[i];
      for (int j = 0; j < order; ++j) {
        const double t = gl.nodes[j];
        const double xi = px + s * (ax + t * (bx - ax)), eta = py + s * (ay + t * (by - ay));
        rule.push_back(mesh::p2_point(xi, eta, gl.weights[i] * gl.weights[j] * s * det));
      }
    }
  }
  return rule;
}

PointTable make_point_table(const std::vector<mesh::P2Point>& rule) {
  PointTable t;
  t.count = static_cast<int>(rule.size());
  for (const mesh::P2Point& p : rule) {
    t.xi.push_back(p.xi);
    t.eta.push_back(p.eta);
    t.w.push_back(p.w);
  }
  return t;
}

ApexTableF make_apex_table(int local, int order) {
  ApexTableF t;
  t.apex_xi = kRefNode[local][0];
  t.apex_eta = kRefNode[local][1];
  for (const mesh::P2Point& p : duffy_rule(local, order)) {
    t.u.push_back(static_cast<float>(p.xi - t.apex_xi));
    t.v.push_back(static_cast<float>(p.eta - t.apex_eta));
    t.w.push_back(static_cast<float>(p.w));
  }
  t.count = static_cast<int>(t.w.size());
  return t;
}

}  // namespace capsim::stokes

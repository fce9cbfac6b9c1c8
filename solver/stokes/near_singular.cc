#include "solver/stokes/near_singular.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "solver/quadrature/triangle_rule.h"

namespace capsim::stokes {

std::vector<mesh::P2Point> subdivided_rule(int subdivision, int degree) {
  const auto& rule = quadrature::triangle_rule(degree);
  using Tri = std::array<std::array<double, 2>, 3>;
  std::vector<Tri> tris = {Tri{{{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}}}};
  for (int k = 0; k < subdivision; ++k) {
    std::vector<Tri> next;
    for (const Tri& t : tris) {
      auto mid = [&](int a, int b) {
        return std::array<double, 2>{0.5 * (t[a][0] + t[b][0]), 0.5 * (t[a][1] + t[b][1])};
      };
      const auto m01 = mid(0, 1), m12 = mid(1, 2), m20 = mid(2, 0);
      next.push_back({t[0], m01, m20});
      next.push_back({m01, t[1], m12});
      next.push_back({m20, m12, t[2]});
      next.push_back({m12, m20, m01});
    }
    tris = std::move(next);
  }
  std::vector<mesh::P2Point> out;
  for (const Tri& t : tris) {
    const double ax = t[1][0] - t[0][0], ay = t[1][1] - t[0][1], bx = t[2][0] - t[0][0], by = t[2][1] - t[0][1];
    const double det = std::abs(ax * by - ay * bx);
    for (int k = 0; k < rule.size(); ++k) {
      const double u = rule.points[k][1], v = rule.points[k][2];
      out.push_back(mesh::p2_point(t[0][0] + u * ax + v * bx, t[0][1] + u * ay + v * by, 0.5 * rule.weights[k] * det));
    }
  }
  return out;
}

NearSingularElements near_singular_elements(const mesh::SurfaceMesh& mesh) {
  const auto& offsets = mesh.node_element_offsets;
  NearSingularElements near;
  near.offsets.assign(1, 0);
  std::vector<int> own, cand;
  for (int i = 0; i < mesh.num_nodes(); ++i) {
    own.assign(mesh.node_elements.begin() + offsets[i], mesh.node_elements.begin() + offsets[i + 1]);
    std::sort(own.begin(), own.end());
    cand.clear();
    for (int e : own)
      for (int a = 0; a < 3; ++a) {
        const int v = mesh.elements[e][a];
        for (int k = offsets[v]; k < offsets[v + 1]; ++k) cand.push_back(mesh.node_elements[k]);
      }
    std::sort(cand.begin(), cand.end());
    cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
    for (int e : cand)
      if (!std::binary_search(own.begin(), own.end(), e)) near.elements.push_back(e);
    near.offsets.push_back(static_cast<int>(near.elements.size()));
  }
  return near;
}

}  // namespace capsim::stokes

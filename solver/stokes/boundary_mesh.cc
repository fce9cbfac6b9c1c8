#include "solver/stokes/boundary_mesh.h"

#include <algorithm>
#include <stdexcept>

namespace capsim::stokes {

BoundaryMesh make_boundary_mesh(const mesh::SurfaceMesh& mesh) {
  BoundaryMesh b;
  b.num_nodes = mesh.num_nodes();
  const int num_nodes = b.num_nodes;
  b.elements = mesh.elements;
  for (const auto& el : b.elements)
    for (int a : el)
      if (a < 0 || a >= num_nodes) throw std::invalid_argument("stokes: element refers to a missing node");
  if (static_cast<int>(mesh.node_element_offsets.size()) != num_nodes + 1)
    throw std::invalid_argument("stokes: mesh node→element offsets have the wrong size");
  b.node_offsets = mesh.node_element_offsets;
  b.inc_element.resize(mesh.node_elements.size());
  b.inc_local.resize(mesh.node_elements.size());
  for (int i = 0; i < num_nodes; ++i) {
    for (int k = b.node_offsets[i]; k < b.node_offsets[i + 1]; ++k) {
      const int e = mesh.node_elements[k];
      const auto& el = b.elements.at(e);
      const auto it = std::find(el.begin(), el.end(), i);
      if (it == el.end()) throw std::invalid_argument("stokes: node→element list inconsistent with elements");
      b.inc_element[k] = e;
      b.inc_local[k] = static_cast<int>(it - el.begin());
    }
  }
  if (static_cast<int>(mesh.mirror_node.size()) == num_nodes) b.mirror = mesh.mirror_node;
  if (static_cast<int>(mesh.central_node.size()) == num_nodes) b.central = mesh.central_node;
  std::vector<int> first(static_cast<std::size_t>(num_nodes), 0);
  for (int i = 0; i < num_nodes; ++i) {
    first[i] = num_nodes > 0 && b.node_offsets[i] < b.node_offsets[i + 1] ? b.inc_element[b.node_offsets[i]] : 0;
    for (int k = b.node_offsets[i]; k < b.node_offsets[i + 1]; ++k) first[i] = std::min(first[i], b.inc_element[k]);
  }
  b.node_order.resize(static_cast<std::size_t>(num_nodes));
  for (int i = 0; i < num_nodes; ++i) b.node_order[i] = i;
  std::stable_sort(b.node_order.begin(), b.node_order.end(), [&](int p, int q) { return first[p] < first[q]; });
  return b;
}

bool symmetric_scene(const std::vector<int>& image, const std::array<double, 3>& signs, const Eigen::Matrix3Xd& x,
                     const Eigen::Matrix3Xd& f, double x_tol, double f_tol) {
  if (image.empty() || x.cols() != static_cast<Eigen::Index>(image.size()) || f.cols() != x.cols()) return false;
  const double lx = (x.rowwise().maxCoeff() - x.rowwise().minCoeff()).norm();
  const double lf = f.colwise().norm().maxCoeff();
  return mesh::symmetric_under(image, signs, x, x_tol * lx) && mesh::symmetric_under(image, signs, f, f_tol * lf);
}

std::vector<int> orbit_targets(const BoundaryMesh& b, const Eigen::Matrix3Xd& x, bool mirror, bool central) {
  std::vector<int> targets;
  for (const int i : b.node_order) {
    if (central) {
      const int p = b.central[i], m = mirror ? b.mirror[i] : i, r = mirror ? b.mirror[p] : i;
      if (std::min({m, p, r}) < i) continue;
    } else if (mirror) {
      const int m = b.mirror[i];
      const bool mine = m == i || x(2, i) > x(2, m) || (x(2, i) == x(2, m) && i < m);
      if (!mine) continue;
    }
    targets.push_back(i);
  }
  return targets;
}

void expand_mirror(const BoundaryMesh& b, const std::vector<int>& targets, bool zero_on_plane, Eigen::Matrix3Xd& u) {
  for (const int i : targets) {
    const int m = b.mirror[i];
    if (m == i) {
      if (zero_on_plane) u(2, i) = 0.0;
      continue;
    }
    u(0, m) = u(0, i);
    u(1, m) = u(1, i);
    u(2, m) = -u(2, i);
  }
}

void expand_central(const BoundaryMesh& b, const std::vector<int>& targets, bool mirror, Eigen::Matrix3Xd& u) {
  // A node fixed by M (on the plane) or by R (on the x3 axis) gets the components the symmetry sets to zero set
  // exactly: the sums give them as round-off in double and ≈ 1e-7 |u| in mixed precision, which would move such a
  // node off its plane or axis and lose the symmetry.
  for (const int i : targets) {
    const int p = b.central[i], m = mirror ? b.mirror[i] : i, r = mirror ? b.mirror[p] : i;
    if (mirror && m == i) u(2, i) = 0.0;
    if (mirror && r == i) u(0, i) = u(1, i) = 0.0;
    const double a = u(0, i), c1 = u(1, i), c = u(2, i);
    if (mirror) u(0, r) = -a, u(1, r) = -c1, u(2, r) = c;
    u(0, p) = -a, u(1, p) = -c1, u(2, p) = -c;
    if (mirror) u(0, m) = a, u(1, m) = c1, u(2, m) = -c;
    u(0, i) = a, u(1, i) = c1, u(2, i) = c;  // last: a member that is its own image keeps its value
  }
}

}  // namespace capsim::stokes

#include "solver/diagnostics/material_point.h"

#include <cmath>
#include <limits>

#include "solver/diagnostics/shape_moments.h"

namespace capsim::diagnostics {

int choose_material_point(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, double round_D12) {
  const ShapeMoments m = shape_moments(mesh, x);
  const EllipsoidOfInertia el = ellipsoid_of_inertia(m);
  Eigen::Vector3d e(0.0, 1.0, 0.0);
  if (el.D12 >= round_D12) {
    // Short axis ⟂ long axis (cos θ, sin θ, 0).
    e = Eigen::Vector3d(-std::sin(el.theta), std::cos(el.theta), 0.0);
    // Orient toward +x2 when e is closer to x2 than to x1, else toward +x1 (long axis along x2, e.g.
    // a/b = 0.5): deciding on the dominant component keeps round-off in θ ≈ ±π/2 from flipping P.
    if ((std::abs(e.y()) >= std::abs(e.x()) ? e.y() : e.x()) < 0) e = -e;
  }
  const Eigen::Vector3d target = m.centroid + el.L2 * e;
  // An exact mirror test (x3 = 0 by construction of the symmetric meshes) rather than a coordinate tolerance.
  const bool have_mirror = static_cast<int>(mesh.mirror_node.size()) == mesh.num_nodes();
  int best = -1, best_any = -1;
  double best_d = std::numeric_limits<double>::infinity(), best_any_d = best_d;
  for (int i = 0; i < mesh.num_nodes(); ++i) {
    const double d = (x.col(i) - target).squaredNorm();
    if (d < best_any_d) best_any_d = d, best_any = i;
    if (have_mirror && mesh.mirror_node[i] == i && d < best_d) best_d = d, best = i;
  }
  return best >= 0 ? best : best_any;
}

}  // namespace capsim::diagnostics

#include "solver/stokes/kernel_problem.h"

#include "solver/mesh/mesh.h"
#include "solver/stokes/single_layer.h"

namespace capsim::stokes {

KernelProblem make_kernel_problem(int level, int regular_degree) {
  const auto mesh = mesh::make_sphere_mesh(level);
  Eigen::Matrix3Xd q(3, mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) {
    const auto x = mesh.nodes.col(i);
    q.col(i) << 1.0 + 0.5 * x(0) * x(1), -0.4 + x(2) * x(2), 0.7 * x(0) - 0.2 * x(1) * x(2);
  }
  SingleLayerOptions opt;
  opt.regular_degree = regular_degree;
  SingleLayer op(mesh, opt);
  const kernel::Sources s = op.build_sources(mesh.nodes, q);
  KernelProblem p;
  p.num_sources = op.num_quadrature_points();
  p.sx.assign(s.x, s.x + s.n);
  p.sy.assign(s.y, s.y + s.n);
  p.sz.assign(s.z, s.z + s.n);
  p.qx.assign(s.qx, s.qx + s.n);
  p.qy.assign(s.qy, s.qy + s.n);
  p.qz.assign(s.qz, s.qz + s.n);
  const int n = mesh.num_nodes();
  p.tx.resize(n);
  p.ty.resize(n);
  p.tz.resize(n);
  for (int i = 0; i < n; ++i) {
    p.tx[i] = mesh.nodes(0, i);
    p.ty[i] = mesh.nodes(1, i);
    p.tz[i] = mesh.nodes(2, i);
  }
  return p;
}

}  // namespace capsim::stokes

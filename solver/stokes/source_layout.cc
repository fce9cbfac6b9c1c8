#include "solver/stokes/source_layout.h"

namespace capsim::stokes {

void layout_points(const std::vector<mesh::P2Point>& rule, const std::vector<std::array<int, 6>>& elements,
                   const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, int width, SourceArrays& out) {
  const int ne = static_cast<int>(elements.size()), nq = static_cast<int>(rule.size());
  const int n = ne * nq;
  const int npad = (n + width - 1) / width * width;
  for (auto* v : {&out.x, &out.y, &out.z, &out.qx, &out.qy, &out.qz}) v->assign(static_cast<std::size_t>(npad), 0.0);
  double *px = out.x.data(), *py = out.y.data(), *pz = out.z.data(), *pqx = out.qx.data(), *pqy = out.qy.data(),
         *pqz = out.qz.data();
#pragma omp parallel for schedule(static)
  for (int e = 0; e < ne; ++e) {
    const auto& el = elements[e];
    double X[6][3], Q[6][3];
    for (int a = 0; a < 6; ++a)
      for (int c = 0; c < 3; ++c) {
        X[a][c] = x(c, el[a]);
        Q[a][c] = q(c, el[a]);
      }
    for (int k = 0; k < nq; ++k) {
      const mesh::P2Point& s = rule[k];
      double p[3] = {0, 0, 0}, t1[3] = {0, 0, 0}, t2[3] = {0, 0, 0}, qq[3] = {0, 0, 0};
      for (int a = 0; a < 6; ++a)
        for (int c = 0; c < 3; ++c) {
          p[c] += s.n[a] * X[a][c];
          t1[c] += s.dxi[a] * X[a][c];
          t2[c] += s.deta[a] * X[a][c];
          qq[c] += s.n[a] * Q[a][c];
        }
      const double nx = t1[1] * t2[2] - t1[2] * t2[1], ny = t1[2] * t2[0] - t1[0] * t2[2],
                   nz = t1[0] * t2[1] - t1[1] * t2[0];
      const double wj = s.w * std::sqrt(nx * nx + ny * ny + nz * nz);
      const int j = e * nq + k;
      px[j] = p[0];
      py[j] = p[1];
      pz[j] = p[2];
      pqx[j] = wj * qq[0];
      pqy[j] = wj * qq[1];
      pqz[j] = wj * qq[2];
    }
  }
}

std::vector<mesh::P2Point> replace_rule(const std::vector<mesh::P2Point>& a, const std::vector<mesh::P2Point>& b) {
  std::vector<mesh::P2Point> out = a;
  for (const mesh::P2Point& p : b) {
    out.push_back(p);
    out.back().w = -p.w;
  }
  return out;
}

}  // namespace capsim::stokes

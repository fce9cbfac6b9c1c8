#include "solver/stokes/source_layout.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "solver/mesh/p2_element.h"

namespace capsim::stokes {

void layout_points(const std::vector<mesh::P2Point>& rule, const std::vector<std::array<int, 6>>& elements,
                   const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, int width, SourceArrays& out) {
  const int ne = static_cast<int>(elements.size()), nq = static_cast<int>(rule.size());
  const int n = ne * nq;
  const int npad = (n + width - 1) / width * width;
  // Every point is written below; only the padding needs its zero load (and a finite position).
  for (auto* v : {&out.x, &out.y, &out.z, &out.qx, &out.qy, &out.qz}) {
    v->resize(static_cast<std::size_t>(npad));
    std::fill(v->begin() + n, v->end(), 0.0);
  }
  double *px = out.x.data(), *py = out.y.data(), *pz = out.z.data(), *pqx = out.qx.data(), *pqy = out.qy.data(),
         *pqz = out.qz.data();
  // The rule as arrays (ξ, η, w), the element's geometry and load in monomial form (mesh::p2_monomials).
  std::vector<double> rxi(static_cast<std::size_t>(nq)), reta(rxi.size()), rw(rxi.size());
  for (int k = 0; k < nq; ++k) {
    rxi[k] = rule[k].xi;
    reta[k] = rule[k].eta;
    rw[k] = rule[k].w;
  }
  const double *pxi = rxi.data(), *peta = reta.data(), *pw = rw.data();
#pragma omp parallel for schedule(static)
  for (int e = 0; e < ne; ++e) {
    const auto& el = elements[e];
    double C[6][3], D[6][3];
    for (int c = 0; c < 3; ++c) {
      double f[6], g[6], cf[6], cg[6];
      for (int a = 0; a < 6; ++a) {
        f[a] = x(c, el[a]);
        g[a] = q(c, el[a]);
      }
      mesh::p2_monomials(f, cf);
      mesh::p2_monomials(g, cg);
      for (int m = 0; m < 6; ++m) {
        C[m][c] = cf[m];
        D[m][c] = cg[m];
      }
    }
    const int j0 = e * nq;
#pragma omp simd
    for (int k = 0; k < nq; ++k) {
      const double xi = pxi[k], eta = peta[k];
      double p[3], t1[3], t2[3], qq[3];
      for (int c = 0; c < 3; ++c) {
        const double a = C[1][c] + xi * C[3][c] + eta * C[4][c], b = C[2][c] + eta * C[5][c];
        p[c] = C[0][c] + xi * a + eta * b;
        t1[c] = a + xi * C[3][c];
        t2[c] = b + xi * C[4][c] + eta * C[5][c];
        qq[c] = D[0][c] + xi * (D[1][c] + xi * D[3][c] + eta * D[4][c]) + eta * (D[2][c] + eta * D[5][c]);
      }
      const double nx = t1[1] * t2[2] - t1[2] * t2[1], ny = t1[2] * t2[0] - t1[0] * t2[2],
                   nz = t1[0] * t2[1] - t1[1] * t2[0];
      const double wj = pw[k] * std::sqrt(nx * nx + ny * ny + nz * nz);
      px[j0 + k] = p[0];
      py[j0 + k] = p[1];
      pz[j0 + k] = p[2];
      pqx[j0 + k] = wj * qq[0];
      pqy[j0 + k] = wj * qq[1];
      pqz[j0 + k] = wj * qq[2];
    }
  }
}

void layout_normal_points(const std::vector<mesh::P2Point>& rule, const std::vector<std::array<int, 6>>& elements,
                          const Eigen::Matrix3Xd& x, NormalSourceArrays& out) {
  const int ne = static_cast<int>(elements.size()), nq = static_cast<int>(rule.size());
  for (auto* a : {&out.x, &out.y, &out.z, &out.nx, &out.ny, &out.nz})
    a->resize(static_cast<std::size_t>(ne) * static_cast<std::size_t>(nq));
  double* pos[3] = {out.x.data(), out.y.data(), out.z.data()};
  double* nrm[3] = {out.nx.data(), out.ny.data(), out.nz.data()};
  // O(N) per surface, against the O(N²) regular sum: the element geometry through the monomial helpers of
  // mesh/p2_element.h, in a scalar loop.
#pragma omp parallel for schedule(static)
  for (int e = 0; e < ne; ++e) {
    double X[6][3], C[6][3];
    for (int a = 0; a < 6; ++a)
      for (int c = 0; c < 3; ++c) X[a][c] = x(c, elements[e][a]);
    mesh::p2_monomials3(X, C);
    for (int k = 0; k < nq; ++k) {
      double p[3], g1[3], g2[3];
      mesh::p2_monomial_geometry(C, rule[k].xi, rule[k].eta, p, g1, g2);
      const double w = rule[k].w;
      const double n[3] = {w * (g1[1] * g2[2] - g1[2] * g2[1]), w * (g1[2] * g2[0] - g1[0] * g2[2]),
                           w * (g1[0] * g2[1] - g1[1] * g2[0])};
      const std::size_t j = static_cast<std::size_t>(e) * nq + k;
      for (int c = 0; c < 3; ++c) {
        pos[c][j] = p[c];
        nrm[c][j] = n[c];
      }
    }
  }
}

void layout_density(const std::vector<mesh::P2Point>& rule, const std::vector<std::array<int, 6>>& elements,
                    const Eigen::Matrix3Xd& v, NormalSourceArrays& out) {
  const int ne = static_cast<int>(elements.size()), nq = static_cast<int>(rule.size());
  for (auto* a : {&out.vx, &out.vy, &out.vz}) a->resize(static_cast<std::size_t>(ne) * static_cast<std::size_t>(nq));
  double* den[3] = {out.vx.data(), out.vy.data(), out.vz.data()};
#pragma omp parallel for schedule(static)
  for (int e = 0; e < ne; ++e) {
    double V[6][3];
    for (int a = 0; a < 6; ++a)
      for (int c = 0; c < 3; ++c) V[a][c] = v(c, elements[e][a]);
    for (int k = 0; k < nq; ++k) {
      const std::size_t j = static_cast<std::size_t>(e) * nq + k;
      for (int c = 0; c < 3; ++c) {
        double s = 0.0;
        for (int a = 0; a < 6; ++a) s += rule[k].n[a] * V[a][c];
        den[c][j] = s;
      }
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

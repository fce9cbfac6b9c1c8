#include "solver/stokes/double_layer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "solver/mesh/p2_element.h"

namespace capsim::stokes {
namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

DoubleLayer::DoubleLayer(const mesh::SurfaceMesh& mesh, const SingleLayerOptions& options) : opt_(options) {
  if (std::string why; !opt_.valid(&why)) throw std::invalid_argument("stokes: " + why);
  topo_ = make_boundary_mesh(mesh);
  rule_ = mesh::P2Tabulation::of_degree(opt_.regular_degree);
  regular_.assign(rule_.points().begin(), rule_.points().end());
  for (int l = 0; l < 6; ++l) duffy_[l] = make_point_table(duffy_rule(l, opt_.duffy_order));
  if (opt_.near_subdivision > 0) {
    near_rule_ = replace_rule(subdivided_rule(opt_.near_subdivision, opt_.near_degree), regular_);
    // Padded with zero-weight points (zero normal, at the centroid) to whole lanes: add_double_layer_blocks.
    while (near_rule_.size() % kDoubleLayerLanes != 0) near_rule_.push_back(mesh::p2_point(1.0 / 3, 1.0 / 3, 0.0));
    near_ = near_singular_elements(mesh);
    near_begin_.resize(near_.elements.size());
    for (std::size_t k = 0; k < near_.elements.size(); ++k)
      near_begin_[k] = near_.elements[k] * static_cast<int>(near_rule_.size());
  }
}

void DoubleLayer::regular_sum(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& u) const {
  // Targets in lanes, kTile per tile (two AVX-512 vectors of doubles: register blocking), one source broadcast
  // at a time, as the portable tile of the Stokeslet sum (kernel::add_sources_to_lanes). The last tile is padded
  // with copies of its last target (their results are dropped).
  constexpr int kTile = 16;
  const int n = static_cast<int>(sources_.x.size()), nt = static_cast<int>(targets_.size());
  const int tiles = (nt + kTile - 1) / kTile;
  const double *sx = sources_.x.data(), *sy = sources_.y.data(), *sz = sources_.z.data();
  const double *svx = sources_.vx.data(), *svy = sources_.vy.data(), *svz = sources_.vz.data();
  const double *snx = sources_.nx.data(), *sny = sources_.ny.data(), *snz = sources_.nz.data();
#pragma omp parallel for schedule(static)
  for (int b = 0; b < tiles; ++b) {
    alignas(64) double tx[kTile], ty[kTile], tz[kTile], tvx[kTile], tvy[kTile], tvz[kTile];
    alignas(64) double ax[kTile] = {}, ay[kTile] = {}, az[kTile] = {};
    for (int l = 0; l < kTile; ++l) {
      const int i = targets_[std::min(b * kTile + l, nt - 1)];
      tx[l] = x(0, i), ty[l] = x(1, i), tz[l] = x(2, i);
      tvx[l] = v(0, i), tvy[l] = v(1, i), tvz[l] = v(2, i);
    }
    for (int j = 0; j < n; ++j) {
      const double px = sx[j], py = sy[j], pz = sz[j], qx = svx[j], qy = svy[j], qz = svz[j], mx = snx[j],
                   my = sny[j], mz = snz[j];
#pragma omp simd aligned(tx, ty, tz, tvx, tvy, tvz, ax, ay, az : 64)
      for (int l = 0; l < kTile; ++l) {
        const double rx = px - tx[l], ry = py - ty[l], rz = pz - tz[l];
        const double r2 = rx * rx + ry * ry + rz * rz;
        const double inv = r2 == 0.0 ? 0.0 : kernel::rsqrt_arith(r2);
        kernel::add_stresslet(rx, ry, rz, qx - tvx[l], qy - tvy[l], qz - tvz[l], mx, my, mz, inv, ax[l], ay[l], az[l]);
      }
    }
    for (int l = 0; l < kTile && b * kTile + l < nt; ++l) {
      const int i = targets_[b * kTile + l];
      u(0, i) = ax[l], u(1, i) = ay[l], u(2, i) = az[l];
    }
  }
}

void DoubleLayer::singular_correction(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                                      Eigen::Matrix3Xd& u) const {
  const int nq = static_cast<int>(regular_.size()), nt = static_cast<int>(targets_.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (int it = 0; it < nt; ++it) {
    const int i = targets_[it];
    const double x0[3] = {x(0, i), x(1, i), x(2, i)}, v0[3] = {v(0, i), v(1, i), v(2, i)};
    double acc[3] = {0.0, 0.0, 0.0};
    for (int k = topo_.node_offsets[i]; k < topo_.node_offsets[i + 1]; ++k) {
      const int e = topo_.inc_element[k];
      const auto& el = topo_.elements[e];
      // Remove what the regular rule counted for this element ...
      add_double_layer_block(x0, v0, sources_, e * nq, e * nq + nq, -1.0, acc);
      // ... and add the Duffy integral with the node at the apex, on x − x0 and v − v0 in monomial form (both
      // vanish at the apex exactly, so the integrand keeps its accuracy next to it).
      double R[6][3], W[6][3], C[6][3], D[6][3];
      for (int a = 0; a < 6; ++a)
        for (int c = 0; c < 3; ++c) {
          R[a][c] = x(c, el[a]) - x0[c];
          W[a][c] = v(c, el[a]) - v0[c];
        }
      mesh::p2_monomials3(R, C);
      mesh::p2_monomials3(W, D);
      const PointTable& tb = duffy_[topo_.inc_local[k]];
      const double *pxi = tb.xi.data(), *peta = tb.eta.data(), *wt = tb.w.data();
      double sx = 0.0, sy = 0.0, sz = 0.0;
      // The geometry of mesh::p2_monomial_geometry written out: through that helper's array arguments GCC 12
      // keeps the arrays in memory in `omp simd` loops (p2_element.h), which made this phase 3× slower.
#pragma omp simd reduction(+ : sx, sy, sz)
      for (int p = 0; p < tb.count; ++p) {
        const double xi = pxi[p], eta = peta[p];
        double d[3], g1[3], g2[3], dv[3];
        for (int c = 0; c < 3; ++c) {
          const double e = C[1][c] + xi * C[3][c] + eta * C[4][c], h = C[2][c] + eta * C[5][c];
          d[c] = C[0][c] + xi * e + eta * h;
          g1[c] = e + xi * C[3][c];
          g2[c] = h + xi * C[4][c] + eta * C[5][c];
          dv[c] = D[0][c] + xi * (D[1][c] + xi * D[3][c] + eta * D[4][c]) + eta * (D[2][c] + eta * D[5][c]);
        }
        const double w = wt[p];
        const double nx = w * (g1[1] * g2[2] - g1[2] * g2[1]), ny = w * (g1[2] * g2[0] - g1[0] * g2[2]),
                     nz = w * (g1[0] * g2[1] - g1[1] * g2[0]);
        // Duffy points are interior, so d ≠ 0 on a non-degenerate element.
        const double inv = kernel::rsqrt_arith(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        kernel::add_stresslet(d[0], d[1], d[2], dv[0], dv[1], dv[2], nx, ny, nz, inv, sx, sy, sz);
      }
      acc[0] += sx;
      acc[1] += sy;
      acc[2] += sz;
    }
    for (int c = 0; c < 3; ++c) u(c, i) += acc[c];
  }
}

void DoubleLayer::near_correction(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& u) const {
  const int nr = static_cast<int>(near_rule_.size());
  if (nr == 0) return;
  const int nt = static_cast<int>(targets_.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (int it = 0; it < nt; ++it) {
    const int i = targets_[it];
    const double x0[3] = {x(0, i), x(1, i), x(2, i)}, v0[3] = {v(0, i), v(1, i), v(2, i)};
    double acc[3] = {0.0, 0.0, 0.0};
    // Near-singular neighbours: subdivided rule in, regular rule out (negative weights), one block each.
    add_double_layer_blocks(x0, v0, near_points_, near_begin_.data() + near_.offsets[i],
                            near_.offsets[i + 1] - near_.offsets[i], nr, acc);
    for (int c = 0; c < 3; ++c) u(c, i) += acc[c];
  }
}

void DoubleLayer::apply(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& u) {
  const int nn = topo_.num_nodes;
  if (x.cols() != nn || v.cols() != nn)
    throw std::invalid_argument("stokes: x and v must have " + std::to_string(nn) + " columns (got " +
                                std::to_string(x.cols()) + " and " + std::to_string(v.cols()) + ")");
  const double t0 = now_s();
  bool sym = false;
  if (opt_.symmetry != Symmetry::Off) {
    sym = is_symmetric(x, v);
    if (!sym && opt_.symmetry == Symmetry::On)
      throw std::invalid_argument("stokes: symmetry forced on but the scene is not symmetric under x3 -> -x3");
  }
  const bool central = opt_.central_symmetry && opt_.symmetry != Symmetry::Off && is_centrally_symmetric(x, v);
  layout_normal_points(regular_, topo_.elements, x, v, sources_);
  if (!near_rule_.empty()) layout_normal_points(near_rule_, topo_.elements, x, v, near_points_);
  targets_ = orbit_targets(topo_, x, sym, central);
  const double t1 = now_s();
  u.resize(3, nn);
  regular_sum(x, v, u);
  const double t2 = now_s();
  singular_correction(x, v, u);
  const double t3 = now_s();
  near_correction(x, v, u);
  // The subtracted principal value: − 4π v(x0).
  constexpr double kFourPi = 4.0 * std::numbers::pi;
  for (const int i : targets_)
    for (int c = 0; c < 3; ++c) u(c, i) -= kFourPi * v(c, i);
  // The nodes not evaluated, from the symmetries (in double the components they set to zero are round-off).
  if (central)
    expand_central(topo_, targets_, sym, u);
  else if (sym)
    expand_mirror(topo_, targets_, false, u);
  const double t4 = now_s();
  stats_.used_symmetry = sym;
  stats_.used_central = central;
  stats_.targets = static_cast<int>(targets_.size());
  stats_.sources = static_cast<int>(sources_.x.size());
  stats_.build_s = t1 - t0;
  stats_.regular_s = t2 - t1;
  stats_.singular_s = t3 - t2;
  stats_.near_s = t4 - t3;
  stats_.total_s = t4 - t0;
}

bool DoubleLayer::is_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) const {
  return x.cols() == topo_.num_nodes &&
         symmetric_scene(topo_.mirror, mesh::kMirrorSigns, x, v, opt_.symmetry_tol, opt_.load_symmetry_tol);
}

bool DoubleLayer::is_centrally_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) const {
  return x.cols() == topo_.num_nodes &&
         symmetric_scene(topo_.central, mesh::kCentralSigns, x, v, opt_.symmetry_tol, opt_.load_symmetry_tol);
}

Eigen::Matrix3Xd DoubleLayer::apply(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v) {
  Eigen::Matrix3Xd u;
  apply(x, v, u);
  return u;
}

Eigen::Matrix3Xd DoubleLayer::flux_weights(const Eigen::Matrix3Xd& x) const {
  if (x.cols() != topo_.num_nodes)
    throw std::invalid_argument("stokes: x must have " + std::to_string(topo_.num_nodes) + " columns");
  // Per element in parallel, summed over elements serially in element order (bitwise the same on any number of
  // threads).
  const int ne = num_elements();
  std::vector<Eigen::Matrix<double, 3, 6>> local(static_cast<std::size_t>(ne));
#pragma omp parallel for schedule(static)
  for (int e = 0; e < ne; ++e) {
    const auto& el = topo_.elements[e];
    local[e].setZero();
    for (int q = 0; q < rule_.size(); ++q) {
      const mesh::Tangents t = rule_.tangents(x, el, q);
      const Eigen::Vector3d n = rule_.weight(q) * t.g1.cross(t.g2);
      for (int a = 0; a < 6; ++a) local[e].col(a) += rule_[q].n[a] * n;
    }
  }
  Eigen::Matrix3Xd a = Eigen::Matrix3Xd::Zero(3, topo_.num_nodes);
  for (int e = 0; e < ne; ++e)
    for (int k = 0; k < 6; ++k) a.col(topo_.elements[e][k]) += local[e].col(k);
  return a;
}

}  // namespace capsim::stokes

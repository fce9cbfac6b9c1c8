#include "solver/stokes/double_layer.h"

#include <algorithm>
#include <chrono>

#include <Eigen/Core>
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

// The shape functions N_a of a rule's points as structure of arrays (a-major: shape[a * count + p]).
std::vector<double> shape_table(const std::vector<mesh::P2Point>& rule) {
  const std::size_t n = rule.size();
  std::vector<double> out(6 * n);
  for (std::size_t p = 0; p < n; ++p)
    for (int a = 0; a < 6; ++a) out[a * n + p] = rule[p].n[a];
  return out;
}

DoubleLayer::DoubleLayer(const mesh::SurfaceMesh& mesh, const SingleLayerOptions& options) : opt_(options) {
  if (std::string why; !opt_.valid(&why)) throw std::invalid_argument("stokes: " + why);
  topo_ = make_boundary_mesh(mesh);
  const mesh::P2Tabulation rule = mesh::P2Tabulation::of_degree(opt_.regular_degree);
  regular_.assign(rule.points().begin(), rule.points().end());
  regular_shape_ = shape_table(regular_);
  for (int l = 0; l < 6; ++l) {
    const std::vector<mesh::P2Point> rule = duffy_rule(l, opt_.duffy_order);
    duffy_[l] = make_point_table(rule);
    duffy_shape_[l] = shape_table(rule);
  }
  if (opt_.near_subdivision > 0) {
    near_rule_ = replace_rule(subdivided_rule(opt_.near_subdivision, opt_.near_degree), regular_);
    near_shape_ = shape_table(near_rule_);
    near_ = near_singular_elements(mesh);
  }
  make_correction_slots();
}

bool DoubleLayer::uses_mixed_precision() const {
  return opt_.precision == KernelPrecision::Mixed && opt_.kernel == KernelChoice::Fast;
}

void DoubleLayer::regular_sum(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& u) {
  const int nt = static_cast<int>(targets_.size());
  for (auto* a : {&tx_, &ty_, &tz_, &tvx_, &tvy_, &tvz_, &ux_, &uy_, &uz_}) a->resize(static_cast<std::size_t>(nt));
  for (int k = 0; k < nt; ++k) {
    const int i = targets_[k];
    tx_[k] = x(0, i), ty_[k] = x(1, i), tz_[k] = x(2, i);
    tvx_[k] = v(0, i), tvy_[k] = v(1, i), tvz_[k] = v(2, i);
  }
  const kernel::StressletTargets t{tx_.data(), ty_.data(), tz_.data(), tvx_.data(), tvy_.data(), tvz_.data(), nt};
  const kernel::StressletSources s{sources_.x.data(),  sources_.y.data(),  sources_.z.data(),
                                   sources_.vx.data(), sources_.vy.data(), sources_.vz.data(),
                                   sources_.nx.data(), sources_.ny.data(), sources_.nz.data(),
                                   static_cast<int>(sources_.x.size())};
  const kernel::Result r{ux_.data(), uy_.data(), uz_.data()};
  if (opt_.kernel == KernelChoice::Plain)
    kernel::stresslet_sum_plain(t, s, r);
  else if (uses_mixed_precision())
    kernel::stresslet_sum_mixed(t, s, r);
  else
    kernel::stresslet_sum_fast(t, s, r);
  for (int k = 0; k < nt; ++k) {
    const int i = targets_[k];
    u(0, i) = ux_[k], u(1, i) = uy_[k], u(2, i) = uz_[k];
  }
}

namespace {

// W[a][m] += sign · Σ_p N_a(p) G_m(p) over `count` points, G(p) = −6 (r·n)/|r|⁵ · r rᵀ (its six entries xx, xy, xz,
// yy, yz, zz), r = (px, py, pz)[p] − x0 from the target to the point, n = (nx, ny, nz)[p] the weighted normal, N the
// shape table (a-major, stride `count`): the stresslet kernel::add_stresslet as a matrix on the density
// difference, d·T·n = G d. A point at the target contributes nothing. g: work array.
void accumulate_points(const double* px, const double* py, const double* pz, const double* nx, const double* ny,
                       const double* nz, const double x0[3], int count, const double* shape, double sign,
                       std::vector<double>& g, double W[6][6]) {
  g.resize(static_cast<std::size_t>(6) * count);
  double *g0 = g.data(), *g1 = g0 + count, *g2 = g1 + count, *g3 = g2 + count, *g4 = g3 + count, *g5 = g4 + count;
#pragma omp simd
  for (int p = 0; p < count; ++p) {
    const double x = px[p] - x0[0], y = py[p] - x0[1], z = pz[p] - x0[2];
    const double r2 = x * x + y * y + z * z;
    const double inv = r2 == 0.0 ? 0.0 : kernel::rsqrt_arith(r2);
    // kernel::add_stresslet with the density left out: its u = s r, s = −6 (d·r)(r·n)/r⁵ = (d·r) c.
    const double inv2 = inv * inv;
    const double c = sign * -6.0 * (nx[p] * x + ny[p] * y + nz[p] * z) * (inv2 * inv2 * inv);
    g0[p] = c * x * x, g1[p] = c * x * y, g2[p] = c * x * z;
    g3[p] = c * y * y, g4[p] = c * y * z, g5[p] = c * z * z;
  }
  // W += Nᵀ G, (6 × count) (count × 6): per a, six sums over the points.
  for (int a = 0; a < 6; ++a) {
    const double* na = shape + static_cast<std::size_t>(a) * count;
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0, s4 = 0.0, s5 = 0.0;
#pragma omp simd reduction(+ : s0, s1, s2, s3, s4, s5)
    for (int p = 0; p < count; ++p) {
      const double w = na[p];
      s0 += w * g0[p], s1 += w * g1[p], s2 += w * g2[p], s3 += w * g3[p], s4 += w * g4[p], s5 += w * g5[p];
    }
    W[a][0] += s0, W[a][1] += s1, W[a][2] += s2, W[a][3] += s3, W[a][4] += s4, W[a][5] += s5;
  }
}

}  // namespace

void DoubleLayer::make_correction_slots() {
  // For every node: its neighbours through its own and its near-singular elements (itself left out: its
  // difference v_i − v_i is 0), and for each (element, local node) of those the neighbour's slot (−1: the node).
  const int nn = topo_.num_nodes;
  correction_offsets_.assign(static_cast<std::size_t>(nn) + 1, 0);
  correction_nodes_.clear();
  own_slots_.assign(topo_.inc_element.size() * 6, -1);
  near_slots_.assign(near_.elements.size() * 6, -1);
  std::vector<int> list;
  for (int i = 0; i < nn; ++i) {
    list.clear();
    auto slot = [&](int node) {
      if (node == i) return -1;
      for (std::size_t k = 0; k < list.size(); ++k)
        if (list[k] == node) return static_cast<int>(k);
      list.push_back(node);
      return static_cast<int>(list.size()) - 1;
    };
    for (int k = topo_.node_offsets[i]; k < topo_.node_offsets[i + 1]; ++k)
      for (int a = 0; a < 6; ++a) own_slots_[6 * k + a] = slot(topo_.elements[topo_.inc_element[k]][a]);
    if (!near_.offsets.empty())
      for (int k = near_.offsets[i]; k < near_.offsets[i + 1]; ++k)
        for (int a = 0; a < 6; ++a) near_slots_[6 * k + a] = slot(topo_.elements[near_.elements[k]][a]);
    correction_nodes_.insert(correction_nodes_.end(), list.begin(), list.end());
    correction_offsets_[i + 1] = static_cast<int>(correction_nodes_.size());
  }
}

void DoubleLayer::prepare_corrections(const Eigen::Matrix3Xd& x) {
  // The geometry of every point of the regular rule (and of the near rule) on x; the densities are laid out per
  // apply (layout_density).
  layout_normal_points(regular_, topo_.elements, x, sources_);
  if (!near_rule_.empty()) layout_normal_points(near_rule_, topo_.elements, x, near_points_);
  const int nq = static_cast<int>(regular_.size()), nr = static_cast<int>(near_rule_.size());
  const int nt = static_cast<int>(targets_.size());
  // The targets' rows, in targets_ order.
  row_offsets_.resize(static_cast<std::size_t>(nt) + 1);
  row_offsets_[0] = 0;
  for (int it = 0; it < nt; ++it)
    row_offsets_[it + 1] =
        row_offsets_[it] + correction_offsets_[targets_[it] + 1] - correction_offsets_[targets_[it]];
  correction_weights_.assign(6 * static_cast<std::size_t>(row_offsets_[nt]), 0.0);
#pragma omp parallel
  {
    std::vector<double> g, rx, ry, rz, nx, ny, nz;
#pragma omp for schedule(dynamic, 16)
    for (int it = 0; it < nt; ++it) {
      const int i = targets_[it];
      const double x0[3] = {x(0, i), x(1, i), x(2, i)};
      double* row = correction_weights_.data() + 6 * static_cast<std::size_t>(row_offsets_[it]);
      // Adds an element's six node matrices to the target's row at their slots.
      auto add = [&](const int* slots, const double W[6][6]) {
        for (int a = 0; a < 6; ++a)
          if (slots[a] >= 0)
            for (int m = 0; m < 6; ++m) row[6 * slots[a] + m] += W[a][m];
      };
      // A laid-out block of points against x0.
      auto block = [&](const NormalSourceArrays& s, int begin, int count, const double* shape, double sign,
                       double W[6][6]) {
        accumulate_points(s.x.data() + begin, s.y.data() + begin, s.z.data() + begin, s.nx.data() + begin,
                          s.ny.data() + begin, s.nz.data() + begin, x0, count, shape, sign, g, W);
      };
      constexpr double kApex[3] = {0.0, 0.0, 0.0};  // the Duffy points are relative to x0 already
      for (int k = topo_.node_offsets[i]; k < topo_.node_offsets[i + 1]; ++k) {
        const int e = topo_.inc_element[k], l = topo_.inc_local[k];
        const auto& el = topo_.elements[e];
        double W[6][6] = {};
        // Remove what the regular rule counts for this element ...
        block(sources_, e * nq, nq, regular_shape_.data(), -1.0, W);
        // ... and add the Duffy integral with the node at the apex, the geometry on x − x0 in monomial form (it
        // vanishes at the apex exactly, so the kernel keeps its accuracy next to it).
        double R[6][3], C[6][3];
        for (int a = 0; a < 6; ++a)
          for (int c = 0; c < 3; ++c) R[a][c] = x(c, el[a]) - x0[c];
        mesh::p2_monomials3(R, C);
        const PointTable& tb = duffy_[l];
        for (auto* a : {&rx, &ry, &rz, &nx, &ny, &nz}) a->resize(static_cast<std::size_t>(tb.count));
        const double *pxi = tb.xi.data(), *peta = tb.eta.data(), *wt = tb.w.data();
        double *px = rx.data(), *py = ry.data(), *pz = rz.data(), *qx = nx.data(), *qy = ny.data(), *qz = nz.data();
        // The geometry of mesh::p2_monomial_geometry written out (p2_element.h: GCC keeps that helper's arrays in
        // memory in `omp simd` loops).
#pragma omp simd
        for (int p = 0; p < tb.count; ++p) {
          const double xi = pxi[p], eta = peta[p];
          double d[3], g1[3], g2[3];
          for (int c = 0; c < 3; ++c) {
            const double ee = C[1][c] + xi * C[3][c] + eta * C[4][c], h = C[2][c] + eta * C[5][c];
            d[c] = C[0][c] + xi * ee + eta * h;
            g1[c] = ee + xi * C[3][c];
            g2[c] = h + xi * C[4][c] + eta * C[5][c];
          }
          const double w = wt[p];
          px[p] = d[0], py[p] = d[1], pz[p] = d[2];
          qx[p] = w * (g1[1] * g2[2] - g1[2] * g2[1]);
          qy[p] = w * (g1[2] * g2[0] - g1[0] * g2[2]);
          qz[p] = w * (g1[0] * g2[1] - g1[1] * g2[0]);
        }
        accumulate_points(px, py, pz, qx, qy, qz, kApex, tb.count, duffy_shape_[l].data(), 1.0, g, W);
        add(own_slots_.data() + 6 * k, W);
      }
      // Near-singular neighbours: the subdivided rule in, the regular rule out (negative weights in near_rule_).
      if (nr > 0)
        for (int k = near_.offsets[i]; k < near_.offsets[i + 1]; ++k) {
          const int e = near_.elements[k];
          double W[6][6] = {};
          block(near_points_, e * nr, nr, near_shape_.data(), 1.0, W);
          add(near_slots_.data() + 6 * k, W);
        }
    }
  }
}

void DoubleLayer::apply_corrections(const Eigen::Matrix3Xd& v, Eigen::Matrix3Xd& u) const {
  const int nt = static_cast<int>(targets_.size());
#pragma omp parallel for schedule(static)
  for (int it = 0; it < nt; ++it) {
    const int i = targets_[it];
    const double v0x = v(0, i), v0y = v(1, i), v0z = v(2, i);
    double ax = 0.0, ay = 0.0, az = 0.0;
    const int* nodes = correction_nodes_.data() + correction_offsets_[i];
    const double* w = correction_weights_.data() + 6 * static_cast<std::size_t>(row_offsets_[it]);
    for (int k = 0; k < correction_offsets_[i + 1] - correction_offsets_[i]; ++k, w += 6) {
      const int b = nodes[k];
      const double dx = v(0, b) - v0x, dy = v(1, b) - v0y, dz = v(2, b) - v0z;
      ax += w[0] * dx + w[1] * dy + w[2] * dz;
      ay += w[1] * dx + w[3] * dy + w[4] * dz;
      az += w[2] * dx + w[4] * dy + w[5] * dz;
    }
    u(0, i) += ax;
    u(1, i) += ay;
    u(2, i) += az;
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
  // What depends on the surface alone (the points' geometry, the correction matrices of the targets) is kept
  // while x (bit for bit) and the target set stay the same: within a second-kind solve every application.
  const bool same = prepared_ && sym == prepared_mirror_ && central == prepared_central_ &&
                    prepared_x_.cols() == x.cols() && (prepared_x_.array() == x.array()).all();
  const double t1 = now_s();
  if (!same) {
    targets_ = orbit_targets(topo_, x, sym, central);
    prepare_corrections(x);
    prepared_x_ = x;
    prepared_mirror_ = sym;
    prepared_central_ = central;
    prepared_ = true;
  }
  const double t2 = now_s();
  layout_density(regular_, topo_.elements, v, sources_);
  const double t3 = now_s();
  u.resize(3, nn);
  regular_sum(x, v, u);
  const double t4 = now_s();
  apply_corrections(v, u);
  const double t5 = now_s();
  // The subtracted principal value: − 4π v(x0).
  constexpr double kFourPi = 4.0 * std::numbers::pi;
  for (const int i : targets_)
    for (int c = 0; c < 3; ++c) u(c, i) -= kFourPi * v(c, i);
  // The nodes not evaluated, from the symmetries (in double the components they set to zero are round-off; in
  // mixed precision u3 on the mirror plane is set to 0 exactly, as the single layer does).
  if (central)
    expand_central(topo_, targets_, sym, u);
  else if (sym)
    expand_mirror(topo_, targets_, uses_mixed_precision(), u);
  const double t6 = now_s();
  stats_.used_symmetry = sym;
  stats_.used_central = central;
  stats_.targets = static_cast<int>(targets_.size());
  stats_.sources = static_cast<int>(sources_.x.size());
  stats_.prepared = !same;
  stats_.prepare_s = t2 - t1;
  stats_.build_s = (t1 - t0) + (t3 - t2);
  stats_.regular_s = t4 - t3;
  stats_.singular_s = t5 - t4;
  stats_.near_s = t6 - t5;
  stats_.total_s = t6 - t0;
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
  // The nodes' flux moments (one owner: mesh::node_normals_and_flux_moments, exact for P2 fields).
  Eigen::Matrix3Xd normals, a;
  std::vector<double> scratch;
  mesh::node_normals_and_flux_moments(topo_.elements, x, normals, a, scratch);
  return a;
}

}  // namespace capsim::stokes

#include "solver/stokes/single_layer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "solver/quadrature/triangle_rule.h"

namespace capsim::stokes {
namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

bool fail(std::string* why, const std::string& message) {
  if (why != nullptr) *why = message;
  return false;
}

// The Duffy integral of one element with the target at the apex of the table, in single precision
// (KernelPrecision::Mixed), added to acc. C and D: the element's position and load in monomial form about
// (ξ, η) = (0, 0) (mesh::p2_monomials), re-expanded here in double about the apex P. Of the position only
// C1..C5 are read: about P, which is the target, the constant term is 0, and the others do not depend on the
// origin of the positions (absolute ones do: their rounding, 1e-16 of |x|, is far below float's). So the
// float loop works with coordinates (u, v) relative to P and a position d that vanishes at P exactly:
// next to the apex, where the points crowd and the terms are largest, d keeps its float relative accuracy
// instead of inheriting the cancellation of C0 + ... against a far origin. The terms are summed in float over
// chunks of kDuffyChunk points (one 8 × 8 Duffy square) and the chunk sums in double, as kernel::sum_mixed
// sums blocks of sources.
constexpr int kDuffyChunk = 64;

void duffy_mixed(const ApexTableF& tb, const double C[6][3], const double D[6][3], double acc[3]) {
  const double a = tb.apex_xi, b = tb.apex_eta;
  float c[6][3], f[6][3];  // shifted coefficients: g(u, v) = c0 + c1 u + c2 v + c3 u² + c4 u v + c5 v²
  for (int k = 0; k < 3; ++k) {
    c[0][k] = 0.0f;  // the target is the apex node: its relative position is exactly 0
    c[1][k] = static_cast<float>(C[1][k] + 2.0 * C[3][k] * a + C[4][k] * b);
    c[2][k] = static_cast<float>(C[2][k] + C[4][k] * a + 2.0 * C[5][k] * b);
    c[3][k] = static_cast<float>(C[3][k]);
    c[4][k] = static_cast<float>(C[4][k]);
    c[5][k] = static_cast<float>(C[5][k]);
    f[0][k] = static_cast<float>(D[0][k] + a * (D[1][k] + a * D[3][k] + b * D[4][k]) + b * (D[2][k] + b * D[5][k]));
    f[1][k] = static_cast<float>(D[1][k] + 2.0 * D[3][k] * a + D[4][k] * b);
    f[2][k] = static_cast<float>(D[2][k] + D[4][k] * a + 2.0 * D[5][k] * b);
    f[3][k] = static_cast<float>(D[3][k]);
    f[4][k] = static_cast<float>(D[4][k]);
    f[5][k] = static_cast<float>(D[5][k]);
  }
  const float *pu = tb.u.data(), *pv = tb.v.data(), *wt = tb.w.data();
  double sx = 0.0, sy = 0.0, sz = 0.0;
  for (int p0 = 0; p0 < tb.count; p0 += kDuffyChunk) {
    const int p1 = std::min(tb.count, p0 + kDuffyChunk);
    float fx = 0.0f, fy = 0.0f, fz = 0.0f;
    // The body of the double loop in SingleLayer::singular_correction, in float and about the apex. Written
    // out twice on purpose: one shared inline template for both made GCC 12 slower here (float singular phase
    // 0.78–0.92 → 1.14–1.16 ms on a level-3 evaluation, alternated runs), as a shared geometry
    // helper had before (results/benchmarks.md, "Flow evaluation by phase").
#pragma omp simd reduction(+ : fx, fy, fz)
    for (int p = p0; p < p1; ++p) {
      const float u = pu[p], v = pv[p];
      float d[3], t1[3], t2[3], qq[3];
      for (int k = 0; k < 3; ++k) {
        const float e = c[1][k] + u * c[3][k] + v * c[4][k], g = c[2][k] + v * c[5][k];
        d[k] = u * e + v * g;
        t1[k] = e + u * c[3][k];
        t2[k] = g + u * c[4][k] + v * c[5][k];
        qq[k] = f[0][k] + u * (f[1][k] + u * f[3][k] + v * f[4][k]) + v * (f[2][k] + v * f[5][k]);
      }
      const float nx = t1[1] * t2[2] - t1[2] * t2[1], ny = t1[2] * t2[0] - t1[0] * t2[2],
                  nz = t1[0] * t2[1] - t1[1] * t2[0];
      const float nn = nx * nx + ny * ny + nz * nz;
      const float r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      // As in the double loop: with s = (nn r²)^(−1/2), w |t1 × t2| / |r| = w nn s and 1/r² = nn s².
      const float s = kernel::rsqrt_arith(nn * r2), ns = nn * s;
      kernel::add_stokeslet_scaled(-d[0], -d[1], -d[2], qq[0], qq[1], qq[2], ns * s, wt[p] * ns, fx, fy, fz);
    }
    sx += fx;
    sy += fy;
    sz += fz;
  }
  acc[0] += sx;
  acc[1] += sy;
  acc[2] += sz;
}

}  // namespace

bool SingleLayerOptions::valid(std::string* why) const {
  // Degrees 1 and 2 exist only as far-field rules: the regular and near rules must stay accurate near targets.
  auto accurate = [](int d) { return d >= 4 && d <= 6; };
  if (!accurate(regular_degree))
    return fail(why, "regular_degree must be 4, 5 or 6, got " + std::to_string(regular_degree));
  if (!accurate(near_degree)) return fail(why, "near_degree must be 4, 5 or 6, got " + std::to_string(near_degree));
  if (duffy_order < 2 || duffy_order > 64)
    return fail(why, "duffy_order must be 2..64, got " + std::to_string(duffy_order));
  if (near_subdivision < 0 || near_subdivision > 4)
    return fail(why, "near_subdivision must be 0..4, got " + std::to_string(near_subdivision));
  if (far_degree < 0 || far_degree > 2)
    return fail(why, "far_degree must be 0 (off), 1 or 2, got " + std::to_string(far_degree));
  // far_radius ≤ 1 would call elements far from their own nodes' neighbourhood (|x0 − c_e| ≤ ρ_e for a node
  // of e); the own elements are always treated as mid anyway, but such a radius is surely a mistake.
  if (!(far_radius > 1.0) || !std::isfinite(far_radius))
    return fail(why, "far_radius must be a finite number > 1, got " + std::to_string(far_radius));
  if (!(symmetry_tol >= 0.0)) return fail(why, "symmetry_tol must be >= 0");
  if (!(load_symmetry_tol >= 0.0)) return fail(why, "load_symmetry_tol must be >= 0");
  if (fast.block < 1 || fast.block > 4) return fail(why, "fast.block must be 1..4, got " + std::to_string(fast.block));
  return true;
}

SingleLayer::SingleLayer(const mesh::SurfaceMesh& mesh, const SingleLayerOptions& options) : opt_(options) {
  if (std::string why; !opt_.valid(&why)) throw std::invalid_argument("stokes: " + why);
  topo_ = make_boundary_mesh(mesh);
  const auto regular = mesh::P2Tabulation::of_degree(opt_.regular_degree);
  regular_.assign(regular.points().begin(), regular.points().end());
  rule_size_ = static_cast<int>(regular_.size());
  for (int l = 0; l < 6; ++l) duffy_[l] = make_point_table(duffy_rule(l, opt_.duffy_order));
  if (uses_mixed_precision())
    for (int l = 0; l < 6; ++l) duffy_f_[l] = make_apex_table(l, opt_.duffy_order);
  if (opt_.near_subdivision > 0) {
    near_rule_ = replace_rule(subdivided_rule(opt_.near_subdivision, opt_.near_degree), regular_);
    // Padded with zero-weight points (zero load, at the centroid) to whole SIMD vectors: kernel::sum_blocks.
    const int w = kernel::simd_width();
    while (near_rule_.size() % static_cast<std::size_t>(w) != 0) near_rule_.push_back(mesh::p2_point(1.0 / 3, 1.0 / 3, 0.0));
    near_ = near_singular_elements(mesh);
    near_begin_.resize(near_.elements.size());
    for (std::size_t k = 0; k < near_.elements.size(); ++k)
      near_begin_[k] = near_.elements[k] * static_cast<int>(near_rule_.size());
  }
  if (opt_.far_degree > 0) {
    const auto coarse = mesh::P2Tabulation::of_degree(opt_.far_degree);
    coarse_.assign(coarse.points().begin(), coarse.points().end());
    mid_rule_ = replace_rule(regular_, coarse_);
  }
}

bool SingleLayer::is_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q) const {
  return x.cols() == topo_.num_nodes &&
         symmetric_scene(topo_.mirror, mesh::kMirrorSigns, x, q, opt_.symmetry_tol, opt_.load_symmetry_tol);
}

bool SingleLayer::is_centrally_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q) const {
  return x.cols() == topo_.num_nodes &&
         symmetric_scene(topo_.central, mesh::kCentralSigns, x, q, opt_.symmetry_tol, opt_.load_symmetry_tol);
}

kernel::Sources SingleLayer::build_sources(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q) {
  layout_points(regular_, topo_.elements, x, q, kernel::simd_width(), sources_);
  return sources_.sources();
}

void SingleLayer::select_targets(const Eigen::Matrix3Xd& x, bool symmetric, bool central) {
  target_ids_ = orbit_targets(topo_, x, symmetric, central);
  const int nt = static_cast<int>(target_ids_.size());
  for (auto* v : {&tx_, &ty_, &tz_, &ux_, &uy_, &uz_}) v->resize(static_cast<std::size_t>(nt));
  for (int k = 0; k < nt; ++k) {
    tx_[k] = x(0, target_ids_[k]);
    ty_[k] = x(1, target_ids_[k]);
    tz_[k] = x(2, target_ids_[k]);
  }
}

void SingleLayer::regular_sum(const kernel::Sources& src, Eigen::Matrix3Xd& u) {
  const int nt = static_cast<int>(target_ids_.size());
  const kernel::Targets tg{tx_.data(), ty_.data(), tz_.data(), nt};
  const kernel::Result res{ux_.data(), uy_.data(), uz_.data()};
  if (opt_.kernel == KernelChoice::Plain)
    kernel::sum_plain(tg, src, res);
  else if (opt_.precision == KernelPrecision::Mixed)
    kernel::sum_mixed(tg, src, res);
  else
    kernel::sum_fast(tg, src, res, opt_.fast);
  u.resize(3, topo_.num_nodes);
  for (int k = 0; k < nt; ++k) {
    u(0, target_ids_[k]) = ux_[k];
    u(1, target_ids_[k]) = uy_[k];
    u(2, target_ids_[k]) = uz_[k];
  }
}

long long SingleLayer::far_field(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, Eigen::Matrix3Xd& u) {
  // Mid elements (and the own/near ones) upgraded from the coarse to the regular rule. The singular
  // correction then finds the regular points of each element in the mid layout (first nq of each block)
  // instead of the all-pairs sources.
  grid_.build(x, topo_.elements, opt_.far_radius);
  layout_points(mid_rule_, grid_.sorted_elements, x, q, 1, mid_points_);
  regular_points_ = &mid_points_;
  regular_stride_ = static_cast<int>(mid_rule_.size());
  regular_slot_ = grid_.slot.data();
  return add_mid_blocks(grid_, mid_points_, static_cast<int>(mid_rule_.size()), topo_.node_offsets,
                        topo_.inc_element, near_, target_ids_, x, mid_scratch_, u);
}

void SingleLayer::singular_correction(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q) {
  const int nt = static_cast<int>(target_ids_.size()), nq = rule_size_;
  const SourceArrays& reg = *regular_points_;
  const int stride = regular_stride_;
  const int* slot = regular_slot_;
  const bool mixed = uses_mixed_precision();
  if (mixed) {
    // The monomials of every element's position and load, once per call instead of once per (target,
    // element) pair: in duffy_mixed only C1..C5 of the position enter (the apex is the target), and those do
    // not depend on the target.
    const int ne = num_elements();
    element_monomials_.resize(static_cast<std::size_t>(ne) * 36);
#pragma omp parallel for schedule(static)
    for (int e = 0; e < ne; ++e) {
      double X[6][3], F[6][3];
      for (int a = 0; a < 6; ++a)
        for (int c = 0; c < 3; ++c) {
          X[a][c] = x(c, topo_.elements[e][a]);
          F[a][c] = q(c, topo_.elements[e][a]);
        }
      double* m = element_monomials_.data() + static_cast<std::size_t>(e) * 36;
      mesh::p2_monomials3(X, reinterpret_cast<double(*)[3]>(m));
      mesh::p2_monomials3(F, reinterpret_cast<double(*)[3]>(m + 18));
    }
  }
#pragma omp parallel for schedule(dynamic, 16)
  for (int it = 0; it < nt; ++it) {
    const int i = target_ids_[it];
    const double x0[3] = {x(0, i), x(1, i), x(2, i)};
    double acc[3] = {0.0, 0.0, 0.0};
    for (int k = topo_.node_offsets[i]; k < topo_.node_offsets[i + 1]; ++k) {
      const int e = topo_.inc_element[k], l = topo_.inc_local[k];
      const auto& el = topo_.elements[e];
      // Remove what the regular rule counted for this element ...
      const int b = (slot != nullptr ? slot[e] : e) * stride;
      add_block(x0, reg, b, b + nq, -1.0, acc);
      // ... and add the Duffy integral with the node at the apex. Positions relative to x0 (Σ N_a = 1)
      // avoid cancellation near the apex; geometry and load in monomial form (mesh::p2_monomials).
      if (mixed) {
        const double* m = element_monomials_.data() + static_cast<std::size_t>(e) * 36;
        duffy_mixed(duffy_f_[l], reinterpret_cast<const double(*)[3]>(m),
                    reinterpret_cast<const double(*)[3]>(m + 18), acc);
        continue;
      }
      double C[6][3], D[6][3];
      for (int c = 0; c < 3; ++c) {
        double r[6], f[6], cr[6], cf[6];
        for (int a = 0; a < 6; ++a) {
          r[a] = x(c, el[a]) - x0[c];
          f[a] = q(c, el[a]);
        }
        mesh::p2_monomials(r, cr);
        mesh::p2_monomials(f, cf);
        for (int m = 0; m < 6; ++m) {
          C[m][c] = cr[m];
          D[m][c] = cf[m];
        }
      }
      const PointTable& tb = duffy_[l];
      const double *pxi = tb.xi.data(), *peta = tb.eta.data(), *wt = tb.w.data();
      double sx = 0.0, sy = 0.0, sz = 0.0;
#pragma omp simd reduction(+ : sx, sy, sz)
      for (int p = 0; p < tb.count; ++p) {
        const double xi = pxi[p], eta = peta[p];
        double d[3], t1[3], t2[3], qq[3];
        for (int c = 0; c < 3; ++c) {
          const double a = C[1][c] + xi * C[3][c] + eta * C[4][c], b = C[2][c] + eta * C[5][c];
          d[c] = C[0][c] + xi * a + eta * b;
          t1[c] = a + xi * C[3][c];
          t2[c] = b + xi * C[4][c] + eta * C[5][c];
          qq[c] = D[0][c] + xi * (D[1][c] + xi * D[3][c] + eta * D[4][c]) + eta * (D[2][c] + eta * D[5][c]);
        }
        const double nx = t1[1] * t2[2] - t1[2] * t2[1], ny = t1[2] * t2[0] - t1[0] * t2[2],
                     nz = t1[0] * t2[1] - t1[1] * t2[0];
        const double nn = nx * nx + ny * ny + nz * nz;
        // r = x0 − x = −d; Duffy points are interior, so r ≠ 0 on a non-degenerate element. One inverse
        // square root gives both factors: with a = (|t1 × t2|² r²)^(−1/2), the weight times 1/|r| is
        // w |t1 × t2| / |r| = w nn a, and 1/r² = nn a².
        const double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        const double a = kernel::rsqrt_arith(nn * r2), na = nn * a;
        kernel::add_stokeslet_scaled(-d[0], -d[1], -d[2], qq[0], qq[1], qq[2], na * a, wt[p] * na, sx, sy, sz);
      }
      acc[0] += sx;
      acc[1] += sy;
      acc[2] += sz;
    }
    ux_[it] = acc[0];
    uy_[it] = acc[1];
    uz_[it] = acc[2];
  }
}

void SingleLayer::near_correction(Eigen::Matrix3Xd& u) {
  const int nt = static_cast<int>(target_ids_.size());
  const int nr = static_cast<int>(near_rule_.size());
  const kernel::Sources np = near_points_.sources();
#pragma omp parallel for schedule(dynamic, 16)
  for (int it = 0; it < nt; ++it) {
    const int i = target_ids_[it];
    const double x0[3] = {tx_[it], ty_[it], tz_[it]};
    double acc[3] = {ux_[it], uy_[it], uz_[it]};
    // Near-singular neighbours: subdivided rule in, regular rule out (negative weights), one block each.
    if (nr > 0)
      kernel::sum_blocks(x0, np, near_begin_.data() + near_.offsets[i], near_.offsets[i + 1] - near_.offsets[i], nr,
                         acc);
    u(0, i) += acc[0];
    u(1, i) += acc[1];
    u(2, i) += acc[2];
  }
}

void SingleLayer::mirror(Eigen::Matrix3Xd& u) const {
  // In mixed precision a node on the plane x3 = 0 gets u3 ≈ 1e-7 |u| instead of 0: its mirror-image sources
  // are summed in float at different places of the sum and no longer cancel to round-off. Left alone, that
  // moves such nodes off the plane by more than symmetry_tol within a few steps, and every later evaluation
  // loses the symmetry (twice the targets: measured 1.06× instead of 1.7× on a level-3 case). The symmetry
  // says u3 = 0 there exactly; in double the same u3 is round-off and left as it is (bit for bit unchanged).
  expand_mirror(topo_, target_ids_, uses_mixed_precision(), u);
}

void SingleLayer::apply(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, Eigen::Matrix3Xd& u) {
  if (x.cols() != topo_.num_nodes || q.cols() != topo_.num_nodes)
    throw std::invalid_argument("stokes: x and q must have " + std::to_string(topo_.num_nodes) + " columns (got " +
                                std::to_string(x.cols()) + " and " + std::to_string(q.cols()) + ")");
  const double t0 = now_s();
  bool sym = false;
  if (opt_.symmetry != Symmetry::Off) {
    sym = is_symmetric(x, q);
    if (!sym && opt_.symmetry == Symmetry::On)
      throw std::invalid_argument("stokes: symmetry forced on but the scene is not symmetric under x3 -> -x3");
  }
  const bool central = opt_.central_symmetry && opt_.symmetry != Symmetry::Off && is_centrally_symmetric(x, q);
  // 1. Layout: with the far-field tier the all-pairs sum runs over the coarse rule, else the regular rule.
  const bool far = opt_.far_degree > 0;
  layout_points(far ? coarse_ : regular_, topo_.elements, x, q, kernel::simd_width(), sources_);
  if (!near_rule_.empty()) layout_points(near_rule_, topo_.elements, x, q, 1, near_points_);
  regular_points_ = &sources_;
  regular_stride_ = rule_size_;
  regular_slot_ = nullptr;
  const double t1 = now_s();
  // 2. Regular part, for the targets of this call.
  select_targets(x, sym, central);
  regular_sum(sources_.sources(), u);
  const double t2 = now_s();
  // 3. Far-field tier.
  const long long mids = far ? far_field(x, q, u) : 0;
  const double t2f = now_s();
  // 4. Singular and near-singular corrections.
  singular_correction(x, q);
  const double t3 = now_s();
  near_correction(u);
  // 5. Symmetries: u at the nodes not evaluated.
  if (central)
    expand_central(topo_, target_ids_, sym, u);
  else if (sym)
    mirror(u);
  const double t4 = now_s();

  stats_.used_symmetry = sym;
  stats_.used_central = central;
  stats_.targets = static_cast<int>(target_ids_.size());
  stats_.sources = num_elements() * static_cast<int>(far ? coarse_.size() : regular_.size());
  stats_.mid_elements = mids;
  stats_.build_s = t1 - t0;
  stats_.regular_s = t2 - t1;
  stats_.far_s = far ? t2f - t2 : 0.0;
  stats_.singular_s = t3 - t2f;
  stats_.near_s = t4 - t3;
  stats_.total_s = t4 - t0;
}

Eigen::Matrix3Xd SingleLayer::apply(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q) {
  Eigen::Matrix3Xd u;
  apply(x, q, u);
  return u;
}

}  // namespace capsim::stokes

#include "solver/stokes/single_layer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include <omp.h>

#include "solver/mesh/p2_element.h"
#include "solver/quadrature/triangle_rule.h"

namespace capsim::stokes {
namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Reference coordinates of the 6 local nodes.
constexpr double kRefNode[6][2] = {{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}, {0.5, 0.0}, {0.5, 0.5}, {0.0, 0.5}};

// Sub-triangles of the Duffy map for each local node, as (A, B) in reference coordinates: the triangle
// (P, A, B) with P the node at the apex. A vertex has one (the element itself). A mid-side node has the two
// halves through the opposite vertex, each split again at the midpoint of its far edge: on a near-equilateral
// element the two halves have a right angle at the apex, and the collapsed-square rule converges much faster
// on the 45° quarters (measured: 3e-6 → 2e-9 at order 10 on a curved element).
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

SingleLayer::SingleLayer(const mesh::SurfaceMesh& mesh, const SingleLayerOptions& options) : opt_(options) {
  // Degrees 1 and 2 exist only as far-field rules: the regular and near rules must stay accurate near targets.
  if (opt_.regular_degree < 4 || opt_.near_degree < 4)
    throw std::invalid_argument("stokes: regular_degree and near_degree must be 4, 5 or 6");
  const auto& rule = quadrature::triangle_rule(opt_.regular_degree);  // throws for a bad degree
  if (opt_.far_degree < 0 || opt_.far_degree > 2)
    throw std::invalid_argument("stokes: far_degree must be 0 (off), 1 or 2, got " + std::to_string(opt_.far_degree));
  // far_radius ≤ 1 would call elements far from their own nodes' neighbourhood (|x0 − c_e| ≤ ρ_e for a node
  // of e); the own elements are always treated as mid anyway, but such a radius is surely a mistake.
  if (!(opt_.far_radius > 1.0) || !std::isfinite(opt_.far_radius))
    throw std::invalid_argument("stokes: far_radius must be a finite number > 1");
  if (opt_.duffy_order < 1)
    throw std::invalid_argument("stokes: duffy_order must be >= 1, got " + std::to_string(opt_.duffy_order));
  if (!(opt_.symmetry_tol >= 0.0)) throw std::invalid_argument("stokes: symmetry_tol must be >= 0");
  if (opt_.near_subdivision < 0 || opt_.near_subdivision > 4)
    throw std::invalid_argument("stokes: near_subdivision must be 0..4, got " +
                                std::to_string(opt_.near_subdivision));
  const auto& near_rule = quadrature::triangle_rule(opt_.near_degree);

  num_nodes_ = mesh.num_nodes();
  elements_ = mesh.elements;
  for (const auto& el : elements_)
    for (int a : el)
      if (a < 0 || a >= num_nodes_) throw std::invalid_argument("stokes: element refers to a missing node");
  if (static_cast<int>(mesh.node_element_offsets.size()) != num_nodes_ + 1)
    throw std::invalid_argument("stokes: mesh node→element offsets have the wrong size");

  // Node → (element, local index) incidences.
  node_offsets_ = mesh.node_element_offsets;
  inc_element_.resize(mesh.node_elements.size());
  inc_local_.resize(mesh.node_elements.size());
  for (int i = 0; i < num_nodes_; ++i) {
    for (int k = node_offsets_[i]; k < node_offsets_[i + 1]; ++k) {
      const int e = mesh.node_elements[k];
      const auto& el = elements_.at(e);
      const auto it = std::find(el.begin(), el.end(), i);
      if (it == el.end()) throw std::invalid_argument("stokes: node→element list inconsistent with elements");
      inc_element_[k] = e;
      inc_local_[k] = static_cast<int>(it - el.begin());
    }
  }
  if (static_cast<int>(mesh.mirror_node.size()) == num_nodes_) mirror_ = mesh.mirror_node;

  auto shape_at = [](double xi, double eta, double w) {
    ShapeAt s{};
    s.w = w;
    const auto n = mesh::p2_shape(xi, eta);
    const auto g = mesh::p2_shape_gradients(xi, eta);
    for (int a = 0; a < 6; ++a) {
      s.n[a] = n[a];
      s.dxi[a] = g[0][a];
      s.deta[a] = g[1][a];
    }
    return s;
  };

  // Regular rule: ∫_T f dξdη = ½ Σ w f.
  rule_size_ = rule.size();
  for (int k = 0; k < rule.size(); ++k)
    regular_.push_back(shape_at(rule.points[k][1], rule.points[k][2], 0.5 * rule.weights[k]));

  // Duffy points: apex P, opposite edge A→B; (s, t) ∈ [0,1]² ↦ P + s (A − P) + s t (B − A), Jacobian
  // s |det(A − P, B − P)|.
  const auto gl = quadrature::gauss_legendre(opt_.duffy_order);
  for (int l = 0; l < 6; ++l) {
    const double px = kRefNode[l][0], py = kRefNode[l][1];
    for (const auto& st : sub_triangles(l)) {
      const double ax = st.ax - px, ay = st.ay - py;
      const double bx = st.bx - px, by = st.by - py;
      const double det = std::abs(ax * by - ay * bx);
      for (int i = 0; i < opt_.duffy_order; ++i) {
        const double s = gl.nodes[i];
        for (int j = 0; j < opt_.duffy_order; ++j) {
          const double t = gl.nodes[j];
          const double xi = px + s * (ax + t * (bx - ax)), eta = py + s * (ay + t * (by - ay));
          duffy_[l].push_back(shape_at(xi, eta, gl.weights[i] * gl.weights[j] * s * det));
        }
      }
    }
  }

  for (int l = 0; l < 6; ++l) {
    ShapeTable& t = duffy_soa_[l];
    t.count = static_cast<int>(duffy_[l].size());
    for (int a = 0; a < 6; ++a)
      for (const ShapeAt& sa : duffy_[l]) {
        t.n[a].push_back(sa.n[a]);
        t.dxi[a].push_back(sa.dxi[a]);
        t.deta[a].push_back(sa.deta[a]);
      }
    for (const ShapeAt& sa : duffy_[l]) t.w.push_back(sa.w);
  }

  if (opt_.far_degree > 0) {
    // Coarse rule for the all-pairs sum, and the per-element block that upgrades it to the regular rule:
    // the regular points, then the coarse points with negated weights (one contiguous add_block per element).
    const auto& far_rule = quadrature::triangle_rule(opt_.far_degree);
    for (int k = 0; k < far_rule.size(); ++k)
      coarse_.push_back(shape_at(far_rule.points[k][1], far_rule.points[k][2], 0.5 * far_rule.weights[k]));
    mid_rule_ = regular_;
    for (const ShapeAt& c : coarse_) {
      mid_rule_.push_back(c);
      mid_rule_.back().w = -c.w;
    }
  }

  if (opt_.near_subdivision > 0) {
    // Sub-triangles of the reference triangle (regular 4-split, near_subdivision times), the rule on each.
    using Tri = std::array<std::array<double, 2>, 3>;
    std::vector<Tri> tris = {Tri{{{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}}}};
    for (int k = 0; k < opt_.near_subdivision; ++k) {
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
    for (const Tri& t : tris) {
      const double ax = t[1][0] - t[0][0], ay = t[1][1] - t[0][1], bx = t[2][0] - t[0][0], by = t[2][1] - t[0][1];
      const double det = std::abs(ax * by - ay * bx);
      for (int k = 0; k < near_rule.size(); ++k) {
        const double u = near_rule.points[k][1], v = near_rule.points[k][2];
        near_rule_.push_back(
            shape_at(t[0][0] + u * ax + v * bx, t[0][1] + u * ay + v * by, 0.5 * near_rule.weights[k] * det));
      }
    }
    // The regular rule with negative weights: one contiguous block per element both removes the regular
    // contribution and adds the subdivided one.
    for (const ShapeAt& r : regular_) {
      near_rule_.push_back(r);
      near_rule_.back().w = -r.w;
    }
    // Near-singular neighbours: elements sharing a vertex with an element that contains the node.
    near_offsets_.assign(1, 0);
    std::vector<int> own, cand;
    for (int i = 0; i < num_nodes_; ++i) {
      own.assign(mesh.node_elements.begin() + node_offsets_[i], mesh.node_elements.begin() + node_offsets_[i + 1]);
      std::sort(own.begin(), own.end());
      cand.clear();
      for (int e : own)
        for (int a = 0; a < 3; ++a) {
          const int v = elements_[e][a];
          for (int k = node_offsets_[v]; k < node_offsets_[v + 1]; ++k) cand.push_back(mesh.node_elements[k]);
        }
      std::sort(cand.begin(), cand.end());
      cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
      for (int e : cand)
        if (!std::binary_search(own.begin(), own.end(), e)) near_elements_.push_back(e);
      near_offsets_.push_back(static_cast<int>(near_elements_.size()));
    }
  }
}

bool SingleLayer::is_symmetric(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q) const {
  if (mirror_.empty() || x.cols() != num_nodes_ || q.cols() != num_nodes_) return false;
  const double lx = (x.rowwise().maxCoeff() - x.rowwise().minCoeff()).norm();
  const double lq = q.colwise().norm().maxCoeff();
  const double tx = opt_.symmetry_tol * lx, tq = opt_.symmetry_tol * lq;
  for (int i = 0; i < num_nodes_; ++i) {
    const int m = mirror_[i];
    const double ex = std::abs(x(0, m) - x(0, i)) + std::abs(x(1, m) - x(1, i)) + std::abs(x(2, m) + x(2, i));
    const double eq = std::abs(q(0, m) - q(0, i)) + std::abs(q(1, m) - q(1, i)) + std::abs(q(2, m) + q(2, i));
    if (!(ex <= tx) || !(eq <= tq)) return false;  // also false for NaN
  }
  return true;
}

void SingleLayer::layout(const std::vector<ShapeAt>& rule, const std::vector<std::array<int, 6>>& elements,
                         const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, AlignedVector& px, AlignedVector& py,
                         AlignedVector& pz, AlignedVector& pqx, AlignedVector& pqy, AlignedVector& pqz, int width) {
  const int ne = static_cast<int>(elements.size()), nq = static_cast<int>(rule.size());
  const int n = ne * nq;
  const int npad = (n + width - 1) / width * width;
  for (auto* v : {&px, &py, &pz, &pqx, &pqy, &pqz}) v->assign(static_cast<std::size_t>(npad), 0.0);
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
      const ShapeAt& s = rule[k];
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

kernel::Sources SingleLayer::build_sources(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q) {
  return layout_sources(regular_, x, q);
}

kernel::Sources SingleLayer::layout_sources(const std::vector<ShapeAt>& rule, const Eigen::Matrix3Xd& x,
                                            const Eigen::Matrix3Xd& q) {
  layout(rule, elements_, x, q, sx_, sy_, sz_, sqx_, sqy_, sqz_, kernel::simd_width());
  return {sx_.data(), sy_.data(), sz_.data(), sqx_.data(), sqy_.data(), sqz_.data(), static_cast<int>(sx_.size())};
}

namespace {
// acc += sign · Σ_{p ∈ [begin, end)} J(x0, x_p)·wq_p (short contiguous blocks; vectorised over p).
inline void add_block(const double x0[3], const double* px, const double* py, const double* pz, const double* qx,
                      const double* qy, const double* qz, int begin, int end, double sign, double acc[3]) {
  double ax = 0.0, ay = 0.0, az = 0.0;
#pragma omp simd reduction(+ : ax, ay, az)
  for (int p = begin; p < end; ++p) {
    const double dx = x0[0] - px[p], dy = x0[1] - py[p], dz = x0[2] - pz[p];
    const double r2 = dx * dx + dy * dy + dz * dz;
    const double inv = r2 == 0.0 ? 0.0 : kernel::rsqrt_arith(r2);
    const double sc = (dx * qx[p] + dy * qy[p] + dz * qz[p]) * inv * inv * inv;
    ax += qx[p] * inv + dx * sc;
    ay += qy[p] * inv + dy * sc;
    az += qz[p] * inv + dz * sc;
  }
  acc[0] += sign * ax;
  acc[1] += sign * ay;
  acc[2] += sign * az;
}
}  // namespace

void SingleLayer::build_centroid_grid(const Eigen::Matrix3Xd& x) {
  const int ne = num_elements();
  for (auto* v : {&cx_, &cy_, &cz_, &rho_}) v->resize(static_cast<std::size_t>(ne));
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, rmax = 0.0;
  for (int e = 0; e < ne; ++e) {
    const auto& el = elements_[e];
    double c[3] = {0.0, 0.0, 0.0};
    for (int a = 0; a < 6; ++a)
      for (int k = 0; k < 3; ++k) c[k] += x(k, el[a]);
    for (double& ck : c) ck /= 6.0;
    double r2 = 0.0;
    for (int a = 0; a < 6; ++a) {
      const double dx = x(0, el[a]) - c[0], dy = x(1, el[a]) - c[1], dz = x(2, el[a]) - c[2];
      r2 = std::max(r2, dx * dx + dy * dy + dz * dz);
    }
    cx_[e] = c[0];
    cy_[e] = c[1];
    cz_[e] = c[2];
    rho_[e] = std::sqrt(r2);
    rmax = std::max(rmax, rho_[e]);
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], c[k]);
      hi[k] = std::max(hi[k], c[k]);
    }
  }
  // Every mid element of a target has its centroid within far_reach_ of it; cells of half that size make
  // the search box (at most 5 cells per direction) hug the ball more tightly than 3 cells of the full size
  // (fewer candidates to test). The cell count is capped near 2 N (enlarging the cells) so a thin or very
  // fine surface cannot blow up the grid.
  far_reach_ = opt_.far_radius * rmax;
  double ext = 0.0;
  for (int k = 0; k < 3; ++k) ext = std::max(ext, hi[k] - lo[k]);
  double cell = far_reach_ > 0.0 ? 0.5 * far_reach_ : ext + 1.0;
  if (!(cell > 0.0) || !std::isfinite(cell)) cell = 1.0;  // NaN positions: any grid; NaN then propagates
  auto cells = [&](double h) {
    long long n = 1;
    for (int k = 0; k < 3; ++k) {
      const double span = hi[k] - lo[k];
      grid_dim_[k] = std::isfinite(span) ? static_cast<int>(std::min(span / h, 1e6)) + 1 : 1;
      n *= grid_dim_[k];
    }
    return n;
  };
  while (cells(cell) > 2LL * ne + 8) cell *= 1.25;
  grid_cell_ = cell;
  for (int k = 0; k < 3; ++k) grid_lo_[k] = std::isfinite(lo[k]) ? lo[k] : 0.0;
  const int ncell = grid_dim_[0] * grid_dim_[1] * grid_dim_[2];
  auto index = [&](double p, int k) {
    const double f = std::floor((p - grid_lo_[k]) / grid_cell_);
    return f >= 0.0 ? static_cast<int>(std::min(f, static_cast<double>(grid_dim_[k] - 1))) : 0;  // NaN → 0
  };
  // Counting sort of the elements by cell: slot j (cell order) holds element cell_elements_[j].
  cell_offsets_.assign(static_cast<std::size_t>(ncell) + 1, 0);
  cell_elements_.resize(static_cast<std::size_t>(ne));
  cell_cursor_.resize(static_cast<std::size_t>(ne));
  for (int e = 0; e < ne; ++e) {
    const int id = (index(cz_[e], 2) * grid_dim_[1] + index(cy_[e], 1)) * grid_dim_[0] + index(cx_[e], 0);
    cell_cursor_[e] = id;
    ++cell_offsets_[id + 1];
  }
  for (int c = 0; c < ncell; ++c) cell_offsets_[c + 1] += cell_offsets_[c];
  cell_fill_.assign(cell_offsets_.begin(), cell_offsets_.end() - 1);
  for (int e = 0; e < ne; ++e) cell_elements_[cell_fill_[cell_cursor_[e]]++] = e;
  // Everything the per-target search touches is stored in slot order: a target's candidates are one
  // contiguous range per row of cells, and its mid blocks merge into a few contiguous loops (no gathers).
  slot_.resize(static_cast<std::size_t>(ne));
  sorted_elements_.resize(static_cast<std::size_t>(ne));
  for (auto* v : {&scx_, &scy_, &scz_, &sreach2_}) v->resize(static_cast<std::size_t>(ne));
  for (int j = 0; j < ne; ++j) {
    const int e = cell_elements_[j];
    slot_[e] = j;
    sorted_elements_[j] = elements_[e];
    scx_[j] = cx_[e];
    scy_[j] = cy_[e];
    scz_[j] = cz_[e];
    sreach2_[j] = opt_.far_radius * opt_.far_radius * rho_[e] * rho_[e];
  }
}

long long SingleLayer::mid_correction(const std::vector<int>& targets, const Eigen::Matrix3Xd& x,
                                      Eigen::Matrix3Xd& u) {
  const int nt = static_cast<int>(targets.size()), ne = num_elements();
  const int nm = static_cast<int>(mid_rule_.size());
  // Per-thread scratch, sized for the worst case so the target loop never allocates: stamps (mark[j] == i:
  // slot j is already listed for target i; targets are distinct, so no reset is needed within a call, stale
  // stamps of the last call are cleared here) and the mid slots of the current target.
  const int nthreads = std::max(1, omp_get_max_threads());
  if (static_cast<int>(mark_.size()) < nthreads) mark_.resize(static_cast<std::size_t>(nthreads));
  if (static_cast<int>(slots_.size()) < nthreads) slots_.resize(static_cast<std::size_t>(nthreads));
  for (auto& m : mark_) m.assign(static_cast<std::size_t>(ne), -1);
  for (auto& c : slots_) c.resize(static_cast<std::size_t>(ne) + 1);
  const double *mx = mx_.data(), *my = my_.data(), *mz = mz_.data(), *mqx = mqx_.data(), *mqy = mqy_.data(),
               *mqz = mqz_.data();
  const double *cx = scx_.data(), *cy = scy_.data(), *cz = scz_.data(), *reach2 = sreach2_.data();
  const int* slot = slot_.data();
  long long total = 0;
#pragma omp parallel reduction(+ : total)
  {
    const int thread = omp_get_thread_num();
    int* mark = mark_[static_cast<std::size_t>(thread)].data();
    int* mid = slots_[static_cast<std::size_t>(thread)].data();
#pragma omp for schedule(dynamic, 16)
    for (int it = 0; it < nt; ++it) {
      const int i = targets[it];
      const double x0[3] = {x(0, i), x(1, i), x(2, i)};
      // Collect the mid slots first, then sum their blocks: one add_block per element costs a horizontal
      // reduction and a masked remainder each (measured ~10× slower per interaction than the all-pairs
      // kernel); consecutive slots are merged into one contiguous loop (~5% fewer cycles than gathering).
      int nc = 0;
      auto always = [&](int j) {  // j: slot of the element
        if (mark[j] == i) return;
        mark[j] = i;
        mid[nc++] = j;
      };
      // The own elements and near-singular neighbours first: the corrections after this step remove
      // exactly the regular rule from them, whatever their distance.
      for (int k = node_offsets_[i]; k < node_offsets_[i + 1]; ++k) always(slot[inc_element_[k]]);
      if (!near_offsets_.empty())
        for (int k = near_offsets_[i]; k < near_offsets_[i + 1]; ++k) always(slot[near_elements_[k]]);
      int lo[3], hi[3];
      for (int k = 0; k < 3; ++k) {
        const double a = std::floor((x0[k] - far_reach_ - grid_lo_[k]) / grid_cell_);
        const double b = std::floor((x0[k] + far_reach_ - grid_lo_[k]) / grid_cell_);
        lo[k] = a > 0.0 ? static_cast<int>(std::min(a, grid_dim_[k] - 1.0)) : 0;
        hi[k] = b > 0.0 ? static_cast<int>(std::min(b, grid_dim_[k] - 1.0)) : 0;
      }
      for (int iz = lo[2]; iz <= hi[2]; ++iz)
        for (int iy = lo[1]; iy <= hi[1]; ++iy) {
          const int row = (iz * grid_dim_[1] + iy) * grid_dim_[0];
          // Branch-free append (the mid/far outcome is unpredictable); the cells are disjoint, so only the
          // slots listed above can come twice. mid has room for one write past the last element.
          for (int j = cell_offsets_[row + lo[0]]; j < cell_offsets_[row + hi[0] + 1]; ++j) {
            const double dx = x0[0] - cx[j], dy = x0[1] - cy[j], dz = x0[2] - cz[j];
            mid[nc] = j;
            nc += static_cast<int>(dx * dx + dy * dy + dz * dz <= reach2[j]) & static_cast<int>(mark[j] != i);
          }
        }
      total += nc;
      std::sort(mid, mid + nc);
      double acc[3] = {0.0, 0.0, 0.0};
      for (int c = 0; c < nc;) {  // runs of consecutive mid elements are one contiguous block
        int d = c + 1;
        while (d < nc && mid[d] == mid[d - 1] + 1) ++d;
        add_block(x0, mx, my, mz, mqx, mqy, mqz, mid[c] * nm, (mid[d - 1] + 1) * nm, 1.0, acc);
        c = d;
      }
      u(0, i) += acc[0];
      u(1, i) += acc[1];
      u(2, i) += acc[2];
    }
  }
  return total;
}

void SingleLayer::singular_correction(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q,
                                      const std::vector<int>& targets, const double* const reg[6], int stride,
                                      const int* slot, Eigen::Matrix3Xd& u) const {
  const int nt = static_cast<int>(targets.size()), nq = rule_size_;
  const int nr = static_cast<int>(near_rule_.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (int it = 0; it < nt; ++it) {
    const int i = targets[it];
    const double x0[3] = {x(0, i), x(1, i), x(2, i)};
    double acc[3] = {0.0, 0.0, 0.0};
    for (int k = node_offsets_[i]; k < node_offsets_[i + 1]; ++k) {
      const int e = inc_element_[k], l = inc_local_[k];
      const auto& el = elements_[e];
      // Remove what the regular rule counted for this element ...
      const int b = (slot != nullptr ? slot[e] : e) * stride;
      add_block(x0, reg[0], reg[1], reg[2], reg[3], reg[4], reg[5], b, b + nq, -1.0, acc);
      // ... and add the Duffy integral with the node at the apex. Positions relative to x0 (Σ N_a = 1)
      // avoid cancellation near the apex.
      double R[6][3], Q[6][3];
      for (int a = 0; a < 6; ++a)
        for (int c = 0; c < 3; ++c) {
          R[a][c] = x(c, el[a]) - x0[c];
          Q[a][c] = q(c, el[a]);
        }
      const ShapeTable& tb = duffy_soa_[l];
      const double *n0 = tb.n[0].data(), *n1 = tb.n[1].data(), *n2 = tb.n[2].data(), *n3 = tb.n[3].data(),
                   *n4 = tb.n[4].data(), *n5 = tb.n[5].data();
      const double *a0 = tb.dxi[0].data(), *a1 = tb.dxi[1].data(), *a2 = tb.dxi[2].data(), *a3 = tb.dxi[3].data(),
                   *a4 = tb.dxi[4].data(), *a5 = tb.dxi[5].data();
      const double *b0 = tb.deta[0].data(), *b1 = tb.deta[1].data(), *b2 = tb.deta[2].data(),
                   *b3 = tb.deta[3].data(), *b4 = tb.deta[4].data(), *b5 = tb.deta[5].data();
      const double* wt = tb.w.data();
      double sx = 0.0, sy = 0.0, sz = 0.0;
#pragma omp simd reduction(+ : sx, sy, sz)
      for (int p = 0; p < tb.count; ++p) {
        double d[3], t1[3], t2[3], qq[3];
        for (int c = 0; c < 3; ++c) {
          d[c] = n0[p] * R[0][c] + n1[p] * R[1][c] + n2[p] * R[2][c] + n3[p] * R[3][c] + n4[p] * R[4][c] +
                 n5[p] * R[5][c];
          t1[c] = a0[p] * R[0][c] + a1[p] * R[1][c] + a2[p] * R[2][c] + a3[p] * R[3][c] + a4[p] * R[4][c] +
                  a5[p] * R[5][c];
          t2[c] = b0[p] * R[0][c] + b1[p] * R[1][c] + b2[p] * R[2][c] + b3[p] * R[3][c] + b4[p] * R[4][c] +
                  b5[p] * R[5][c];
          qq[c] = n0[p] * Q[0][c] + n1[p] * Q[1][c] + n2[p] * Q[2][c] + n3[p] * Q[3][c] + n4[p] * Q[4][c] +
                  n5[p] * Q[5][c];
        }
        const double nx = t1[1] * t2[2] - t1[2] * t2[1], ny = t1[2] * t2[0] - t1[0] * t2[2],
                     nz = t1[0] * t2[1] - t1[1] * t2[0];
        const double nn = nx * nx + ny * ny + nz * nz;
        const double wj = wt[p] * nn * kernel::rsqrt_arith(nn);  // w |t1 × t2|
        // r = x0 − x = −d; Duffy points are interior, so r ≠ 0 on a non-degenerate element.
        const double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        const double inv = kernel::rsqrt_arith(r2);
        const double rq = -(d[0] * qq[0] + d[1] * qq[1] + d[2] * qq[2]);
        const double sc = rq * inv * inv;
        sx += wj * inv * (qq[0] - d[0] * sc);
        sy += wj * inv * (qq[1] - d[1] * sc);
        sz += wj * inv * (qq[2] - d[2] * sc);
      }
      acc[0] += sx;
      acc[1] += sy;
      acc[2] += sz;
    }
    // Near-singular neighbours: subdivided rule in, regular rule out (negative weights), one block each.
    if (nr > 0) {
      for (int k = near_offsets_[i]; k < near_offsets_[i + 1]; ++k) {
        const int e = near_elements_[k];
        add_block(x0, nx_.data(), ny_.data(), nz_.data(), nqx_.data(), nqy_.data(), nqz_.data(), e * nr,
                  (e + 1) * nr, 1.0, acc);
      }
    }
    u(0, i) += acc[0];
    u(1, i) += acc[1];
    u(2, i) += acc[2];
  }
}

void SingleLayer::apply(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q, Eigen::Matrix3Xd& u) {
  if (x.cols() != num_nodes_ || q.cols() != num_nodes_)
    throw std::invalid_argument("stokes: x and q must have " + std::to_string(num_nodes_) + " columns (got " +
                                std::to_string(x.cols()) + " and " + std::to_string(q.cols()) + ")");
  const double t0 = now_s();
  bool sym = false;
  if (opt_.symmetry != Symmetry::Off) {
    sym = is_symmetric(x, q);
    if (!sym && opt_.symmetry == Symmetry::On)
      throw std::invalid_argument("stokes: symmetry forced on but the scene is not symmetric under x3 -> -x3");
  }

  // With the far-field tier the all-pairs sum runs over the coarse rule; without it, over the regular rule.
  const bool far = opt_.far_degree > 0;
  const kernel::Sources src = layout_sources(far ? coarse_ : regular_, x, q);
  const double t1 = now_s();

  // Targets: all nodes, or one of each mirror pair (the one with the larger x3; a node on the plane is its
  // own image and is evaluated).
  target_ids_.clear();
  for (int i = 0; i < num_nodes_; ++i) {
    if (sym) {
      const int m = mirror_[i];
      const bool mine = m == i || x(2, i) > x(2, m) || (x(2, i) == x(2, m) && i < m);
      if (!mine) continue;
    }
    target_ids_.push_back(i);
  }
  const int nt = static_cast<int>(target_ids_.size());
  for (auto* v : {&tx_, &ty_, &tz_, &ux_, &uy_, &uz_}) v->resize(static_cast<std::size_t>(nt));
  for (int k = 0; k < nt; ++k) {
    tx_[k] = x(0, target_ids_[k]);
    ty_[k] = x(1, target_ids_[k]);
    tz_[k] = x(2, target_ids_[k]);
  }
  const kernel::Targets tg{tx_.data(), ty_.data(), tz_.data(), nt};
  const kernel::Result res{ux_.data(), uy_.data(), uz_.data()};
  if (opt_.kernel == KernelChoice::Fast)
    kernel::sum_fast(tg, src, res, opt_.fast);
  else
    kernel::sum_plain(tg, src, res);
  const double t2 = now_s();

  u.resize(3, num_nodes_);
  for (int k = 0; k < nt; ++k) {
    u(0, target_ids_[k]) = ux_[k];
    u(1, target_ids_[k]) = uy_[k];
    u(2, target_ids_[k]) = uz_[k];
  }
  // Far-field tier: mid elements (and the own/near ones) upgraded from the coarse to the regular rule. The
  // singular correction then finds the regular points of each element in the mid layout (first nq of each
  // block) instead of the all-pairs sources.
  long long mids = 0;
  const double* reg[6] = {sx_.data(), sy_.data(), sz_.data(), sqx_.data(), sqy_.data(), sqz_.data()};
  int stride = rule_size_;
  const int* slot = nullptr;
  if (far) {
    build_centroid_grid(x);
    layout(mid_rule_, sorted_elements_, x, q, mx_, my_, mz_, mqx_, mqy_, mqz_, 1);
    slot = slot_.data();
    mids = mid_correction(target_ids_, x, u);
    const double* m[6] = {mx_.data(), my_.data(), mz_.data(), mqx_.data(), mqy_.data(), mqz_.data()};
    std::copy(m, m + 6, reg);
    stride = static_cast<int>(mid_rule_.size());
  }
  const double t2f = now_s();
  if (!near_rule_.empty()) layout(near_rule_, elements_, x, q, nx_, ny_, nz_, nqx_, nqy_, nqz_, 1);
  singular_correction(x, q, target_ids_, reg, stride, slot, u);
  if (sym) {
    for (int k = 0; k < nt; ++k) {
      const int i = target_ids_[k], m = mirror_[i];
      if (m == i) continue;
      u(0, m) = u(0, i);
      u(1, m) = u(1, i);
      u(2, m) = -u(2, i);
    }
  }
  const double t3 = now_s();

  stats_.used_symmetry = sym;
  stats_.targets = nt;
  stats_.sources = num_elements() * static_cast<int>(far ? coarse_.size() : regular_.size());
  stats_.mid_elements = mids;
  stats_.build_s = t1 - t0;
  stats_.regular_s = t2 - t1;
  stats_.far_s = far ? t2f - t2 : 0.0;
  stats_.singular_s = far ? t3 - t2f : t3 - t2;
  stats_.total_s = t3 - t0;
}

Eigen::Matrix3Xd SingleLayer::apply(const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& q) {
  Eigen::Matrix3Xd u;
  apply(x, q, u);
  return u;
}

}  // namespace capsim::stokes

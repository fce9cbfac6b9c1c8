#include "solver/stokes/far_field.h"

#include <algorithm>
#include <cmath>

#include <omp.h>

namespace capsim::stokes {

void FarFieldGrid::build(const Eigen::Matrix3Xd& x, const std::vector<std::array<int, 6>>& elements,
                         double far_radius) {
  const int ne = static_cast<int>(elements.size());
  for (auto* v : {&cx, &cy, &cz, &rho}) v->resize(static_cast<std::size_t>(ne));
  double lo_[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, rmax = 0.0;
  for (int e = 0; e < ne; ++e) {
    const auto& el = elements[e];
    double c[3] = {0.0, 0.0, 0.0};
    for (int a = 0; a < 6; ++a)
      for (int k = 0; k < 3; ++k) c[k] += x(k, el[a]);
    for (double& ck : c) ck /= 6.0;
    double r2 = 0.0;
    for (int a = 0; a < 6; ++a) {
      const double dx = x(0, el[a]) - c[0], dy = x(1, el[a]) - c[1], dz = x(2, el[a]) - c[2];
      r2 = std::max(r2, dx * dx + dy * dy + dz * dz);
    }
    cx[e] = c[0];
    cy[e] = c[1];
    cz[e] = c[2];
    rho[e] = std::sqrt(r2);
    rmax = std::max(rmax, rho[e]);
    for (int k = 0; k < 3; ++k) {
      lo_[k] = std::min(lo_[k], c[k]);
      hi[k] = std::max(hi[k], c[k]);
    }
  }
  // Every mid element of a target has its centroid within `reach` of it; cells of half that size make the
  // search box (at most 5 cells per direction) hug the ball more tightly than 3 cells of the full size
  // (fewer candidates to test). The cell count is capped near 2 N (enlarging the cells) so a thin or very
  // fine surface cannot blow up the grid.
  reach = far_radius * rmax;
  double ext = 0.0;
  for (int k = 0; k < 3; ++k) ext = std::max(ext, hi[k] - lo_[k]);
  double h = reach > 0.0 ? 0.5 * reach : ext + 1.0;
  if (!(h > 0.0) || !std::isfinite(h)) h = 1.0;  // NaN positions: any grid; NaN then propagates
  auto cells = [&](double size) {
    long long n = 1;
    for (int k = 0; k < 3; ++k) {
      const double span = hi[k] - lo_[k];
      dim[k] = std::isfinite(span) ? static_cast<int>(std::min(span / size, 1e6)) + 1 : 1;
      n *= dim[k];
    }
    return n;
  };
  while (cells(h) > 2LL * ne + 8) h *= 1.25;
  cell = h;
  for (int k = 0; k < 3; ++k) lo[k] = std::isfinite(lo_[k]) ? lo_[k] : 0.0;
  const int ncell = dim[0] * dim[1] * dim[2];
  auto index = [&](double p, int k) {
    const double f = std::floor((p - lo[k]) / cell);
    return f >= 0.0 ? static_cast<int>(std::min(f, static_cast<double>(dim[k] - 1))) : 0;  // NaN → 0
  };
  // Counting sort of the elements by cell: slot j (cell order) holds element cell_elements[j].
  cell_offsets.assign(static_cast<std::size_t>(ncell) + 1, 0);
  cell_elements.resize(static_cast<std::size_t>(ne));
  cursor_.resize(static_cast<std::size_t>(ne));
  for (int e = 0; e < ne; ++e) {
    const int id = (index(cz[e], 2) * dim[1] + index(cy[e], 1)) * dim[0] + index(cx[e], 0);
    cursor_[e] = id;
    ++cell_offsets[id + 1];
  }
  for (int c = 0; c < ncell; ++c) cell_offsets[c + 1] += cell_offsets[c];
  fill_.assign(cell_offsets.begin(), cell_offsets.end() - 1);
  for (int e = 0; e < ne; ++e) cell_elements[fill_[cursor_[e]]++] = e;
  // Everything the per-target search touches is stored in slot order: a target's candidates are one
  // contiguous range per row of cells, and its mid blocks merge into a few contiguous loops (no gathers).
  slot.resize(static_cast<std::size_t>(ne));
  sorted_elements.resize(static_cast<std::size_t>(ne));
  for (auto* v : {&scx, &scy, &scz, &sreach2}) v->resize(static_cast<std::size_t>(ne));
  for (int j = 0; j < ne; ++j) {
    const int e = cell_elements[j];
    slot[e] = j;
    sorted_elements[j] = elements[e];
    scx[j] = cx[e];
    scy[j] = cy[e];
    scz[j] = cz[e];
    sreach2[j] = far_radius * far_radius * rho[e] * rho[e];
  }
}

long long add_mid_blocks(const FarFieldGrid& grid, const SourceArrays& mid_points, int mid_rule_size,
                         const std::vector<int>& own_offsets, const std::vector<int>& own_elements,
                         const NearSingularElements& near, const std::vector<int>& targets,
                         const Eigen::Matrix3Xd& x, MidScratch& scratch, Eigen::Matrix3Xd& u) {
  const int nt = static_cast<int>(targets.size()), ne = static_cast<int>(grid.slot.size());
  const int nm = mid_rule_size;
  // Per-thread scratch, sized for the worst case so the target loop never allocates: stamps (mark[j] == i:
  // slot j is already listed for target i; targets are distinct, so no reset is needed within a call, stale
  // stamps of the last call are cleared here) and the mid slots of the current target.
  const int nthreads = std::max(1, omp_get_max_threads());
  if (static_cast<int>(scratch.mark.size()) < nthreads) scratch.mark.resize(static_cast<std::size_t>(nthreads));
  if (static_cast<int>(scratch.slots.size()) < nthreads) scratch.slots.resize(static_cast<std::size_t>(nthreads));
  for (auto& m : scratch.mark) m.assign(static_cast<std::size_t>(ne), -1);
  for (auto& c : scratch.slots) c.resize(static_cast<std::size_t>(ne) + 1);
  const double *mx = mid_points.x.data(), *my = mid_points.y.data(), *mz = mid_points.z.data(),
               *mqx = mid_points.qx.data(), *mqy = mid_points.qy.data(), *mqz = mid_points.qz.data();
  const double *cx = grid.scx.data(), *cy = grid.scy.data(), *cz = grid.scz.data(), *reach2 = grid.sreach2.data();
  const int* slot = grid.slot.data();
  const double reach = grid.reach, cell = grid.cell;
  const double* glo = grid.lo;
  const int* dim = grid.dim;
  long long total = 0;
#pragma omp parallel reduction(+ : total)
  {
    const int thread = omp_get_thread_num();
    int* mark = scratch.mark[static_cast<std::size_t>(thread)].data();
    int* mid = scratch.slots[static_cast<std::size_t>(thread)].data();
#pragma omp for schedule(dynamic, 16)
    for (int it = 0; it < nt; ++it) {
      const int i = targets[it];
      const double x0[3] = {x(0, i), x(1, i), x(2, i)};
      // Collect the mid slots first, then sum their blocks: one add_block per element costs a horizontal
      // reduction and a masked remainder each; consecutive slots are merged into one contiguous loop
      // (measured cheaper than gathering; results/benchmarks.md).
      int nc = 0;
      auto always = [&](int j) {  // j: slot of the element
        if (mark[j] == i) return;
        mark[j] = i;
        mid[nc++] = j;
      };
      // The own elements and near-singular neighbours first: the corrections after this phase remove
      // exactly the regular rule from them, whatever their distance.
      for (int k = own_offsets[i]; k < own_offsets[i + 1]; ++k) always(slot[own_elements[k]]);
      if (!near.offsets.empty())
        for (int k = near.offsets[i]; k < near.offsets[i + 1]; ++k) always(slot[near.elements[k]]);
      int lo[3], hi[3];
      for (int k = 0; k < 3; ++k) {
        const double a = std::floor((x0[k] - reach - glo[k]) / cell);
        const double b = std::floor((x0[k] + reach - glo[k]) / cell);
        lo[k] = a > 0.0 ? static_cast<int>(std::min(a, dim[k] - 1.0)) : 0;
        hi[k] = b > 0.0 ? static_cast<int>(std::min(b, dim[k] - 1.0)) : 0;
      }
      for (int iz = lo[2]; iz <= hi[2]; ++iz)
        for (int iy = lo[1]; iy <= hi[1]; ++iy) {
          const int row = (iz * dim[1] + iy) * dim[0];
          // Branch-free append (the mid/far outcome is unpredictable); the cells are disjoint, so only the
          // slots listed above can come twice. mid has room for one write past the last element.
          for (int j = grid.cell_offsets[row + lo[0]]; j < grid.cell_offsets[row + hi[0] + 1]; ++j) {
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

}  // namespace capsim::stokes

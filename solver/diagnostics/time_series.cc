#include "solver/diagnostics/time_series.h"

#include <stdexcept>

#include "solver/diagnostics/shape_moments.h"

namespace capsim::diagnostics {

StepRecord measure_step(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, double t, int p_node,
                        double tau_min) {
  if (p_node < 0 || p_node >= x.cols()) throw std::out_of_range("measure_step: material point node out of range");
  const ShapeMoments m = shape_moments(mesh, x);
  const EllipsoidOfInertia el = ellipsoid_of_inertia(m);
  StepRecord r;
  r.t = t;
  r.D12 = el.D12;
  r.L1 = el.L1;
  r.L2 = el.L2;
  r.theta = el.theta;
  r.tau_min = tau_min;
  r.volume = m.volume;
  r.area = m.area;
  r.P = {x(0, p_node), x(1, p_node), x(2, p_node)};
  return r;
}

void TimeSeries::push_back(const StepRecord& r) {
  t.push_back(r.t);
  D12.push_back(r.D12);
  L1.push_back(r.L1);
  L2.push_back(r.L2);
  theta.push_back(r.theta);
  tau_min.push_back(r.tau_min);
  volume.push_back(r.volume);
  area.push_back(r.area);
  P.push_back(r.P);
  bending_energy.push_back(r.bending_energy);
  max_bending_moment.push_back(r.max_bending_moment);
}

StepRecord TimeSeries::at(std::size_t i) const {
  if (i >= size()) throw std::out_of_range("TimeSeries::at: index out of range");
  return {t[i], D12[i], L1[i], L2[i], theta[i], tau_min[i], volume[i], area[i], P[i], bending_energy[i],
          max_bending_moment[i]};
}

void TimeSeries::truncate(std::size_t n) {
  if (n >= size()) return;
  for (auto* c : {&t, &D12, &L1, &L2, &theta, &tau_min, &volume, &area, &bending_energy, &max_bending_moment})
    c->resize(n);
  P.resize(n);
}

bool TimeSeries::consistent() const {
  const std::size_t n = t.size();
  for (const auto* c : {&D12, &L1, &L2, &theta, &tau_min, &volume, &area, &bending_energy, &max_bending_moment})
    if (c->size() != n) return false;
  return P.size() == n;
}

}  // namespace capsim::diagnostics

#include "solver/diagnostics/time_series.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>

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
  const MaterialAxis ax = material_axis(mesh, x);
  r.axis = ax.axis;
  r.axis_tilt = ax.tilt;
  r.axis_azimuth = ax.azimuth;
  const EllipsoidOfInertia3D el3 = ellipsoid_of_inertia_3d(m);
  r.La = el3.La;
  r.Lb = el3.Lb;
  r.Lc = el3.Lc;
  for (int k = 0; k < 3; ++k) {
    r.ea[k] = el3.axes[0](k);
    r.eb[k] = el3.axes[1](k);
    r.ec[k] = el3.axes[2](k);
  }
  return r;
}

MaterialAxis material_axis(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const auto [a, b] = mesh.pole_node;
  if (a < 0 || b < 0 || a >= x.cols() || b >= x.cols()) return {{kNaN, kNaN, kNaN}, kNaN, kNaN};
  const Eigen::Vector3d d = x.col(a) - x.col(b);
  const double n = d.norm();
  if (!(n > 0.0)) return {{kNaN, kNaN, kNaN}, kNaN, kNaN};
  const Eigen::Vector3d p = d / n;
  constexpr double kDeg = 180.0 / std::numbers::pi;
  MaterialAxis m;
  m.axis = {p(0), p(1), p(2)};
  // The tilt from the in-plane length, not asin(|p3|): atan2 keeps full accuracy near 90° as well as near 0.
  m.tilt = std::atan2(std::abs(p(2)), std::hypot(p(0), p(1))) * kDeg;
  // The axis is a line: its projection's angle is taken modulo 180°, in (−90, 90] like the inclination θ (0 when
  // the projection vanishes, the axis along x3). An exact 0 of p1 gives +90 whichever sign p2 has.
  double phi = std::atan2(p(1), p(0)) * kDeg;
  if (phi <= -90.0) phi += 180.0;
  if (phi > 90.0) phi -= 180.0;
  m.azimuth = phi;
  return m;
}

double final_tilt(const TimeSeries& s, double t_begin, double t_end) {
  if (s.empty()) return std::numeric_limits<double>::quiet_NaN();
  t_begin = std::max(t_begin, s.t.front());
  t_end = std::min(t_end, s.t.back());
  if (!(t_begin < t_end)) return s.axis_tilt.back();
  // The tilt at time t, linear between samples i − 1 and i.
  auto at = [&](std::size_t i, double t) {
    const double w = (t - s.t[i - 1]) / (s.t[i] - s.t[i - 1]);
    return s.axis_tilt[i - 1] + w * (s.axis_tilt[i] - s.axis_tilt[i - 1]);
  };
  double integral = 0.0;
  for (std::size_t i = 1; i < s.size(); ++i) {
    const double lo = std::max(s.t[i - 1], t_begin), hi = std::min(s.t[i], t_end);
    if (hi <= lo) continue;
    integral += 0.5 * (at(i, lo) + at(i, hi)) * (hi - lo);
  }
  return integral / (t_end - t_begin);
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
  axis_x1.push_back(r.axis[0]);
  axis_x2.push_back(r.axis[1]);
  axis_x3.push_back(r.axis[2]);
  axis_tilt.push_back(r.axis_tilt);
  axis_azimuth.push_back(r.axis_azimuth);
  La.push_back(r.La);
  Lb.push_back(r.Lb);
  Lc.push_back(r.Lc);
  for (auto [col, v] : {std::pair{&ea_x1, r.ea[0]}, std::pair{&ea_x2, r.ea[1]}, std::pair{&ea_x3, r.ea[2]},
                        std::pair{&eb_x1, r.eb[0]}, std::pair{&eb_x2, r.eb[1]}, std::pair{&eb_x3, r.eb[2]},
                        std::pair{&ec_x1, r.ec[0]}, std::pair{&ec_x2, r.ec[1]}, std::pair{&ec_x3, r.ec[2]}})
    col->push_back(v);
  spin.push_back(r.spin);
}

StepRecord TimeSeries::at(std::size_t i) const {
  if (i >= size()) throw std::out_of_range("TimeSeries::at: index out of range");
  StepRecord r;
  r.t = t[i];
  r.D12 = D12[i];
  r.L1 = L1[i];
  r.L2 = L2[i];
  r.theta = theta[i];
  r.tau_min = tau_min[i];
  r.volume = volume[i];
  r.area = area[i];
  r.P = P[i];
  r.bending_energy = bending_energy[i];
  r.max_bending_moment = max_bending_moment[i];
  r.axis = {axis_x1[i], axis_x2[i], axis_x3[i]};
  r.axis_tilt = axis_tilt[i];
  r.axis_azimuth = axis_azimuth[i];
  r.La = La[i];
  r.Lb = Lb[i];
  r.Lc = Lc[i];
  r.ea = {ea_x1[i], ea_x2[i], ea_x3[i]};
  r.eb = {eb_x1[i], eb_x2[i], eb_x3[i]};
  r.ec = {ec_x1[i], ec_x2[i], ec_x3[i]};
  r.spin = spin[i];
  return r;
}

void TimeSeries::truncate(std::size_t n) {
  if (n >= size()) return;
  for (auto* c : scalar_columns()) c->resize(n);
  P.resize(n);
}

bool operator==(const TimeSeries& a, const TimeSeries& b) {
  auto same = [](const auto& u, const auto& v) {
    return u.size() == v.size() && (u.empty() || std::memcmp(u.data(), v.data(), sizeof(u[0]) * u.size()) == 0);
  };
  const auto ca = a.scalar_columns(), cb = b.scalar_columns();
  for (std::size_t k = 0; k < ca.size(); ++k)
    if (!same(*ca[k], *cb[k])) return false;
  return same(a.P, b.P);
}

bool TimeSeries::consistent() const {
  const std::size_t n = t.size();
  for (const auto* c : scalar_columns())
    if (c->size() != n) return false;
  return P.size() == n;
}

}  // namespace capsim::diagnostics

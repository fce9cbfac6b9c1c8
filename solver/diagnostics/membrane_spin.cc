#include "solver/diagnostics/membrane_spin.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace capsim::diagnostics {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

SpinFrame spin_frame(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x) {
  if (x.cols() != mesh.num_nodes())
    throw std::invalid_argument("spin_frame: positions have " + std::to_string(x.cols()) + " columns, mesh has " +
                                std::to_string(mesh.num_nodes()) + " nodes");
  const auto [a, b] = mesh.pole_node;
  const int s = mesh.equator_node;
  const int n = mesh.num_nodes();
  if (a < 0 || b < 0 || s < 0 || a >= n || b >= n || s >= n) return {};
  const Eigen::Vector3d d = x.col(a) - x.col(b);
  const double length = d.norm();
  if (!(length > 0.0)) return {};
  const Eigen::Vector3d p = d / length;
  const Eigen::Vector3d r = x.col(s) - 0.5 * (x.col(a) + x.col(b));
  const Eigen::Vector3d r_perp = r - r.dot(p) * p;
  const double rn = r_perp.norm();
  // A node (nearly) on the axis has no direction about it: u would carry the round-off of r as a turn.
  if (!(rn > 1e-8 * r.norm())) return {};
  SpinFrame f;
  f.axis = p;
  f.radial = r_perp / rn;
  return f;
}

double spin_increment(const SpinFrame& from, const SpinFrame& to) {
  if (!from.valid() || !to.valid()) return kNaN;
  const Eigen::Vector3d& p = from.axis;
  const Eigen::Vector3d& q = to.axis;
  const double cos_pq = p.dot(q);
  // T is undefined for an axis that reversed (any turn about any perpendicular would do): no measurable step.
  if (!(cos_pq > -1.0 + 1e-12)) return kNaN;
  // The smallest rotation p → q applied to u (Rodrigues with c = p × q, |c| = sin, p·q = cos): exact for unit p, q,
  // and free of the cancellation of an axis-angle form for small turns.
  const Eigen::Vector3d c = p.cross(q);
  const Eigen::Vector3d& u = from.radial;
  const Eigen::Vector3d w = u + c.cross(u) + c.cross(c.cross(u)) / (1.0 + cos_pq);
  // The signed angle from w to u′ about q (both ⟂ q up to round-off).
  return std::atan2(q.dot(w.cross(to.radial)), w.dot(to.radial));
}

double advance_spin(double spin, const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x_from,
                    const Eigen::Matrix3Xd& x_to) {
  return spin + spin_increment(spin_frame(mesh, x_from), spin_frame(mesh, x_to));
}

double final_spin_rate(const TimeSeries& s, double t_begin, double t_end) {
  if (s.empty()) return kNaN;
  t_begin = std::max(t_begin, s.t.front());
  t_end = std::min(t_end, s.t.back());
  if (!(t_begin < t_end)) return kNaN;
  // The spin at time t, linear between the samples around it.
  auto at = [&](double t) {
    const auto hi = static_cast<std::size_t>(std::lower_bound(s.t.begin(), s.t.end(), t) - s.t.begin());
    if (hi == 0) return s.spin.front();
    if (hi >= s.size()) return s.spin.back();
    const double w = (t - s.t[hi - 1]) / (s.t[hi] - s.t[hi - 1]);
    return s.spin[hi - 1] + w * (s.spin[hi] - s.spin[hi - 1]);
  };
  // A NaN anywhere in the window (a step that could not be measured) makes the turn over it unknown.
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.t[i] >= t_begin && s.t[i] <= t_end && std::isnan(s.spin[i])) return kNaN;
  return (at(t_end) - at(t_begin)) / (t_end - t_begin);
}

}  // namespace capsim::diagnostics

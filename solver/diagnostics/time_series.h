#pragma once
/// @file
/// @brief The per-step diagnostics of one case (seed §3: D12, θ, τmin, P; solver/README.md §5) and their time series.

#include <array>
#include <cstddef>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "solver/mesh/mesh.h"

namespace capsim::diagnostics {

/// @brief Diagnostics of one time step.
struct StepRecord {
  double t = 0;        ///< time, units of 1/γ̇
  double D12 = 0;      ///< Taylor parameter of the ellipsoid of inertia in the shear plane
  double L1 = 0;       ///< longer in-plane semi-axis of the ellipsoid of inertia
  double L2 = 0;       ///< shorter in-plane semi-axis
  double theta = 0;    ///< inclination of L1 to x1, (−π/2, π/2]
  double tau_min = 0;  ///< smallest principal tension over the surface (from the membrane), units of Gs
  double volume = 0;   ///< enclosed volume
  double area = 0;     ///< surface area
  std::array<double, 3> P{};  ///< position of the material point P
  double bending_energy = 0;      ///< W_b, units Gs ℓ² (0 without bending stiffness)
  double max_bending_moment = 0;  ///< max κ_b |c − c0| over the surface, units Gs ℓ (0 without bending)
  /// The material axis: the unit vector from the node that started at the −x1 pole of the unrotated spheroid to
  /// the one that started at its +x1 pole (mesh.pole_node), i.e. the axis of revolution carried by the membrane.
  std::array<double, 3> axis{};
  double axis_tilt = 0;     ///< angle of the material axis out of the shear plane, asin |axis_3|, degrees [0, 90]
  double axis_azimuth = 0;  ///< angle of its projection on the shear plane from x1 toward x2, as a line: (−90, 90] degrees
  /// The 3D ellipsoid of inertia (EllipsoidOfInertia3D): semi-axes La ≥ Lb ≥ Lc, units ℓ, and their unit
  /// directions (x1 component positive, see there).
  double La = 0, Lb = 0, Lc = 0;
  std::array<double, 3> ea{}, eb{}, ec{};
  /// The membrane's rotation about the material axis since the start, radians, counter-clockwise about `axis`
  /// (diagnostics/membrane_spin.h). Not measured by measure_step (it accumulates over the steps): NaN there, set
  /// by the caller with advance_spin.
  double spin = std::numeric_limits<double>::quiet_NaN();
};

/// @brief Measure everything but τmin (which the membrane provides) and the spin (which needs the state before) on
/// positions x at time t.
/// @param p_node the node chosen by choose_material_point at the start of the case.
StepRecord measure_step(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, double t, int p_node,
                        double tau_min);

/// @brief The material axis's direction, tilt and azimuth (StepRecord::axis, axis_tilt, axis_azimuth) on positions
/// x, from the mesh's pole nodes; {NaN...} if the mesh has none or the two poles coincide.
struct MaterialAxis {
  std::array<double, 3> axis{};
  double tilt = 0, azimuth = 0;
};
MaterialAxis material_axis(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x);

/// @brief Column-wise time series of StepRecord (ready for std::span analysis and for HDF5 datasets).
/// Invariant: every column has size() entries.
struct TimeSeries {
  std::vector<double> t, D12, L1, L2, theta, tau_min, volume, area;
  std::vector<std::array<double, 3>> P;
  std::vector<double> bending_energy, max_bending_moment;
  std::vector<double> axis_x1, axis_x2, axis_x3, axis_tilt, axis_azimuth;
  std::vector<double> La, Lb, Lc, ea_x1, ea_x2, ea_x3, eb_x1, eb_x2, eb_x3, ec_x1, ec_x2, ec_x3, spin;

 private:
  template <class Self>
  static auto columns_of(Self& s) {
    return std::array{&s.t,       &s.D12,     &s.L1,      &s.L2,      &s.theta,   &s.tau_min, &s.volume,
                      &s.area,    &s.bending_energy,      &s.max_bending_moment,  &s.axis_x1, &s.axis_x2,
                      &s.axis_x3, &s.axis_tilt, &s.axis_azimuth, &s.La, &s.Lb,    &s.Lc,      &s.ea_x1,
                      &s.ea_x2,   &s.ea_x3,   &s.eb_x1,   &s.eb_x2,   &s.eb_x3,   &s.ec_x1,   &s.ec_x2,
                      &s.ec_x3,   &s.spin};
  }

 public:
  /// @brief Every 1-D column (all but P), for operations on all of them: a column added to this list is truncated
  /// and checked with the others.
  auto scalar_columns() { return columns_of(*this); }
  auto scalar_columns() const { return columns_of(*this); }

  /// @brief Append one record.
  void push_back(const StepRecord& r);
  /// @brief Number of records.
  [[nodiscard]] std::size_t size() const { return t.size(); }
  /// @brief True when there is no record.
  [[nodiscard]] bool empty() const { return t.empty(); }
  /// @brief Record i (0 ≤ i < size()).
  [[nodiscard]] StepRecord at(std::size_t i) const;
  /// @brief Drop every record after the first n (n ≥ size() is a no-op).
  void truncate(std::size_t n);
  /// @brief True when every column has size() entries.
  [[nodiscard]] bool consistent() const;
  /// @brief Bitwise equality of all columns (so a NaN equals the same NaN: columns that were not measured, such as
  /// the spin of records not taken along a run, compare equal when they were written and read back).
  friend bool operator==(const TimeSeries& a, const TimeSeries& b);
};

/// @brief The final tilt of a case (summary final_tilt, degrees): the time mean of axis_tilt (trapezoidal, linear
/// between samples) over [t_begin, t_end] (the last period) when t_begin < t_end, else the last value; NaN for an
/// empty series.
double final_tilt(const TimeSeries& series, double t_begin, double t_end);

}  // namespace capsim::diagnostics

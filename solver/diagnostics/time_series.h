#pragma once
/// @file
/// @brief The per-step diagnostics of one case (seed §3: D12, θ, τmin, P; solver/README.md §5) and their time series.

#include <array>
#include <cstddef>
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
};

/// @brief Measure everything but τmin (which the membrane provides) on positions x at time t.
/// @param p_node the node chosen by choose_material_point at the start of the case.
StepRecord measure_step(const mesh::SurfaceMesh& mesh, const Eigen::Matrix3Xd& x, double t, int p_node,
                        double tau_min);

/// @brief Column-wise time series of StepRecord (ready for std::span analysis and for HDF5 datasets).
/// Invariant: every column has size() entries.
struct TimeSeries {
  std::vector<double> t, D12, L1, L2, theta, tau_min, volume, area;
  std::vector<std::array<double, 3>> P;
  std::vector<double> bending_energy, max_bending_moment;

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
  /// @brief Bitwise equality of all columns.
  friend bool operator==(const TimeSeries&, const TimeSeries&) = default;
};

}  // namespace capsim::diagnostics
